"""Splitting a non-convex colour face into the convex faces it merged.

Every face of the solids is convex, so a traced face with a reflex corner is two faces whose shared edge the
line detector missed (two faces of one colour under nearly the same shading). That edge runs from the reflex
corner to another corner of the outline; of the cuts that leave two convex parts, the one with the strongest
image gradient along it is taken.
"""

from __future__ import annotations

import functools

import cv2
import numpy as np

from ..polygons import area, following, outline_distance, pixel_values, preceding, signed_area


def reflex_corners(poly: np.ndarray, tol_deg: float = 4.0) -> list[int]:
    """Indices of the corners of ``poly`` (n, 2) where it turns against its orientation by more than
    ``tol_deg`` degrees."""
    p = np.asarray(poly, np.float64)
    d_in = p - preceding(p)
    d_out = following(p) - p
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    sin = cross / np.maximum(np.linalg.norm(d_in, axis=1) * np.linalg.norm(d_out, axis=1), 1e-9)
    sign = 1.0 if signed_area(p) > 0 else -1.0
    return [int(i) for i in np.nonzero(sign * sin < -np.sin(np.radians(tol_deg)))[0]]


def _line_strength(a: np.ndarray, b: np.ndarray, grad: np.ndarray, trim_px: float = 3.0) -> float:
    """Mean gradient magnitude along segment ab, leaving out ``trim_px`` at each end (corners are strong)."""
    length = float(np.hypot(*(b - a)))
    if length <= 2 * trim_px + 2:
        return 0.0
    t = np.linspace(trim_px / length, 1 - trim_px / length, max(4, int(length)))
    pts = a + t[:, None] * (b - a)
    return float(pixel_values(grad, pts).mean())


