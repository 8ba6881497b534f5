"""Small polygon helpers. A polygon is an (n, 2) float array of pixel vertices (u right, v down), in order,
not closed (the last vertex joins the first)."""

from __future__ import annotations

import math

import cv2
import numpy as np

# a corner cutting off more than this fraction of a face's area is kept however little it turns (simplify's
# keep_area_frac, for traced colour outlines and depth mask outlines)
KEEP_AREA = 0.1


def following(p: np.ndarray) -> np.ndarray:
    """Each vertex's successor around the closed polygon ``p`` (n, ...): ``np.roll(p, -1, axis=0)``, the same
    array, at a fraction of its cost on a polygon's few vertices (its generality costs more than the copy)."""
    return np.concatenate((p[1:], p[:1]))


def preceding(p: np.ndarray) -> np.ndarray:
    """Each vertex's predecessor around the closed polygon ``p`` (n, ...): ``np.roll(p, 1, axis=0)``, the same
    array."""
    return np.concatenate((p[-1:], p[:-1]))


def pair_dots(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The dot products of pixel vectors ``a`` and ``b`` (..., 2), broadcast: ``(a * b).sum(-1)``, the same numbers
    (numpy's reduce adds the two products as written here) at a fraction of its cost, which a reduction over an
    axis two long spends on its generality."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area in pixels^2; positive when the vertices run clockwise in the image (v down)."""
    p = np.asarray(poly, dtype=np.float64)
    x, y = p[:, 0], p[:, 1]
    # shoelace with the closing term written out: np.roll is slow on these tiny arrays
    return 0.5 * float(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1]) + x[-1] * y[0] - x[0] * y[-1])


def area(poly: np.ndarray) -> float:
    return abs(signed_area(poly))


def perimeter(poly: np.ndarray) -> float:
    p = np.asarray(poly, dtype=np.float64)
    return float(np.linalg.norm(following(p) - p, axis=1).sum())


def mean_width(poly: np.ndarray, area_px: float | None = None, perimeter_px: float | None = None) -> float:
    """Twice the area over the perimeter (px): a long strip's width, a sliver's measure. ``area_px`` and
    ``perimeter_px`` are the area and perimeter when the caller has them already (measured here otherwise)."""
    return 2.0 * (area(poly) if area_px is None else area_px) / (perimeter(poly) if perimeter_px is None
                                                                 else perimeter_px)


