"""Perception: faces from colour (edges, segments, planar graph), planes from depth (support plane, objects,
planes per object), and their fusion, as a :class:`lv3d.scene.Scene`."""

from .perceive import perceive as perceive

__all__ = ["perceive"]