def _diagonal_samples(p: np.ndarray, pairs: list[tuple[int, int]], grad: np.ndarray,
                      trim_px: float = 3.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points along each diagonal (i, j) of the polygon ``p`` (n, 2), as :func:`_line_strength` samples them
    (``trim_px`` left out at each end): which diagonal each point belongs to (m,), the gradient magnitude there
    (m,) and its distance to the polygon's outline (m,), in pixels. All diagonals in one go: the polygons are
    small and numpy calls cost more than the arithmetic."""
    pts, owner = [], []
    for k, (i, j) in enumerate(pairs):
        length = float(np.hypot(*(p[j] - p[i])))
        if length <= 2 * trim_px + 2:
            continue
        t = np.linspace(trim_px / length, 1 - trim_px / length, max(4, int(length)))
        pts.append(p[i] + t[:, None] * (p[j] - p[i]))
        owner.append(np.full(len(t), k))
    if not pts:
        return np.zeros(0, int), np.zeros(0), np.zeros(0)
    pts = np.concatenate(pts)
    return np.concatenate(owner), pixel_values(grad, pts), outline_distance(pts, p)


def _mean_clear_of_outline(n_pairs: int, owner: np.ndarray, values: np.ndarray, clearance: np.ndarray,
                           clear_px: float) -> np.ndarray:
    """Mean gradient magnitude (n_pairs,) along each diagonal over its samples (from :func:`_diagonal_samples`)
    lying ``clear_px`` or more from the outline: a diagonal that runs close along the outline would pick up the
    outline's own edge (0 when no point is left)."""
    clear = clearance >= clear_px
    total = np.bincount(owner[clear], weights=values[clear], minlength=n_pairs)
    count = np.bincount(owner[clear], minlength=n_pairs)
    out = np.zeros(n_pairs)
    np.divide(total, count, out=out, where=count > 0)
    return out


def split_concave(poly: np.ndarray, grad: np.ndarray, min_area_px: float, depth: int = 2) -> list[np.ndarray]:
    """Convex pieces of ``poly`` (n, 2) pixels: ``[poly]`` when it is convex (or cannot be cut into convex
    parts), else the parts of the best cut from a reflex corner to another corner, each split again up to
    ``depth`` times. ``grad``: gradient magnitude (H, W) in the polygon's pixel frame. Parts smaller than
    ``min_area_px`` make a cut invalid."""
    p = np.asarray(poly, np.float64)
    n = len(p)
    reflex = reflex_corners(p)
    if not reflex or depth == 0 or n < 4:
        return [p]
    best, best_score = None, -1.0
    for r in reflex:
        for k in range(n):
            if k in (r, (r + 1) % n, (r - 1) % n):
                continue
            i, j = min(r, k), max(r, k)
            a, b = p[i:j + 1], np.concatenate([p[j:], p[:i + 1]])
            if len(a) < 3 or len(b) < 3 or min(area(a), area(b)) < min_area_px:
                continue
            # a cut must remove the reflex corner from both parts' sight: at least one part convex, and it
            # must not leave the face (the segment's midpoint inside it)
            mid = 0.5 * (p[i] + p[j])
            if cv2.pointPolygonTest(p.astype(np.float32).reshape(-1, 1, 2), (float(mid[0]), float(mid[1])),
                                    False) < 0:
                continue
            fewer = len(reflex_corners(a)) + len(reflex_corners(b))
            score = _line_strength(p[i], p[j], grad) - 1000.0 * fewer
            if score > best_score:
                best, best_score = (a, b), score
    if best is None:
        return [p]
    return [q for part in best for q in split_concave(part, grad, min_area_px, depth - 1)]


def split_by_diagonal(poly: np.ndarray, grad: np.ndarray, min_area_px: float, rel_interior: float = 3.0,
                      min_strength: float = 20.0, rel_boundary: float = 0.1, faint_rel_interior: float = 1.5,
                      faint_clear_px: float = 2.5) -> list[np.ndarray]:
    """``poly`` cut along its strongest diagonal (corner to corner) when the image has an edge there that the
    line detector missed: a thin face merged with its neighbour makes a convex outline, so only the gradient
    can tell. The diagonal's mean gradient must exceed ``rel_interior`` times the 90th percentile of the
    gradient inside the face (texture, noise), ``min_strength``, and ``rel_boundary`` times the outline's.

    Failing that, a fainter edge is cut at ``faint_rel_interior`` times that percentile, measured only where
    the diagonal lies ``faint_clear_px`` or more from the outline. The diagonal's figure is a mean over tens of
    pixels, in which sensor noise averages out, while the percentile is one pixel's: on noisy (realsense)
    renders the edges between two faces of one colour measured 1.5-2.6 times it, diagonals across one face at
    most 0.9 times (dev seeds 1000 and 2000). The wider clearance keeps out the outline's own edge, 2-3 px wide
    in a blurred image: measured 1 px clear, diagonals skipping a corner at a shallow angle passed the lower
    factor and cut 244-1093 px slivers off three realsense rgbd faces; measured 2.5 px clear in the first test
    too, a clean face was not cut (square pyramid, dev seed 1000).
    Returns ``[poly]`` when no diagonal qualifies, or when the face is too thin to have an interior (a face seen
    edge-on)."""
    p = np.asarray(poly, np.float64)
    n = len(p)
    if n < 4:
        return [p]
    pairs = [(i, j) for i in range(n) for j in range(i + 2, n) if not (i == 0 and j == n - 1)]
    # both tests read the same samples along the diagonals, thresholded at their own clearance
    samples = _diagonal_samples(p, pairs, grad)

    @functools.cache
    def boundary():  # the outline's mean strength, measured once and only when a test gets that far
        return np.mean([_line_strength(p[k], p[(k + 1) % n], grad) for k in range(n)])

    for rel, clear in ((rel_interior, 1.0), (faint_rel_interior, faint_clear_px)):
        strengths = _mean_clear_of_outline(len(pairs), *samples, clear)
        parts = _cut(p, pairs, strengths, grad, min_area_px, rel, min_strength, rel_boundary, boundary)
        if parts is not None:
            return parts
    return [p]


def _cut(p: np.ndarray, pairs: list[tuple[int, int]], strengths: np.ndarray, grad: np.ndarray,
         min_area_px: float, rel_interior: float, min_strength: float, rel_boundary: float,
         boundary) -> list[np.ndarray] | None:
    """The two parts of ``p`` (n >= 4, 2) cut along its strongest diagonal (``strengths`` of ``pairs``), when
    that passes :func:`split_by_diagonal`'s tests with ``rel_interior``; else None. ``boundary()``: the
    outline's mean strength."""
    strength, i, j = max((float(st), i, j) for st, (i, j) in zip(strengths, pairs))
    if strength < min_strength:
        return None
    a, b = p[i:j + 1], np.concatenate([p[j:], p[:i + 1]])
    if min(area(a), area(b)) < min_area_px:
        return None
    if strength < rel_boundary * boundary():
        return None
    # the interior: the polygon shrunk by a few pixels, in a box around it
    u0, v0 = np.floor(p.min(axis=0)).astype(int)
    u1, v1 = np.ceil(p.max(axis=0)).astype(int) + 1
    h, w = grad.shape
    u0, v0, u1, v1 = max(0, u0), max(0, v0), min(w, u1), min(h, v1)
    m = np.zeros((v1 - v0, u1 - u0), np.uint8)
    cv2.fillPoly(m, [np.round(p - [u0, v0]).astype(np.int32)], 1)
    m = cv2.erode(m, np.ones((7, 7), np.uint8))
    # leave out a band along the diagonal itself, or the edge being tested counts as interior texture
    cv2.line(m, tuple(int(x) for x in np.round(p[i] - [u0, v0])), tuple(int(x) for x in np.round(p[j] - [u0, v0])),
             0, 7)
    inner = grad[v0:v1, u0:u1][m.astype(bool)]
    # a sliver has no interior: its diagonals run so close to its sides that their gradient says nothing
    if not inner.size or strength < rel_interior * float(np.percentile(inner, 90)):
        return None
    return [a, b]
