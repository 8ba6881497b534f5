"""A face's outline in its own plane: image vertices lifted onto the face's plane, simplified there, projected back.

Perspective squeezes a face seen at a grazing angle: in the image a thin strip's short sides are a few pixels
and its corners turn by little, so image-space simplification drops true corners (3 sides for 4) or keeps a
bend of a noisy long side (5 sides for 4). On the plane the face has its true shape and angles.
"""

from __future__ import annotations

import numpy as np

from ...camera import Intrinsics
from ...plane import Plane
from ..polygons import clockwise, drop_short_sides, simplify
from .snap import cross3

# a ray this close to lying in the plane (|cos| of its angle to the normal) lifts to a point whose place is
# dominated by the plane's error: the face is seen too edge-on to be measured on its plane
_MIN_COS = 0.05


def plane_basis(plane: Plane) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin (3,), e1 (3,), e2 (3,)): the plane's point nearest the camera and two orthonormal in-plane axes."""
    n = plane.n
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = cross3(n, a)
    e1 /= np.linalg.norm(e1)
    return -plane.offset * n, e1, cross3(n, e1)


def lift(poly: np.ndarray, plane: Plane, k: Intrinsics) -> np.ndarray | None:
    """In-plane coordinates (n, 2) metres of image polygon ``poly`` (n, 2) pixels on ``plane``; None when a
    vertex's ray misses the plane in front of the camera or grazes it."""
    rays = k.rays(np.asarray(poly, np.float64))
    cos = np.abs(rays @ plane.n) / np.linalg.norm(rays, axis=1)
    if np.any(cos < _MIN_COS):
        return None
    pts = plane.intersect_rays(rays)
    if not np.all(np.isfinite(pts)) or np.any(pts[:, 2] <= 0):
        return None
    o, e1, e2 = plane_basis(plane)
    return np.stack([(pts - o) @ e1, (pts - o) @ e2], axis=1)


def drop(uv: np.ndarray, plane: Plane, k: Intrinsics) -> np.ndarray:
    """Image pixels (n, 2) of in-plane coordinates ``uv`` (n, 2) metres on ``plane``."""
    o, e1, e2 = plane_basis(plane)
    return k.project(o + uv[:, :1] * e1 + uv[:, 1:] * e2)


def simplify_on_plane(poly: np.ndarray, plane: Plane, k: Intrinsics, rel_tol: float = 0.06,
                      abs_tol_m: float = 0.002, min_turn_deg: float = 15.0, rel_len: float = 0.15) -> np.ndarray:
    """``poly`` (n, 2) pixels, the outline of a face on ``plane``, with the vertices that are no corners on the
    plane removed: near-collinear ones (see :func:`lv3d.perception.polygons.simplify`; ``abs_tol_m`` metres)
    and the pairs of corners a few millimetres apart that trace one corner (sides under ``rel_len`` of the mean
    side). Returns ``poly`` itself when it cannot be lifted onto the plane or nothing changes; never adds
    sides."""
    p = np.asarray(poly, np.float64)
    if len(p) <= 3:
        return poly
    uv = lift(p, plane, k)
    if uv is None:
        return poly
    # simplify works in pixels: millimetres keep its absolute tolerance meaningful
    q = simplify(uv * 1e3, rel_tol=rel_tol, abs_tol=abs_tol_m * 1e3, min_turn_deg=min_turn_deg)
    if len(q) > 3:
        q = drop_short_sides(q, rel_len=rel_len)
    if len(q) == len(p) or len(q) < 3:
        return poly
    out = drop(q * 1e-3, plane, k)
    if not np.all(np.isfinite(out)):
        return poly
    return clockwise(out)
