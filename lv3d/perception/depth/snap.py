"""Depth face polygons snapped to plane intersections.

A polygon traced from a plane's grid mask sits a cell or two inside the true face, its bottom side is cut off
with the noise band above the support plane, and its corners are rounded off into short extra sides. The
sides a face shares with a neighbouring plane (or with the support plane) lie on the image of the two planes'
3D intersection line, which the plane fits know far better than the mask does. So each side that runs along
such a line is moved onto it, sides too short to be real are dropped, and the corners are recomputed as the
crossings of consecutive side lines. A result that is not a convex polygon near the original is discarded.
"""

from __future__ import annotations

import cv2
import numpy as np

from ...camera import Intrinsics
from ...plane import Plane
from ..polygons import area, clockwise

_Line = tuple[np.ndarray, np.ndarray]  # (point, unit direction) in pixels


def _meet(a: _Line, b: _Line) -> np.ndarray | None:
    """Crossing of two image lines, None when they are nearly parallel."""
    (p, u), (q, v) = a, b
    cross = u[0] * v[1] - u[1] * v[0]
    if abs(cross) < np.sin(np.radians(8.0)):
        return None
    d = q - p
    s = (d[0] * v[1] - d[1] * v[0]) / cross
    return p + s * u


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two 3-vectors (np.cross costs ten times more on single vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _intersection_line(pi: Plane, pj: Plane, near: np.ndarray, k: Intrinsics) -> _Line | None:
    """Image of the 3D line where planes ``pi`` and ``pj`` meet, around the camera-frame point ``near`` (m).
    Written with 3-vectors in plain numpy (no solve/project calls): it runs for every side of every face."""
    ni, nj = pi.n, pj.n
    d = cross3(ni, nj)
    nd = float(np.sqrt(d @ d))
    if nd < np.sin(np.radians(10.0)):
        return None
    d = d / nd
    # the point of the line nearest ``near``: n_i.x = -o_i, n_j.x = -o_j, d.x = d.near, by Cramer's rule
    # with rows (n_i, n_j, d), whose determinant is d . (n_i x n_j) = nd
    rhs = (-pi.offset, -pj.offset, float(d @ near))
    x0 = (rhs[0] * cross3(nj, d) + rhs[1] * cross3(d, ni) + rhs[2] * cross3(ni, nj)) / nd
    a, b = x0 - 0.03 * d, x0 + 0.03 * d
    if a[2] <= 0.05 or b[2] <= 0.05:
        return None
    ua = np.array([k.fx * a[0] / a[2] + k.cx, k.fy * a[1] / a[2] + k.cy])
    ub = np.array([k.fx * b[0] / b[2] + k.cx, k.fy * b[1] / b[2] + k.cy])
    u = ub - ua
    n = float(np.hypot(u[0], u[1]))
    if n < 1e-6:
        return None
    return ua, u / n


def _convex(poly: np.ndarray) -> bool:
    """Every turn the same way and one full turn in all: convex and simple."""
    d = np.diff(np.vstack([poly, poly[:1]]), axis=0)
    e = np.vstack([d[1:], d[:1]])
    cross = d[:, 0] * e[:, 1] - d[:, 1] * e[:, 0]
    if not (np.all(cross > 0) or np.all(cross < 0)):
        return False
    turn = np.arctan2(cross, (d * e).sum(axis=1))
    return bool(abs(abs(turn.sum()) - 2 * np.pi) < 1e-3)


def snap_polygon(poly: np.ndarray, plane: Plane, others: list[Plane], k: Intrinsics, near_m: float,
                 max_move_px: float = 14.0, short_frac: float = 0.2) -> np.ndarray:
    """``poly`` (n, 2) pixels, the traced outline of the face on ``plane``, with each side whose two ends lie on
    average within ``near_m`` metres (in 3D, on ``plane``) of one of ``others`` (neighbour and support planes)
    moved onto that intersection line, unsnapped sides shorter than ``short_frac`` of the mean side dropped, and
    the corners recomputed. Returns the input when the result is not convex or moves a corner more than
    ``max_move_px`` plus a tenth of the face's size (square root of its area, px). ``k``: the camera."""
    n = len(poly)
    if n < 3:
        return poly
    ends3d = plane.intersect_rays(k.rays(poly))  # (n, 3) metres
    if np.any(~np.isfinite(ends3d)) or np.any(ends3d[:, 2] <= 0):
        return poly
    lines: list[_Line] = []
    snapped = np.zeros(n, bool)
    # each other plane claims at most one side (a convex face meets a plane along one edge): the longest of
    # those whose ends lie within ``near_m`` of it on average (one end of a traced side often strays further)
    length = np.linalg.norm(np.vstack([poly[1:], poly[:1]]) - poly, axis=1)
    claims: dict[int, tuple[float, int]] = {}
    for j, q in enumerate(others):
        dist = np.abs(q.distance(ends3d))
        side = 0.5 * (dist + np.append(dist[1:], dist[0]))  # side s runs from vertex s to s+1
        cand = np.nonzero(side <= near_m)[0]
        if len(cand) == 0:
            continue
        s = int(cand[np.argmax(length[cand])])
        if s not in claims or side[s] < claims[s][0]:
            claims[s] = (float(side[s]), j)
    for s in range(n):
        a, b = poly[s], poly[(s + 1) % n]
        line = None
        if s in claims:
            mid = 0.5 * (ends3d[s] + ends3d[(s + 1) % n])
            line = _intersection_line(plane, others[claims[s][1]], mid, k)
            if line is not None:
                # the snapped line must run roughly along the traced side
                u = (b - a) / max(np.linalg.norm(b - a), 1e-9)
                if abs(u @ line[1]) < np.cos(np.radians(20.0)):
                    line = None
        if line is None:
            u = b - a
            line = (a, u / max(np.linalg.norm(u), 1e-9))
        else:
            snapped[s] = True
        lines.append(line)
    # drop unsnapped sides much shorter than the rest: rounded-off corners, not edges of the face. Lengths on
    # the plane: in the image a face seen edge-on has its true short sides squeezed to a few pixels
    length3 = np.linalg.norm(np.vstack([ends3d[1:], ends3d[:1]]) - ends3d, axis=1)
    keep = [s for s in range(n) if snapped[s] or length3[s] >= short_frac * length3.mean()]
    out = _corners(poly, [lines[s] for s in keep], max_move_px)
    if out is None:
        # a corner cut off further (a sharp apex whose tip went to the neighbour's mask): try without the
        # short unsnapped sides next to a snapped one
        keep = [s for s in keep if snapped[s] or length3[s] >= 0.35 * length3.mean()
                or not (snapped[s - 1] or snapped[(s + 1) % n])]
        out = _corners(poly, [lines[s] for s in keep], max_move_px)
    return poly if out is None else clockwise(out)


def _corners(poly: np.ndarray, lines: list[_Line], max_move_px: float) -> np.ndarray | None:
    """The polygon whose sides lie on ``lines`` (in order), or None when it is no convex polygon whose corners
    stay near those of ``poly``."""
    if len(lines) < 3:
        return None
    out = []
    for i in range(len(lines)):
        p = _meet(lines[i - 1], lines[i])
        if p is None:
            return None
        out.append(p)
    out = np.array(out)
    # each new corner is the crossing of two traced sides: it must stay near the traced outline's corners
    d = np.linalg.norm(out[:, None, :] - poly[None, :, :], axis=2).min(axis=1)
    if np.any(d > max_move_px + 0.1 * np.sqrt(area(poly))) or not _convex(out) or area(out) < 0.5 * area(poly):
        return None
    return out


def snap_polygons(polys: list[np.ndarray | None], planes: list[Plane], adjacency: list[tuple[int, int]],
                  support: Plane | None, k: Intrinsics, near_m: float) -> list[np.ndarray | None]:
    """:func:`snap_polygon` for each face of one object: its neighbours are the planes adjacent to it, and the
    support plane."""
    out = []
    for i, poly in enumerate(polys):
        if poly is None:
            out.append(None)
            continue
        others = [planes[b if a == i else a] for a, b in adjacency if i in (a, b)]
        if support is not None:
            others.append(support)
        out.append(snap_polygon(poly, planes[i], others, k, near_m))
    return out


def _triple_point(a: Plane, b: Plane, c: Plane, min_det: float = 0.15) -> np.ndarray | None:
    """The point (3,) metres where three planes meet; None when two of them are nearly parallel or all three
    nearly share a direction (the lateral faces of a prism meet along parallel lines, at no point)."""
    n = np.stack([a.n, b.n, c.n])
    if abs(np.linalg.det(n)) < min_det:
        return None
    return np.linalg.solve(n, -np.array([a.offset, b.offset, c.offset]))


def add_triple_corners(polys: list[np.ndarray | None], planes: list[Plane], adjacency: list[tuple[int, int]],
                       k: Intrinsics, max_px: float = 12.0, min_gap_px: float = 3.0) -> list[np.ndarray | None]:
    """Each face's outline (n, 2) pixels with the corners it lost put back: where the face and two of its
    neighbours that neighbour each other meet (their planes' common point, projected) there is a corner of the
    face. A face seen edge-on is a few grid cells wide and its traced hull cuts such a corner off (3 sides for
    4). A point is added, as a vertex of the outline's convex hull with it, only when it lies outside the
    outline by at most ``max_px`` pixels and at least ``min_gap_px`` from every vertex."""
    nb: dict[int, set[int]] = {}
    for a, b in adjacency:
        nb.setdefault(a, set()).add(b)
        nb.setdefault(b, set()).add(a)
    out = list(polys)
    for i, poly in enumerate(polys):
        if poly is None or i not in nb:
            continue
        p = np.asarray(poly, np.float64)
        extra = []
        ns = sorted(nb[i])
        for x, a in enumerate(ns):
            for b in ns[x + 1:]:
                if b not in nb.get(a, ()):
                    continue
                X = _triple_point(planes[i], planes[a], planes[b])
                if X is None or X[2] <= 0:
                    continue
                q = k.project(X[None])[0]
                if np.min(np.linalg.norm(p - q, axis=1)) < min_gap_px:
                    continue
                dist = cv2.pointPolygonTest(p.astype(np.float32).reshape(-1, 1, 2), (float(q[0]), float(q[1])), True)
                if -max_px <= dist < -1.0:  # outside, near: a cut-off corner
                    extra.append(q)
        if not extra:
            continue
        hull = cv2.convexHull(np.concatenate([p, np.array(extra)]).astype(np.float32)).reshape(-1, 2)
        if len(hull) > len(p):
            out[i] = clockwise(hull.astype(np.float64))
    return out
