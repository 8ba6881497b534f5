"""Faces grouped into solids by colour alone, by the edges they share and the silhouette they lie in, never by hue.

A solid's faces may be of any colours (a box printed in three, a cube painted face by face) and one face of a
single-hue solid may be shaded far darker than the rest: the hue of a face says nothing of the solid it belongs
to. What holds whatever the paint is the line drawing:

- faces of one solid share edges (the planar graph's, or the cut between two parts of one traced outline) and lie
  in one silhouette, one region that differs from the background (silhouette.foreground): faces on two regions
  are never joined;
- two neighbouring faces of one solid share a whole side: where their common boundary ends, both outlines turn (a
  corner of each: the Y and arrow junctions of a line drawing). Where one solid hides part of another, or stands
  against it, the boundary they share ends where the hidden solid's side meets the front one's outline, which
  runs on straight past it: a T junction, the outline of one turning there and the other's not.

So faces are joined in groups, two neighbouring groups at a time, while no end of the boundary they share is a T
junction (group_solids); the pair sharing the longest boundary is joined first, and the outline of a joined group
is that of its faces together, so that a face cut in two by a printed edge (each part's corner a T on its
neighbour's side) joins its neighbour once its parts are one. Within a solid, the parts of one face are then one
face again (one_face_parts): two parts whose shared line ends where their outline together runs straight (an
edge of a convex solid ends at a corner of its outline or of another face, a print's edge anywhere), and a part
that does not reach the solid's outline (a label) with the parts around it.

Hand-written: the tests read a few points of two outlines per pair of groups; no library groups faces by their
junctions. Outlines of groups are drawn on a mask at a quarter pixel (OpenCV) and read as polygons.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ..polygons import following, outline_distance, pair_dots, sample_boundary


@dataclass(frozen=True)
class SolidSettings:
    """Thresholds of the grouping, lengths as fractions of the image diagonal or of a face's size, angles in
    degrees, each with its reason."""

    # two outlines touch where they run within this fraction of the image diagonal of each other (2.4 px at
    # 640x480): faces traced from one graph share its vertices, and their simplified outlines stray from them by a
    # pixel or two
    contact_frac: float = 0.003
    # a point of one outline runs along another where, besides, their sides there run within this (deg) of each
    # other: the sides of two faces on one graph edge run within a few degrees of each other, while the outlines
    # of two solids touching corner to corner meet at an angle and part at once
    align_deg: float = 10.0
    # two groups share a boundary when it is at least this fraction of the smaller one's perimeter: a face shares
    # a whole side with a neighbour on its solid (a quarter of a square's perimeter, near half of a sliver's),
    # while the outlines of two solids that the graph joined where they nearly touch run together for a few pixels
    min_contact: float = 0.08
    # an outline's turn at a point is measured between chords this fraction of the image diagonal long either
    # side of it (9.6 px at 640x480), the sharpest within half a chord of the point: long enough to hold a
    # direction on outlines drawn to a quarter pixel and to reach the corner where two outlines part a pixel or two
    # off it, short enough that a corner two chords away on an outline running straight through the point is not
    # read as its own
    chord_frac: float = 0.012
    # an outline runs straight through a point where it turns less than this (deg) and has a corner there where it
    # turns more than ``corner_deg``; between the two nothing is read (a blunt corner, or one that blur rounds
    # off, of a many-sided outline)
    straight_deg: float = 15.0
    corner_deg: float = 35.0
    # an outline whose sides, a chord or two either side of a corner, turn by more than this (deg) comes to a tip
    # there rather than leaving another outline: a face seen nearly edge-on comes to a point that the graph often
    # traces short or blunt beside its neighbour's side, while a side hidden behind another solid leaves its
    # outline at any angle and runs on
    tip_deg: float = 150.0
    # a line drawn across a face ends where the outline of the parts either side of it, together, turns by less
    # than this (deg): the face's side runs on straight there, as it does not past a corner of the solid
    line_deg: float = 15.0
    # parts of one face are convex together: their area at least this share of their convex hull's (the outline
    # of parts traced apart bends by a pixel or two where they meet)
    min_convex: float = 0.95
    # where two parts of one face meet, the outline of the two together is read between chords no longer than
    # this fraction of the narrower part's width (twice its area over its perimeter): a printed band may be a few
    # pixels wide, and longer chords reach the corners of the face it crosses
    part_chord: float = 0.5


SETTINGS = SolidSettings()


@dataclass
class _Group:
    members: list[int]
    poly: np.ndarray     # (k, 2) the outline of the members together, clockwise
    outline: np.ndarray  # (m, 2) points every pixel along it
    heading: np.ndarray  # (m, 2) the unit direction of the side of ``poly`` each point of ``outline`` lies on
    area: float


def group_solids(polys: list[np.ndarray], pairs: list[tuple[int, int]], shape: tuple[int, int],
                 region: list[int] | None = None, settings: SolidSettings = SETTINGS) -> list[list[int]]:
    """Indices into ``polys`` ((n, 2) pixel polygons) grouped into solids: the neighbouring faces ``pairs``
    (i < j: they share an edge) joined while no end of the boundary two groups share is a T junction and they lie
    in one silhouette (module doc). ``shape``: the image's (H, W); ``region``: the silhouette each face lies in,
    0 where it may lie in any (default: all 0)."""
    h, w = shape
    diag = float(np.hypot(h, w))
    touch = settings.contact_frac * diag
    groups = {i: _group([i], _clockwise(np.asarray(p, np.float64)), abs(_signed_area(p)))
              for i, p in enumerate(polys)}
    owner = list(range(len(polys)))
    links = {(min(a, b), max(a, b)) for a, b in pairs if a != b}
    verdict: dict[tuple[int, int], float | None] = {}  # group pair -> shared length when they may join, else None
    next_id = len(polys)
    region = list(region) if region is not None else [0] * len(polys)
    silhouette = {i: {region[i]} - {0} for i in groups}  # the silhouettes (regions of foreground) a group lies in
    while True:
        for key in links - verdict.keys():
            if len(silhouette[key[0]] | silhouette[key[1]]) > 1:
                verdict[key] = None  # faces on two silhouettes: two solids
                continue
            verdict[key] = _joinable(groups[key[0]], groups[key[1]], touch, diag, (w, h), settings)
        ok = [(length, key) for key, length in verdict.items() if key in links and length is not None]
        if not ok:
            break
        _, (a, b) = max(ok)
        members = groups[a].members + groups[b].members
        groups[next_id] = _group(members, union_outline([polys[i] for i in members], touch),
                                 groups[a].area + groups[b].area)
        for i in members:
            owner[i] = next_id
        silhouette[next_id] = silhouette.pop(a) | silhouette.pop(b)
        del groups[a], groups[b]
        links = {(min(owner[i], owner[j]), max(owner[i], owner[j])) for i, j in pairs
                 if owner[i] != owner[j]}
        next_id += 1
    return [sorted(g.members) for g in groups.values()]


def _signed_area(p: np.ndarray) -> float:
    """Shoelace area (px^2), positive clockwise in the image."""
    x, y = np.asarray(p, np.float64).T
    return 0.5 * float(np.dot(x, following(y)) - np.dot(following(x), y))


def _group(members: list[int], poly: np.ndarray, area: float) -> _Group:
    """A group of faces ``members`` whose outline together is ``poly`` (clockwise) and area ``area`` (px^2)."""
    step = following(poly) - poly
    count = np.maximum(1, np.ceil(np.hypot(*step.T)).astype(int))  # sample_boundary's samples per side
    heading = step / np.maximum(np.hypot(*step.T), 1e-9)[:, None]
    return _Group(members, poly, sample_boundary(poly, 1.0), np.repeat(heading, count, axis=0), area)


def _clockwise(poly: np.ndarray) -> np.ndarray:
    return poly if _signed_area(poly) >= 0 else poly[::-1]


def union_outline(polys: list[np.ndarray], touch: float) -> np.ndarray:
    """The outer outline (clockwise, to a quarter pixel) of the polygons ``polys`` filled together, the seams of
    up to ``touch`` px between neighbouring faces closed."""
    sub = 4  # the mask is drawn at a quarter pixel
    pts = np.concatenate(polys)
    lo = np.floor(pts.min(axis=0)) - touch - 2
    size = (np.ceil(pts.max(axis=0) - lo + touch + 2) * sub).astype(int)
    m = np.zeros((size[1], size[0]), np.uint8)
    cv2.fillPoly(m, [np.round((np.asarray(p) - lo) * sub).astype(np.int32) for p in polys], 1)
    r = int(np.ceil(touch * sub / 2))
    m = cv2.morphologyEx(m, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1)))
    contours, _ = cv2.findContours(m, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    c = max(contours, key=cv2.contourArea)
    # simplified within half a pixel: the mask's own resolution, whatever the image's size
    poly = cv2.approxPolyDP(c, 0.5 * sub, True).reshape(-1, 2).astype(np.float64) / sub + lo
    return _clockwise(poly)


def _corner_deg(outline: np.ndarray, i: int, chord: int) -> float:
    """The sharpest turn (deg) of the closed ``outline`` (points every pixel) within half ``chord`` points of its
    point ``i``: at each point, the angle between the chords from ``chord`` points before it to it and from it
    to ``chord`` points after it. Where two outlines part, the point found lies a pixel or two from the
    corner, on either side of it."""
    n = len(outline)
    k = i + np.arange(-(chord // 2), chord // 2 + 1)
    a, b, c = outline[(k - chord) % n], outline[k % n], outline[(k + chord) % n]
    u, v = b - a, c - b
    norm = np.hypot(*u.T) * np.hypot(*v.T)
    cos = np.where(norm > 1e-9, (u * v).sum(axis=1) / np.maximum(norm, 1e-9), 1.0)
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max())


def _along(small: _Group, large: _Group, touch: float, align_deg: float) -> np.ndarray:
    """(m,) bool: the points of ``small``'s outline that run along ``large``'s: within ``touch`` px of a side of
    it that runs within ``align_deg`` of their own side's direction."""
    a = large.poly
    step = following(a) - a
    rel = small.outline[:, None, :] - a[None]
    t = np.clip(pair_dots(rel, step[None]) / np.maximum(pair_dots(step, step), 1e-12), 0.0, 1.0)
    dist = np.hypot(*(rel - t[..., None] * step[None]).transpose(2, 0, 1))
    side = np.argmin(dist, axis=1)
    k = np.arange(len(side))
    heading = step[side] / np.maximum(np.hypot(*step[side].T), 1e-9)[:, None]
    cos = np.abs((heading * small.heading).sum(axis=1))
    return (dist[k, side] <= touch) & (cos >= np.cos(np.radians(align_deg)))


