"""Fusion: each colour polygon tied to the depth plane it lies on (the polygon's pixels mostly inside the
plane's mask). The fused face keeps the colour polygon (sharper corners) and the depth plane."""

from __future__ import annotations

import numpy as np

from .boundary import grid_to_pixels
from .polygons import rasterize


def match_faces(polygons: list[np.ndarray], plane_masks_grid: list[np.ndarray], stride: int,
                box: tuple[int, int, int, int], min_inside: float = 0.5,
                min_iou: float = 0.2) -> dict[int, int]:
    """One-to-one matches colour face index -> plane index. Polygons are (n, 2) pixels; plane masks are grid
    masks of step ``stride``; everything is compared inside ``box`` (u0, v0, u1, v1). A pair qualifies when at
    least ``min_inside`` of the polygon lies on the plane and their IoU is at least ``min_iou``; pairs are taken
    greedily by IoU, best first (ties broken by index, so the result is deterministic)."""
    u0, v0, u1, v1 = box
    shape = (v1 - v0, u1 - u0)
    off = np.array([u0, v0], float)
    plane_px = [grid_to_pixels(m, stride, box) for m in plane_masks_grid]
    cands = []
    for i, poly in enumerate(polygons):
        pm = rasterize(poly - off, shape)
        pa = np.count_nonzero(pm)
        if pa == 0:
            continue
        for j, qm in enumerate(plane_px):
            inter = np.count_nonzero(pm & qm)
            if inter == 0:
                continue
            iou = inter / (pa + np.count_nonzero(qm) - inter)
            if inter / pa >= min_inside and iou >= min_iou:
                cands.append((-iou, i, j))
    cands.sort()
    used_i, used_j, out = set(), set(), {}
    for _, i, j in cands:
        if i in used_i or j in used_j:
            continue
        out[i] = j
        used_i.add(i)
        used_j.add(j)
    return out


def inside_fraction(poly: np.ndarray, grid_mask: np.ndarray, stride: int, box: tuple[int, int, int, int]) -> float:
    """Fraction of the polygon's pixels that lie on the grid mask (object membership of a colour face)."""
    u0, v0, u1, v1 = box
    pm = rasterize(poly - np.array([u0, v0], float), (v1 - v0, u1 - u0))
    qm = grid_to_pixels(grid_mask, stride, box)
    pa = np.count_nonzero(pm)
    return float(np.count_nonzero(pm & qm) / pa) if pa else 0.0
