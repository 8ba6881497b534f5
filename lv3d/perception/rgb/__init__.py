"""The colour path: edges -> segments -> planar graph -> faces -> solids by shared edges and silhouette
(stage.py runs the chain; each step is a module here)."""

from .stage import RGBFace, RGBResult, rgb_faces

__all__ = ["RGBFace", "RGBResult", "rgb_faces"]