def _far_turn_deg(outline: np.ndarray, i: int, chord: int) -> float:
    """The angle (deg) between the closed ``outline``'s chords from 2 to 1 ``chord`` points before its point ``i``
    and from 1 to 2 after it: how far its sides a little way off either side of the point turn, whatever short
    sides lie between."""
    n = len(outline)
    u = outline[(i - chord) % n] - outline[(i - 2 * chord) % n]
    v = outline[(i + 2 * chord) % n] - outline[(i + chord) % n]
    nu, nv = np.hypot(*u), np.hypot(*v)
    if nu < 1e-9 or nv < 1e-9:
        return 0.0
    return float(np.degrees(np.arccos(np.clip(np.dot(u, v) / (nu * nv), -1.0, 1.0))))


def _runs(flags: np.ndarray, fill: int) -> list[tuple[int, int]]:
    """The runs (start, end) inclusive of true ``flags`` along a closed outline, gaps of at most ``fill`` points
    closed; [] where none, [(0, n - 1)] where all."""
    n = len(flags)
    f = flags.copy()
    if not f.any():
        return []
    # close short gaps (circularly)
    idx = np.flatnonzero(f)
    gaps = np.diff(np.concatenate([idx, idx[:1] + n]))
    for k, g in zip(idx, gaps):
        if 1 < g <= fill + 1:
            f[(k + np.arange(1, g)) % n] = True
    if f.all():
        return [(0, n - 1)]
    start = int(np.flatnonzero(~f)[0])  # roll so that the outline starts off the contact
    g = np.roll(f, -start)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], g.astype(np.int8), [0]])))
    return [((s + start) % n, (e - 1 + start) % n) for s, e in zip(edges[::2], edges[1::2])]


