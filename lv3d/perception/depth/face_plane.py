"""A colour face's own plane: the depth points inside its polygon, fitted directly.

Depth segmentation loses faces seen at a grazing angle: they hold few grid points, their smoothed normals blend
with the neighbouring face's, and RANSAC gives their points to that neighbour or to a plane that straddles the
edge. The colour outline of such a face is often exact, so the points inside it (shrunk away from its edges,
where depth mixes both faces) say directly whether it is a plane of its own.
"""

from __future__ import annotations

import cv2
import numpy as np

from ...plane import Plane
from .cloud import PointGrid
from .support import noise_threshold, ransac_plane, refine


def polygon_cells(poly: np.ndarray, grid_shape: tuple[int, int], stride: int, shrink_px: int = 2) -> np.ndarray:
    """Grid cells (m, 2) as (i, j) whose pixel (stride * j, stride * i) lies inside ``poly`` (n, 2) pixels, after
    the polygon's mask is eroded by ``shrink_px`` pixels."""
    p = np.asarray(poly, np.float64)
    u0, v0 = np.floor(p.min(axis=0)).astype(int) - 1
    u1, v1 = np.ceil(p.max(axis=0)).astype(int) + 2
    m = np.zeros((v1 - v0, u1 - u0), np.uint8)
    cv2.fillPoly(m, [np.round(p - [u0, v0]).astype(np.int32)], 1)
    if shrink_px > 0:
        m = cv2.erode(m, np.ones((2 * shrink_px + 1, 2 * shrink_px + 1), np.uint8))
    vv, uu = np.nonzero(m)
    vv, uu = vv + v0, uu + u0
    on = (vv % stride == 0) & (uu % stride == 0)
    cells = np.stack([vv[on] // stride, uu[on] // stride], axis=1)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < grid_shape[0]) & (cells[:, 1] >= 0) & (cells[:, 1] < grid_shape[1])
    return cells[inside]


def fit_face_plane(poly: np.ndarray, grid: PointGrid, seed: int = 0, min_points: int = 8,
                   min_inliers: float = 0.85, on_mask: np.ndarray | None = None,
                   min_on_mask: float = 0.5, max_points: int = 400) -> tuple[Plane, np.ndarray, float] | None:
    """The plane of the depth points inside colour polygon ``poly`` (n, 2) pixels: (plane, inlier points (m, 3)
    metres, RMS residual in metres), or None when fewer than ``min_points`` valid points lie inside or fewer than
    ``min_inliers`` of them fit one plane within the depth noise (the polygon spans an edge or is not a face).
    With ``on_mask`` (grid-shaped bool, e.g. an object's cells), also None when fewer than ``min_on_mask`` of the
    polygon's cells are on it (a shadow or a patch of table beside the object). At most ``max_points`` cells,
    evenly spread, are used."""
    cells = polygon_cells(poly, grid.shape, grid.stride)
    if len(cells) < min_points:
        return None
    if on_mask is not None and np.mean(on_mask[cells[:, 0], cells[:, 1]]) < min_on_mask:
        return None
    if len(cells) > max_points:  # an evenly thinned set says as much about planarity, for less
        cells = cells[np.linspace(0, len(cells) - 1, max_points).astype(int)]
    ok = grid.valid[cells[:, 0], cells[:, 1]]
    pts = grid.xyz[cells[ok, 0], cells[ok, 1]].astype(np.float64)
    if len(pts) < min_points:
        return None
    dist_m = noise_threshold(float(np.median(pts[:, 2])))
    # a face needs most points on one plane: a triple of inliers comes up within a few draws
    _, inl = ransac_plane(pts, dist_m, np.random.default_rng(seed), iterations=16)
    if inl.sum() < max(min_points, min_inliers * len(pts)):
        return None
    plane = refine(pts[inl])
    rms = float(np.sqrt(np.mean(plane.distance(pts[inl]) ** 2)))
    return plane, pts[inl].astype(np.float32), rms


def angle_deg(a: Plane, b: Plane) -> float:
    """Angle (degrees, in [0, 90]) between two planes' normals."""
    return float(np.degrees(np.arccos(np.clip(abs(float(a.n @ b.n)), 0.0, 1.0))))
