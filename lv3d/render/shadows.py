"""Cast shadows of a directional light, computed exactly from the geometry instead of shadow rays.

Every receiver is a flat face. A point X on a face's plane lies in shadow when the ray X + t L (t > 0,
L towards the light) meets a convex caster, i.e. when X lies in the projection along L, onto that
plane, of the caster's part on the light's side of the plane. That projection is a convex polygon: the
hull of the projected vertices on that side plus the points where the caster's edges cross the plane.
Projected into the image, filled exactly at pixel centres and kept only on the pixels that see that
face, it gives the same shadow as one shadow ray per pixel (tests/render/test_render_fast_paths.py)
for the cost of a few polygon fills (open3d's shadow rays cost ~100 ns each). A convex solid never
shadows its own lit faces, so a body is no caster for its own faces. A curved solid casts the shadow of
its tessellation; its curved faces are no receivers here: they get one shadow ray per pixel
(:mod:`lv3d.render.raycast`), joined in through :func:`soft_shadow`'s ``extra``.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..camera import Intrinsics
from .body import Body, clip_near

_EPS = 1e-9


def _plane_basis(n: np.ndarray) -> np.ndarray:
    """(3, 2) orthonormal vectors (columns) spanning the plane with unit normal ``n``."""
    a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = a - n * (a @ n)
    e1 /= np.sqrt(e1 @ e1)
    e2 = np.array([n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]])
    return np.stack([e1, e2], axis=1)


def shadow_polygon(v: np.ndarray, edges: np.ndarray, n: np.ndarray, d: float, light: np.ndarray,
                   basis: np.ndarray) -> np.ndarray | None:
    """Camera-frame (m, 3) convex polygon (metres, in order) that a convex caster with vertices ``v``
    (n, 3) and ``edges`` (e, 2) (vertex index pairs) casts on the plane n . X + d = 0 under the light
    ``light`` (unit, towards the light, n . light > 0); None when it casts nothing there. ``basis``:
    :func:`_plane_basis` of ``n``."""
    s = v @ n + d  # > 0: between the plane and the light
    on = s >= -_EPS
    pts = [v[on] - np.outer(np.maximum(s[on], 0.0) / float(n @ light), light)]
    sa, sb = s[edges[:, 0]], s[edges[:, 1]]
    cross = ((sa > _EPS) & (sb < -_EPS)) | ((sa < -_EPS) & (sb > _EPS))
    if np.any(cross):
        a, b = v[edges[cross, 0]], v[edges[cross, 1]]
        t = (sa[cross] / (sa[cross] - sb[cross]))[:, None]
        pts.append(a + (b - a) * t)
    p = np.concatenate(pts)
    if len(p) < 3:
        return None
    hull = cv2.convexHull((p @ basis).astype(np.float32), returnPoints=False)
    if hull is None or len(hull) < 3:
        return None
    return p[hull.ravel()]


def convex_mask(uv: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """(h, w) bool: the pixel centres (integer coordinates) inside or on the convex polygon ``uv`` (m, 2),
    either orientation. Exact, unlike cv2.fillPoly, which also fills pixels up to half a pixel outside
    (a shadow polygon's outline often runs along a solid's silhouette: that would draw a false line)."""
    h, w = shape
    p = np.asarray(uv, np.float64)
    q = np.roll(p, -1, axis=0)
    area2 = float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))
    if abs(area2) < 1e-12:
        return np.zeros(shape, bool)
    # inside: nx u + ny v >= c for every edge (normals pointing inwards); per row a span of u
    nx, ny = (p[:, 1] - q[:, 1]) * np.sign(area2), (q[:, 0] - p[:, 0]) * np.sign(area2)
    c = nx * p[:, 0] + ny * p[:, 1]
    rhs = c[None, :] - ny[None, :] * np.arange(h, dtype=np.float64)[:, None]  # nx u >= rhs, (h, m)
    tol = 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = rhs / nx[None, :]
    lo = np.max(np.where(nx > tol, bound, -np.inf), axis=1)
    hi = np.min(np.where(nx < -tol, bound, np.inf), axis=1)
    row_ok = np.all((np.abs(nx) > tol)[None, :] | (rhs <= 0), axis=1)  # edges along the rows
    lo = np.clip(np.ceil(lo - 1e-9), 0, w).astype(np.int64)
    hi = np.where(row_ok, np.clip(np.floor(hi + 1e-9) + 1, 0, w).astype(np.int64), lo)
    cols = np.arange(w)
    return (cols[None, :] >= lo[:, None]) & (cols[None, :] < hi[:, None])


def _edges(body: Body) -> np.ndarray:
    if len(body.solid.faces) == 1:  # a one-sided quad: its loop
        f = body.solid.faces[0]
        return np.array([(a, b) for a, b in zip(f, f[1:] + f[:1])], np.int64)
    return np.array(list(body.solid.edges()), np.int64)


def _pixel_box(poly: np.ndarray, k: Intrinsics) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Pixel positions (m, 2) of the camera-frame polygon (cut at 1 cm before the camera) and its
    bounding box (lo, hi) clipped to the image (half-open); None when it misses the image."""
    poly = clip_near(poly, 1e-2)
    if len(poly) < 3:
        return None
    uv = poly[:, :2] / poly[:, 2:] * [k.fx, k.fy] + [k.cx, k.cy]
    lo = np.maximum(np.floor(uv.min(axis=0)).astype(int), 0)
    hi = np.minimum(np.ceil(uv.max(axis=0)).astype(int) + 1, [k.width, k.height])
    if np.any(hi <= lo):
        return None
    return uv, lo, hi