def _joinable(g1: _Group, g2: _Group, touch: float, diag: float, size: tuple[int, int],
              settings: SolidSettings) -> float | None:
    """The length (px) of the boundary groups ``g1`` and ``g2`` share (``touch``: the contact distance, px;
    ``diag``: the image diagonal, px; ``size``: its (W, H)), when they may be one solid: it is at least
    ``min_contact`` of the smaller one's perimeter and none of its ends off the image's frame is a T junction (one
    outline turning there by less than ``straight_deg``, the other by more than ``corner_deg`` and not coming to a
    tip). None otherwise."""
    small, large = (g1, g2) if g1.area <= g2.area else (g2, g1)
    chord = max(2, int(round(settings.chord_frac * diag)))
    near = _along(small, large, touch, settings.align_deg)
    runs = _runs(near, chord)
    length = float(sum((e - s) % len(near) + 1 for s, e in runs))
    if length < settings.min_contact * len(small.outline):
        return None
    if len(runs) == 1 and runs[0] == (0, len(near) - 1):
        return length  # the smaller group lies along the other all round: no ends
    w, h = size
    for s, e in runs:
        for i in (s, e):
            p = small.outline[i]
            if min(p[0], p[1], w - 1 - p[0], h - 1 - p[1]) <= touch:
                continue  # cut off by the image's frame, not ended
            j = int(np.argmin(np.hypot(*(large.outline - p).T)))
            t_small, t_large = _corner_deg(small.outline, i, chord), _corner_deg(large.outline, j, chord)
            if min(t_small, t_large) >= settings.straight_deg or max(t_small, t_large) <= settings.corner_deg:
                continue
            stem, k = (small.outline, i) if t_small > t_large else (large.outline, j)
            if _far_turn_deg(stem, k, chord) < settings.tip_deg:
                return None
    return length


