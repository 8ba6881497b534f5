"""Colour faces seen edge-on that rgbd fusion keeps although depth gives them no plane of their own.

A face seen at 83-88 degrees is a sliver a few pixels wide. Colour can close it, but depth either drops its points
(along such a surface depth jumps from pixel to pixel, and cloud.py drops the points as flying) or merges it into a
neighbour's plane; fusion would then drop it under the colour-only floor or as print. The two tests here tell such a
sliver from print, shading or a stripe of table (docs/perception.md, session 8)."""

from __future__ import annotations

import numpy as np

from .cloud import PointGrid
from .face_plane import polygon_cells
from .polygons import mean_width
from .rgb import RGBFace

# as wide as thin.py's slivers (under 2.5 px: a hairline between two outlines), most of its cells read by the sensor
# and few of them kept as points
_MIN_WIDTH_PX = 2.5
_MAX_WIDTH_PX = 12.0
_MIN_READ = 0.8
_MAX_VALID = 0.2
# on a plane no colour face has: all its outline on image edges, and wider than a hairline (a traced triangle's
# mean width is a little under its width)
_BARE_SUPPORT = 0.9
_BARE_MIN_WIDTH_PX = 2.0


def points_dropped(poly: np.ndarray, depth: np.ndarray, grid: PointGrid, obj_grown: np.ndarray,
                   min_cells: int = 8) -> bool:
    """True when colour face ``poly`` (n, 2) pixels is a face seen edge-on whose depth readings were all dropped
    as flying points: a sliver ``_MIN_WIDTH_PX`` to ``_MAX_WIDTH_PX`` wide (:func:`polygons.mean_width`), on the
    object's grown cells (``obj_grown``), whose grid cells (``min_cells`` or more; the outline shrunk by a pixel,
    as the outer ones hold its neighbours' points) have readings in ``depth`` (H, W) metres but nearly no point in
    ``grid``. A sliver of print or shading on a face, or a stripe of table, keeps its points; a face with no
    reading at all (a sensor's grazing-angle hole) is holes.py's."""
    if not _MIN_WIDTH_PX <= mean_width(poly) <= _MAX_WIDTH_PX:
        return False
    cells = polygon_cells(poly, grid.shape, grid.stride, shrink_px=1)
    if len(cells) < min_cells or np.mean(obj_grown[cells[:, 0], cells[:, 1]]) < 0.5:
        return False
    z = depth[cells[:, 0] * grid.stride, cells[:, 1] * grid.stride]
    read = np.isfinite(z) & (z > 0)
    return float(np.mean(read)) >= _MIN_READ and float(np.mean(grid.valid[cells[:, 0], cells[:, 1]])) <= _MAX_VALID


def on_unclaimed_plane(f: RGBFace, poly_px: np.ndarray, plane_px: list[np.ndarray], claimed: set[int]) -> bool:
    """True when colour face ``f``, with too few points for a plane of its own and lying on the pixels of depth
    planes (``plane_px``, crop masks like ``poly_px``; ``claimed``: the indices of the planes colour faces matched
    or absorbed), is a face seen edge-on that depth merged into a neighbour, not print: a sliver
    (``_BARE_MIN_WIDTH_PX`` to ``_MAX_WIDTH_PX`` wide) whose outline is nearly all on image edges, lying only on
    planes no colour face claimed (print is on a face colour found)."""
    width = mean_width(f.polygon)
    if not _BARE_MIN_WIDTH_PX <= width <= _MAX_WIDTH_PX or f.edge_support < _BARE_SUPPORT:
        return False
    under = [j for j, q in enumerate(plane_px) if np.count_nonzero(poly_px & q)]
    return bool(under) and not any(j in claimed for j in under)