def shadow_mask(bodies: list[Body], gface: np.ndarray, face_normal: np.ndarray, face_offset: np.ndarray,
                face_body: np.ndarray, k: Intrinsics, light: np.ndarray,
                not_receiver: np.ndarray | None = None) -> np.ndarray:
    """(H, W) uint8: 1 where the point a pixel sees lies in the shadow of another body. ``gface``: (H, W)
    flat face index per pixel (-1 = none) into ``face_normal`` (F, 3), ``face_offset`` (F,) (camera
    frame) and ``face_body`` (F,) (the body of each face); ``light``: (3,) unit vector to the light.
    ``not_receiver`` (F,) bool: faces left out as receivers (the facets of curved faces)."""
    h, w = gface.shape
    out = np.zeros((h, w), np.uint8)
    towards = face_normal @ light
    present = np.bincount(gface.ravel() + 1, minlength=len(face_normal) + 1)[1:] > 0
    # faces turned away get no direct light (a shadow changes nothing); unseen faces need none
    receiving = (towards > 1e-6) & present & (face_offset > _EPS)
    if not_receiver is not None:
        receiving &= ~not_receiver
    receivers = np.flatnonzero(receiving)
    if len(receivers) == 0:
        return out
    first = np.concatenate([[0], np.cumsum([len(b.solid.faces) for b in bodies])])
    verts = [b.vertices() for b in bodies]
    rpolys = [verts[face_body[g]][list(bodies[face_body[g]].solid.faces[g - first[face_body[g]]])] for g in receivers]
    n_r, d_r = face_normal[receivers], face_offset[receivers]
    # pairs (receiver, caster) that can cast anything, tested for all pairs at once:
    # some caster vertex lies between the receiver's plane and the light ...
    vstart = np.concatenate([[0], np.cumsum([len(v) for v in verts])[:-1]])
    between = np.maximum.reduceat(np.concatenate(verts) @ n_r.T + d_r, vstart, axis=0).T > _EPS  # (R, B)
    # ... and no caster face turned to the light has the whole receiver face in front of it (then the
    # rays from the receiver to the light move away from the convex caster)
    rstart = np.concatenate([[0], np.cumsum([len(p) for p in rpolys])[:-1]])
    in_front = np.minimum.reduceat(np.concatenate(rpolys) @ face_normal.T + face_offset, rstart, axis=0) >= -1e-7
    separated = np.logical_or.reduceat(in_front & (towards >= 0), first[:-1], axis=1)  # (R, B)
    cast = between & ~separated
    cast[np.arange(len(receivers)), face_body[receivers]] = False  # a convex body never shadows its lit faces
    edges: dict[int, np.ndarray] = {}
    for j in np.flatnonzero(cast.any(axis=1)):
        g = receivers[j]
        n, d = face_normal[g], float(face_offset[g])
        rbox = _pixel_box(rpolys[j], k)
        if rbox is None:
            continue
        basis = _plane_basis(n)
        for i in np.flatnonzero(cast[j]):
            if i not in edges:
                edges[i] = _edges(bodies[i])
            poly = shadow_polygon(verts[i], edges[i], n, d, light, basis)
            box = None if poly is None else _pixel_box(poly, k)
            if box is None:
                continue
            uv, lo, hi = box
            lo, hi = np.maximum(lo, rbox[1]), np.minimum(hi, rbox[2])  # only where the receiver can be
            if np.any(hi <= lo):
                continue
            win = (slice(lo[1], hi[1]), slice(lo[0], hi[0]))
            fill = convex_mask(uv - lo, (hi[1] - lo[1], hi[0] - lo[0]))
            fill &= gface[win] == g
            out[win] |= fill.view(np.uint8)
    return out


def soft_shadow(bodies: list[Body], gface: np.ndarray, face_normal: np.ndarray, face_offset: np.ndarray,
                face_body: np.ndarray, k: Intrinsics, light: np.ndarray, not_receiver: np.ndarray | None = None,
                extra: np.ndarray | None = None) -> np.ndarray:
    """(H, W) float32 in 0..1: the :func:`shadow_mask` (``not_receiver`` as there), joined with ``extra``
    (H, W) uint8 when given (the shadows on curved faces), with edges softened over about two pixels at
    640x480 (a penumbra, and no staircase)."""
    m = shadow_mask(bodies, gface, face_normal, face_offset, face_body, k, light, not_receiver)
    if extra is not None:
        m |= extra
    out = np.zeros(m.shape, np.float32)
    rows, cols = np.flatnonzero(m.any(axis=1)), np.flatnonzero(m.any(axis=0))
    if len(rows) == 0:
        return out
    sigma = max(0.5, 0.9 * k.width / 640.0)
    # blur only around the shadows: beyond a kernel radius of them the result is 0 anyway
    r = int(np.ceil(4 * sigma)) + 1
    win = (slice(max(rows[0] - r, 0), rows[-1] + r + 1), slice(max(cols[0] - r, 0), cols[-1] + r + 1))
    k_size = 2 * r + 1
    out[win] = cv2.GaussianBlur(m[win] * np.float32(1.0), (k_size, k_size), sigma)
    return out