def one_face_parts(polys: list[np.ndarray], groups: list[list[int]], pairs: list[tuple[int, int]],
                   shape: tuple[int, int], apart: set[tuple[int, int]] = frozenset(),
                   settings: SolidSettings = SETTINGS) -> list[list[int]]:
    """Indices into ``polys`` grouped into faces, within each solid of ``groups``: a face of a convex solid is
    convex and its edges run from corner to corner of the solid's outline or of its other faces, so

    - two neighbouring parts (``pairs``) whose shared boundary ends, at every end off the image's frame, where
      the outline of the two together runs straight (a line drawn across one face: a print's edge, a band), and
      that together are convex, are one face, unless they are parts cut apart where the image steps (``apart``:
      pairs i < j; a cut from side to side parts a cube's top and front seen with its sides edge-on);
    - a part that does not reach the solid's outline (a label, a block of text), together with the parts around
      it, is one face where they are convex together."""
    h, w = shape
    diag = float(np.hypot(h, w))
    touch = settings.contact_frac * diag
    chord = max(2, int(round(settings.chord_frac * diag)))
    out = []
    for members in groups:
        parts = {i: (i,) for i in members}
        owner = {i: i for i in members}
        inside = [(i, j) for i, j in pairs if i in owner and j in owner]

        def join(keep: int, others: list[int]) -> None:
            for o in others:
                parts[keep] = parts[keep] + parts.pop(o)
            for i in parts[keep]:
                owner[i] = keep

        verdict: dict[tuple[tuple[int, ...], tuple[int, ...]], float | None] = {}
        outlines: dict[tuple[int, ...], np.ndarray] = {}  # parts' outlines together, by their sorted indices
        while True:
            links = {(min(owner[i], owner[j]), max(owner[i], owner[j])) for i, j in inside
                     if owner[i] != owner[j] and (i, j) not in apart}
            links = {(a, b) for a, b in links
                     if not any((min(i, j), max(i, j)) in apart for i in parts[a] for j in parts[b])}
            best = None
            for a, b in links:
                key = (parts[a], parts[b])
                if key not in verdict:
                    verdict[key] = _marking(parts[a], parts[b], polys, touch, chord, (w, h), settings, outlines)
                if verdict[key] is not None and (best is None or verdict[key] > best[0]):
                    best = (verdict[key], a, b)
            if best is None:
                break
            join(best[1], [best[2]])

        if len(parts) > 2:
            outline = union_outline([polys[i] for i in members], touch)
            for k in list(parts):
                if k not in parts or len(parts) < 3:
                    continue
                own = np.concatenate([sample_boundary(np.asarray(polys[i], np.float64), 1.0) for i in parts[k]])
                if outline_distance(own, outline).min() <= touch:
                    continue  # it reaches the solid's outline
                around = sorted({owner[j] for i, j in inside if owner[i] == k and owner[j] != k} |
                                {owner[i] for i, j in inside if owner[j] == k and owner[i] != k})
                if not around:
                    continue
                both = union_outline([polys[i] for o in [k] + around for i in parts[o]], touch)
                hull = cv2.convexHull(both.astype(np.float32)).reshape(-1, 2)
                if abs(_signed_area(both)) >= settings.min_convex * abs(_signed_area(hull)):
                    join(k, around)
        out += [sorted(p) for p in parts.values()]
    return out


