"""The depth stage: point grid -> support plane -> objects above it -> solids -> planes and cylindrical faces per
solid -> outlines and adjacency (stage.py runs the chain; each step is a module here, with its own settings)."""

from .stage import DEFAULT, DepthObjectResult, DepthResult, DepthSettings, depth_scene, with_overrides

__all__ = ["DEFAULT", "DepthObjectResult", "DepthResult", "DepthSettings", "depth_scene", "with_overrides"]
