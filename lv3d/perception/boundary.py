"""A plane's boundary as an image polygon: grid mask -> pixel mask -> outer contour -> convex hull (faces of
the solids are convex; the hull bridges holes and ragged noise) -> corners only."""

from __future__ import annotations

import cv2
import numpy as np

from .polygons import KEEP_AREA, clockwise, simplify


def mask_polygon(grid_mask: np.ndarray, stride: int, image_shape: tuple[int, int], eps_frac: float = 0.035,
                 convex: bool = True) -> np.ndarray | None:
    """Polygon (n, 2) pixels, clockwise, of the largest piece of ``grid_mask`` (h, w) bool on a point grid of
    step ``stride``; None when nothing is left. ``eps_frac``: Douglas-Peucker tolerance as a fraction of the
    perimeter."""
    m = grid_mask.astype(np.uint8)
    m = cv2.morphologyEx(m, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    contours, _ = cv2.findContours(m, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        return None
    c = max(contours, key=cv2.contourArea)
    if convex:
        c = cv2.convexHull(c)
    # grid cell (i, j) covers pixels [stride*j - stride/2, stride*j + stride/2): scale, then centre the cells
    pts = c.reshape(-1, 2).astype(np.float64) * stride
    peri = cv2.arcLength(pts.astype(np.float32).reshape(-1, 1, 2), True)
    # a thin face (seen at a grazing angle) must not collapse: the tolerance stays under a fifth of its width
    short_side = min(cv2.minAreaRect(pts.astype(np.float32).reshape(-1, 1, 2))[1])
    eps = max(1.0, min(eps_frac * peri, 0.2 * short_side))
    approx = cv2.approxPolyDP(pts.astype(np.float32).reshape(-1, 1, 2), eps, True).reshape(-1, 2)
    if len(approx) < 3:
        return None
    # a face seen edge-on is a lens whose corners lie a few px off their neighbours' chord and turn by little, yet
    # hold much of its area: simplifying on the chord alone drops corners that carry half a face
    poly = simplify(approx.astype(np.float64), keep_area_frac=KEEP_AREA)
    if convex and len(poly) >= 3:
        # the contour runs through the outermost samples' pixels; each sample stands for a stride x stride
        # block starting there, so the face reaches (stride - 1) / 2 px further on average: on a face a few
        # cells wide (seen at a grazing angle) that is a large part of its area
        poly = grow_convex(clockwise(poly) + 0.5 * (stride - 1), 0.5 * stride)
    h, w = image_shape
    poly[:, 0] = np.clip(poly[:, 0], 0, w - 1)
    poly[:, 1] = np.clip(poly[:, 1], 0, h - 1)
    return clockwise(poly) if len(poly) >= 3 else None


def grid_to_pixels(grid_mask: np.ndarray, stride: int, box: tuple[int, int, int, int]) -> np.ndarray:
    """The pixel mask (v1 - v0, u1 - u0) bool of grid mask (h, w) inside ``box`` = (u0, v0, u1, v1) pixels;
    grid cell (i, j) covers pixels [stride*i, stride*i + stride) x [stride*j, stride*j + stride)."""
    u0, v0, u1, v1 = box
    h, w = grid_mask.shape
    i0, j0 = v0 // stride, u0 // stride
    sub = grid_mask[i0:min(h, -(-v1 // stride)), j0:min(w, -(-u1 // stride))]
    # block upsampling by repetition: much cheaper than fancy indexing with np.ix_
    big = np.repeat(np.repeat(sub, stride, axis=0), stride, axis=1)
    big = big[v0 - i0 * stride:v1 - i0 * stride, u0 - j0 * stride:u1 - j0 * stride]
    out = np.zeros((v1 - v0, u1 - u0), bool)
    out[:big.shape[0], :big.shape[1]] = big
    return out


def grow_convex(poly: np.ndarray, d: float, miter: float = 2.0) -> np.ndarray:
    """Convex polygon (n, 2) pixels, clockwise in the image, with every side moved ``d`` pixels outward and the
    corners recomputed as the crossings of neighbouring sides (a corner stays put where its sides are nearly
    parallel, and moves at most ``miter`` * ``d``)."""
    p = np.asarray(poly, np.float64)
    e = np.roll(p, -1, axis=0) - p
    e /= np.maximum(np.linalg.norm(e, axis=1, keepdims=True), 1e-9)
    out_n = np.stack([e[:, 1], -e[:, 0]], axis=1)  # outward for clockwise order with v down
    q = p + d * out_n                               # a point on each moved side i (from p[i] to p[i+1])
    a, u = np.roll(q, 1, axis=0), np.roll(e, 1, axis=0)  # the side into each corner
    cross = u[:, 0] * e[:, 1] - u[:, 1] * e[:, 0]
    safe = np.where(np.abs(cross) > 1e-3, cross, 1.0)
    t = ((q[:, 0] - a[:, 0]) * e[:, 1] - (q[:, 1] - a[:, 1]) * e[:, 0]) / safe
    res = np.where((np.abs(cross) > 1e-3)[:, None], a + t[:, None] * u, p)
    # miter limit: at a very sharp corner the crossing runs far out along the bisector (d / sin(angle / 2)); the
    # corner moves at most ``miter`` * d
    move = res - p
    dist = np.linalg.norm(move, axis=1)
    scale = np.minimum(1.0, miter * d / np.maximum(dist, 1e-9))
    return p + move * scale[:, None]