def _marking(a: tuple[int, ...], b: tuple[int, ...], polys: list[np.ndarray], touch: float, chord: int,
             size: tuple[int, int], settings: SolidSettings, outlines: dict) -> float | None:
    """The length (px) of the boundary parts ``a`` and ``b`` (indices into ``polys``) share, when it is a line
    across one face (one_face_parts): the two are convex together and at every end of the boundary off the
    image's frame their outline together turns by less than ``line_deg``, read between chords ``part_chord`` of
    the narrower part's width long (at most ``chord``). None otherwise. ``outlines``: the outlines of parts
    together found so far, by their sorted indices (filled in here)."""
    def outline(m: tuple[int, ...]) -> np.ndarray:
        key = tuple(sorted(m))
        if key not in outlines:
            outlines[key] = union_outline([polys[i] for i in key], touch) if len(key) > 1 else \
                _clockwise(np.asarray(polys[key[0]], np.float64))
        return outlines[key]

    ga, gb = (_group(list(m), outline(m), 0.0) for m in (a, b))
    near = _along(ga, gb, touch, settings.align_deg)
    runs = _runs(near, chord)
    if not runs or (len(runs) == 1 and runs[0] == (0, len(near) - 1)):
        return None
    both = outline(a + b)
    hull = cv2.convexHull(both.astype(np.float32)).reshape(-1, 2)
    if abs(_signed_area(both)) < settings.min_convex * abs(_signed_area(hull)):
        return None
    u = sample_boundary(both, 1.0)
    width = min(2 * abs(_signed_area(g.poly)) / len(g.outline) for g in (ga, gb))  # twice area over perimeter
    cm = max(2, min(chord, int(round(settings.part_chord * width))))
    w, h = size
    ends = 0
    for s, e in runs:
        for i in (s, e):
            p = ga.outline[i]
            if min(p[0], p[1], w - 1 - p[0], h - 1 - p[1]) <= touch:
                continue
            j = int(np.argmin(np.hypot(*(u - p).T)))
            if _far_turn_deg(u, j, cm) >= settings.line_deg:
                return None
            ends += 1
    return float(near.sum()) if ends else None