def _segments_cross(a, b, c, d) -> bool:
    """Proper crossing of segments ab and cd (touching at a shared end does not count)."""
    def orient(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    return (o1 * o2 < 0) and (o3 * o4 < 0)


def is_simple(poly: np.ndarray) -> bool:
    """True when no two non-neighbouring sides cross and no vertex repeats."""
    p = np.asarray(poly, dtype=np.float64)
    n = len(p)
    if n < 3:
        return False
    if len(np.unique(np.round(p, 3), axis=0)) != n:
        return False
    for i in range(n):
        a, b = p[i], p[(i + 1) % n]
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # neighbours through the closing side
            if _segments_cross(a, b, p[j], p[(j + 1) % n]):
                return False
    return True


def simplify(poly: np.ndarray, rel_tol: float = 0.06, abs_tol: float = 2.0, min_turn_deg: float = 12.0,
             keep_area_frac: float | None = None) -> np.ndarray:
    """Drop nearly-collinear vertices until only the true corners remain: repeatedly remove the vertex that
    deviates least from the chord of its neighbours while that deviation is under
    ``max(abs_tol px, rel_tol * chord)`` or the direction turns there by less than ``min_turn_deg``. With
    ``keep_area_frac``, a vertex whose removal would cut off more than that fraction of the polygon's area is a
    corner whatever its deviation and turn: a face seen edge-on is a sliver whose corners lie a few px off the
    chord of their neighbours and turn little, yet hold much of its area."""
    p = [(float(u), float(v)) for u, v in np.asarray(poly, dtype=np.float64)]
    max_cut = math.inf if keep_area_frac is None else keep_area_frac * area(poly)

    def score(i: int) -> float:
        """dev / chord of vertex i, or inf when it is a corner to keep (plain floats: numpy calls on 2-vectors
        cost more than the arithmetic)."""
        (ax, ay), (bx, by), (cx, cy) = p[i - 1], p[i], p[(i + 1) % len(p)]
        chx, chy = cx - ax, cy - ay
        L = math.hypot(chx, chy)
        if L < 1e-9:
            return 0.0  # a vertex between two that coincide: no deviation
        dev = abs(chx * (by - ay) - chy * (bx - ax)) / L
        d1x, d1y, d2x, d2y = bx - ax, by - ay, cx - bx, cy - by
        n1, n2 = math.hypot(d1x, d1y), math.hypot(d2x, d2y)
        turn = 0.0 if n1 < 1e-9 or n2 < 1e-9 else math.degrees(
            math.acos(min(1.0, max(-1.0, (d1x * d2x + d1y * d2y) / (n1 * n2)))))
        ok = (dev < max(abs_tol, rel_tol * L) or turn < min_turn_deg) and 0.5 * dev * L <= max_cut
        return dev / L if ok else math.inf

    scores = [score(i) for i in range(len(p))]
    while len(p) > 3:
        best = min(range(len(p)), key=scores.__getitem__)  # the first of equal scores, as before
        if scores[best] == math.inf:
            break
        p.pop(best)
        scores.pop(best)
        # only the two neighbours of the removed vertex have new chords
        n = len(p)
        for i in ((best - 1) % n, best % n):
            scores[i] = score(i)
    return np.array(p, dtype=np.float64)


def clockwise(poly: np.ndarray) -> np.ndarray:
    """The same polygon with its vertices clockwise in the image (v down), starting at the top-left-most."""
    p = np.asarray(poly, dtype=np.float64)
    if signed_area(p) < 0:
        p = p[::-1]
    start = int(np.lexsort((p[:, 0], p[:, 1]))[0])
    return np.concatenate([p[start:], p[:start]])


def rasterize(poly: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Boolean (H, W) mask of the pixels inside the polygon."""
    m = np.zeros(shape, np.uint8)
    cv2.fillPoly(m, [np.round(np.asarray(poly)).astype(np.int32)], 1)
    return m.astype(bool)


def distance_to_segments(points: np.ndarray, starts: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Distance (m,) in pixels from each of ``points`` (m, 2) to the nearest of the segments from ``starts``
    (k, 2) to ``starts + steps`` (k, 2)."""
    rel = points[:, None, :] - starts[None]
    t = np.clip(pair_dots(rel, steps[None]) / np.maximum(pair_dots(steps, steps), 1e-12), 0.0, 1.0)
    # the offsets from the nearest points, each coordinate written out: the numbers of
    # ((rel - t[..., None] * steps) ** 2).sum(-1)
    du = rel[..., 0] - t * steps[:, 0]
    dv = rel[..., 1] - t * steps[:, 1]
    return np.sqrt(du * du + dv * dv).min(axis=1)


def outline_distance(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance (m,) in pixels from each of ``points`` (m, 2) to the closed outline of ``poly`` (n, 2)."""
    p = np.asarray(poly, dtype=np.float64)
    return distance_to_segments(points, p, following(p) - p)


def pixel_values(img: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Values of ``img`` (H, W) at the pixels nearest the points (m, 2) (u, v pixels), clipped to the image."""
    h, w = img.shape[:2]
    u = np.clip(np.round(pts[:, 0]).astype(int), 0, w - 1)
    v = np.clip(np.round(pts[:, 1]).astype(int), 0, h - 1)
    return img[v, u]


def sample_boundary(poly: np.ndarray, step: float = 1.0) -> np.ndarray:
    """Points (m, 2) every ``step`` pixels along the closed boundary."""
    p = np.asarray(poly, dtype=np.float64)
    d = np.concatenate([p[1:], p[:1]]) - p
    k = np.maximum(1, np.ceil(np.hypot(d[:, 0], d[:, 1]) / step).astype(int))
    side = np.repeat(np.arange(len(p)), k)
    # position along its side of each sample: 0, 1/k, ..., (k-1)/k
    t = (np.arange(len(side)) - np.repeat(np.cumsum(k) - k, k)) / k[side]
    return p[side] + t[:, None] * d[side]


def _crossing(p: np.ndarray, s: int) -> np.ndarray | None:
    """Where the sides before and after side s (p[s] -> p[s+1]) of the closed polygon ``p`` cross, or None
    where they are parallel."""
    n = len(p)
    a0, b0 = p[s - 1], p[(s + 1) % n]
    u, v = p[s] - a0, p[(s + 2) % n] - b0
    cross = u[0] * v[1] - u[1] * v[0]
    if abs(cross) < 1e-9 * max(1.0, np.hypot(*u) * np.hypot(*v)):
        return None
    w = b0 - a0
    return a0 + (w[0] * v[1] - w[1] * v[0]) / cross * u


def _join_side(p: np.ndarray, s: int, x: np.ndarray) -> np.ndarray:
    """``p`` with side s's two corners made one, at ``x``."""
    n = len(p)
    p = np.delete(p, (s + 1) % n, axis=0)
    p[s if (s + 1) % n != 0 or s == 0 else s - 1] = x
    return p


def _shortest_side(p: np.ndarray) -> tuple[int, np.ndarray]:
    d = following(p) - p
    length = np.hypot(d[:, 0], d[:, 1])
    return int(np.argmin(length)), length


def drop_short_sides(poly: np.ndarray, rel_len: float = 0.15, reach: float = 1.5) -> np.ndarray:
    """Remove sides shorter than ``rel_len`` of the mean side by extending their neighbours to where they
    cross, if that point lies within ``reach`` times the side's length (+2 px) of it: a junction of three
    edges is often traced as two corners a few pixels apart, and no face of the solids has such a side."""
    p = np.asarray(poly, dtype=np.float64)
    while len(p) > 3:
        s, length = _shortest_side(p)
        if length[s] >= rel_len * length.mean():
            break
        x = _crossing(p, s)
        if x is None or np.hypot(*(x - 0.5 * (p[s] + p[(s + 1) % len(p)]))) > reach * length[s] + 2.0:
            break
        p = _join_side(p, s, x)
    return p


def merge_close_corners(poly: np.ndarray, min_len: float) -> np.ndarray:
    """Join each pair of neighbouring corners closer than ``min_len`` px into one corner: the crossing of the
    sides on either side of them where that lies within ``min_len`` of their midpoint, else the midpoint. A side
    shorter than the grid that traced it can measure is one corner cut off."""
    p = np.asarray(poly, dtype=np.float64)
    while len(p) > 3:
        s, length = _shortest_side(p)
        if length[s] >= min_len:
            break
        mid = 0.5 * (p[s] + p[(s + 1) % len(p)])
        x = _crossing(p, s)
        p = _join_side(p, s, x if x is not None and np.hypot(*(x - mid)) <= min_len else mid)
    return p
