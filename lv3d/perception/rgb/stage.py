"""Faces from colour alone: edges -> segments -> planar graph -> bounded minimal cycles -> validated polygons,
plus the thin faces beside them that the graph cannot trace (thin.py) and, colour alone, the parts of the solids'
silhouettes that no face covers (untraced.py), grouped into objects by shared edges and silhouettes (solids.py)."""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

import cv2
import numpy as np

from .background import background_faces, chromaticity, face_chromaticity, log_gradient, smooth_faces
from ..edges import channel_edges, channels, edge_distance, edge_support
from .ellipse import OutlineEllipse, measure_face
from .faces import bounded_faces, build_graph
from .gaps import close_gaps
from ..polygons import (KEEP_AREA, area, clockwise, drop_short_sides, is_simple, mean_width, outline_distance, perimeter,
                       sample_boundary, simplify)
from .segments import detect_color_segments
from .silhouette import foreground, regions_of, silhouette_segments
from .solids import SETTINGS as SOLIDS, group_solids, one_face_parts, union_outline
from .split import reflex_corners, split_by_diagonal, split_concave
from .step_edge import fork_cut, side_cut, smoothed_gradients, step_cut, step_lines
from .thin import thin_faces
from .untraced import untraced_faces


@dataclass(frozen=True)
class RGBFace:
    """A validated colour face: ``polygon`` (n, 2) pixels, clockwise, simplified to its corners;
    ``edges``: the planar-graph edges it is bounded by (for adjacency); ``edge_support`` in [0, 1]; ``ellipse``:
    the ellipse fitted to its outline's edge pixels beside its polygon (ellipse.py), None where none fits."""

    polygon: np.ndarray
    edges: frozenset[tuple[int, int]]
    edge_support: float
    area_px: float
    ellipse: OutlineEllipse | None = None


@dataclass(frozen=True)
class RGBResult:
    faces: list[RGBFace]
    groups: list[list[int]]           # indices into faces, one list per object, largest first
    adjacency: list[tuple[int, int]]  # pairs of face indices sharing a graph edge, i < j
    timings_ms: dict[str, float]


# a part cut off a traced face at most this wide (twice its area over its perimeter, px) is outlined anew from the
# traced vertices it holds
_THIN_PART_PX = 12.0
# parts cut off an outline tile it when their areas sum to its area within this fraction of it
_TILE_TOL = 1e-6


def _outline(poly: np.ndarray) -> np.ndarray:
    """A traced face's outline with only its corners, short sides dropped, clockwise; a corner holding more than
    ``KEEP_AREA`` of the face's area stays however little it turns (polygons.simplify)."""
    return clockwise(drop_short_sides(simplify(poly, keep_area_frac=KEEP_AREA)))


def _traced_part(traced: np.ndarray, outline: np.ndarray, piece: np.ndarray) -> np.ndarray:
    """``piece`` of ``outline`` (the corners of polygon ``traced``, cut along diagonals between its corners) as a
    piece of ``traced`` itself: between two corners that neighbour on ``outline`` it runs through the traced
    vertices there. The corners were chosen for the whole face: a bend holding a small part of it is dropped,
    though it holds much of the thin part cut off."""
    t = clockwise(np.asarray(traced, np.float64))
    n = len(t)
    near = lambda q: [int(np.argmin(np.hypot(*(t - v).T))) for v in q]  # noqa: E731
    corners = near(outline)
    idx = near(piece)
    run = []
    for a, b in zip(idx, idx[1:] + idx[:1]):
        run.append(a)
        ia, ib = corners.index(a) if a in corners else -1, corners.index(b) if b in corners else -1
        if ia >= 0 and ib == (ia + 1) % len(corners):  # a side of the outline, not a cut
            k = (a + 1) % n
            while k != b:
                run.append(k)
                k = (k + 1) % n
    return t[run]


def _touches_frame(poly: np.ndarray, box: tuple[int, int, int, int], tol: float = 3.0) -> float:
    """Fraction of the polygon's vertices within ``tol`` px of the box (u0, v0, u1, v1) border."""
    u0, v0, u1, v1 = box
    p = poly
    near = (np.abs(p[:, 0] - u0) < tol) | (np.abs(p[:, 0] - u1) < tol) | \
           (np.abs(p[:, 1] - v0) < tol) | (np.abs(p[:, 1] - v1) < tol)
    return float(np.mean(near))


def _contains(outer: np.ndarray, inner: np.ndarray) -> bool:
    c = outer.astype(np.float32).reshape(-1, 1, 2)
    return all(cv2.pointPolygonTest(c, (float(x), float(y)), False) >= 0 for x, y in inner)


def rgb_faces(color: np.ndarray, min_area_px: float = 150.0, max_area_frac: float = 0.35,
              min_support: float = 0.55) -> RGBResult:
    """Faces in the colour image (H, W, 3) uint8 RGB, seen by colour alone (no depth to find or part faces), grouped
    into objects. Faces smaller than ``min_area_px``, larger than ``max_area_frac`` of the image, hugging its frame,
    non-simple, poorly supported by edges (< ``min_support`` of the perimeter), or containing another face (a
    background region around an object) are dropped.

    The sides of the solids' silhouettes, told from the floor by chromaticity, join the segments (silhouette.py),
    segments are carried on across gaps in their edges where the colour still steps (gaps.close_gaps), and a kept
    face whose outline the graph traced whole, or a concave traced outline before it is split, is cut along a faint
    straight edge from one of its corners (step_edge.step_cut), and a convex one that no such line cuts is cut at a
    fork of three faint edges from three of its corners (step_edge.fork_cut: a solid showing three faces of one
    colour), or else along a faint edge from side to side that steps far above its control (step_edge.side_cut: a
    cube's top and front whose left and right sides run on in one line each): most colour-only misses on noisy
    renders are corners the segments stop short of and two faces of one colour traced as one. The parts of the
    silhouettes left outside every face, each of a colour of its own or a whole solid none of whose faces was
    traced, are then faces too (untraced.untraced_faces: slivers whose corners the graph collapsed), each cut from
    side to side as above. Faces of the colour of the image's border (floor texture, shadows, painted lines) are
    then dropped (background.background_faces): most false colour-only faces on noisy renders are such; those much
    smoother than the floor of their hue are kept (background.smooth_faces: an object of the table's hue).

    Faces are grouped into solids by the edges they share and the silhouettes they lie in, never by their hue
    (solids.group_solids: the graph joins solids that nearly touch or overlap, and a side of one ending on the
    other's outline parts them), and the parts of one face cut apart by a line drawn across it are made one face
    again (solids.one_face_parts: a print's edge, a label). Last, each face's outline is fitted with an ellipse and
    compared with its polygon (ellipse.measure_face: a lid, a ball). (rgbd does not trace colour faces: fuse.py.)"""
    import time

    t0 = time.perf_counter()
    h, w = color.shape[:2]
    crop = np.ascontiguousarray(color)
    chans = channels(crop)
    per_channel = [channel_edges(c) for c in chans]
    edges = np.maximum.reduce([c.edges for c in per_channel])
    grad = np.maximum.reduce([c.magnitude for c in per_channel])  # for cutting merged faces (split.py)
    dist = edge_distance(edges)
    t1 = time.perf_counter()
    segs = detect_color_segments(chans)
    sgrads = smoothed_gradients(chans)  # for close_gaps and step_cut
    solids = foreground(crop)  # regions not of the border's chromaticity
    chroma = chromaticity(crop)  # for background_faces and smooth_faces
    segs = close_gaps(np.concatenate([segs, silhouette_segments(solids, grad)]), sgrads)
    t2 = time.perf_counter()
    g = build_graph(segs, edge_dist=dist)
    frame = (0, 0, w - 1, h - 1)
    cands = []
    # made-up edge keys (k, k), k < 0: a cut the graph lacks, shared by the parts either side of it (so that they
    # count as neighbours), or a thin face's contact with the faces beside it (_touching_cands)
    made_up = ((k, k) for k in itertools.count(-1, -1))
    # made-up keys of cuts along an image edge (split_by_diagonal, step_cut, fork_cut): never joined back
    image_cuts = set()
    measured = {}  # index in cands -> step_edge.StepLines (or None: none) of a whole traced face, when measured
    for f in bounded_faces(g):
        traced_area = area(f.polygon)
        if traced_area < min_area_px or traced_area > max_area_frac * w * h:
            continue
        poly = _outline(f.polygon)
        a = area(poly) if len(poly) >= 3 else 0.0
        if len(poly) < 3 or not is_simple(poly) or a < min_area_px:
            continue
        if _touches_frame(poly, frame) > 0.5:
            continue
        sup = edge_support(poly, dist)
        if sup < min_support:
            continue
        # a concave outline is first cut along a faint straight edge from one of its corners (two faces of one colour
        # traced with a third as one outline): split_concave cuts only from corner to corner and reads Canny's
        # gradient, which the faint edge is under. Stricter than step_cut on whole faces (a step 10 times its
        # control, 12 clear samples: a short edge ending on a side keeps few); the parts, their corners found again,
        # are then split as a traced outline is (docs/perception.md)
        concave = bool(reflex_corners(poly))
        lines = step_lines(poly, sgrads) if concave else None
        stepped = step_cut(poly, sgrads, min_area_px, rel_step=10.0, min_samples=12, lines=lines) \
            if lines is not None else None
        pieces = [q for part in (map(_outline, stepped) if stepped else [poly])
                  for q in split_concave(part, grad, min_area_px)]
        image_cut = stepped is not None or len(pieces) == 1
        if len(pieces) == 1:
            pieces = split_by_diagonal(poly, grad, min_area_px)
        if len(pieces) == 1:
            if concave:
                measured[len(cands)] = lines  # step_cut tests these lines again below, as a whole face
            cands.append((poly, f.edges, sup, a, True))
            continue
        # the cut is an edge the graph lacks: a shared made-up edge key makes the parts neighbours
        cut = next(made_up)
        if image_cut:
            image_cuts.add(cut)
        # split_by_diagonal may cut a non-convex outline across a notch: the part cut off lies outside the traced
        # face, its traced vertices are the notch's, and the parts do not tile the outline
        tiled = abs(sum(area(q) for q in pieces) - a) <= _TILE_TOL * a
        for q in pieces:
            # a thin part of a tiled outline keeps the bends of its traced outline where they hold much of its
            # area and leave it convex (_traced_part)
            bent = _outline(_traced_part(f.polygon, poly, q)) if tiled and mean_width(q) <= _THIN_PART_PX else None
            q = bent if bent is not None and not reflex_corners(bent) else _outline(q)
            cands.append(_part(q, f.edges, cut, g.vertices, dist) + (False,))
    # a face that contains another kept face is a region around it (table, wall), not an object face
    region = [any(j != i and cands[j][3] < cands[i][3] and _contains(cands[i][0], cands[j][0])
                  for j in range(len(cands))) for i in range(len(cands))]
    kept = []
    for i, ((poly, es, sup, a, whole), around) in enumerate(zip(cands, region)):
        if around:
            continue
        parts = None
        if whole:
            parts = _faint_cut(poly, sgrads, min_area_px, measured[i] if i in measured else step_lines(poly, sgrads))
        if parts is None:
            kept.append((poly, es, sup, a))
            continue
        cut = next(made_up)
        image_cuts.add(cut)
        kept += [_part(q, es, cut, g.vertices, dist) for q in map(_outline, parts)]
    cands = _join_on_graph_edges(kept, g.vertices, dist, image_cuts)
    n_traced = len(cands)
    cands += _touching_cands(cands, thin_faces(segs, dist, [c[0] for c in cands], min_area_px), dist, made_up)
    cands = _join_thin_to_traced(cands, n_traced, dist)
    untraced = untraced_faces(solids, [c[0] for c in cands], dist, crop, min_area_px, max_area_frac * w * h)
    # a whole solid none of whose faces was traced is cut from side to side where its faces' shared edge
    # steps clearly; the corner and fork cuts, looser, cost realsense multi-class accuracy (docs/perception.md)
    new = []
    for q in untraced:
        parts = side_cut(q, sgrads, min_area_px)
        group = _touching_cands(cands, [_outline(x) for x in parts] if parts else [q], dist, made_up)
        if parts:  # the parts of one cut are neighbours
            cut = next(made_up)
            group = [(p, es | {cut}, sup, a) for p, es, sup, a in group]
        new += group
    cands += new
    hues = []  # each face's chromaticity, for background_faces and smooth_faces
    if cands:
        hues = [face_chromaticity(np.asarray(c[0], np.float64), chroma) for c in cands]
        bg = background_faces(hues, chroma)
        if any(bg):  # unless a face is much smoother than the floor of its hue: an object of the floor's hue
            smooth = smooth_faces([c[0] for c in cands], hues, bg, chroma, log_gradient(crop))
            bg = [b and not s for b, s in zip(bg, smooth)]
        cands, hues = [c for c, b in zip(cands, bg) if not b], [h for h, b in zip(hues, bg) if not b]
    faces = [(RGBFace(p, e, s, a), hue) for (p, e, s, a), hue in zip(cands, hues)]
    faces.sort(key=lambda fh: (-fh[0].area_px, float(fh[0].polygon[0, 0]), float(fh[0].polygon[0, 1])))
    faces, hues = [f for f, _ in faces], [h for _, h in faces]
    adjacency = [(i, j) for i in range(len(faces)) for j in range(i + 1, len(faces))
                 if faces[i].edges & faces[j].edges]
    touch = SOLIDS.contact_frac * np.hypot(h, w)
    polys = [f.polygon for f in faces]
    groups = group_solids(polys, adjacency, (h, w), _silhouettes(polys, hues, solids, chroma, crop))
    # parts cut apart where the image steps (split_by_diagonal, step_cut, fork_cut, side_cut) stay two faces
    apart = {(i, j) for i, j in adjacency if faces[i].edges & faces[j].edges & image_cuts}
    parts = one_face_parts(polys, groups, adjacency, (h, w), apart)
    solid_of = {i: k for k, g in enumerate(groups) for i in g}
    faces = _one_face(faces, parts, dist, touch)
    groups = {}
    for k, part in enumerate(parts):
        groups.setdefault(solid_of[part[0]], []).append(k)
    # faces largest first, the objects by their faces' area, largest first
    order = sorted(range(len(faces)), key=lambda i: (-faces[i].area_px, float(faces[i].polygon[0, 0]),
                                                     float(faces[i].polygon[0, 1])))
    rank = {i: k for k, i in enumerate(order)}
    # each face's outline measured against an ellipse (a lid, a ball: ellipse.py)
    faces = [dataclasses.replace(faces[i], ellipse=measure_face(faces[i].polygon, edges)) for i in order]
    groups = [sorted(rank[i] for i in g) for g in groups.values()]
    adjacency = sorted((i, j) for g in groups for i in g for j in g if i < j and faces[i].edges & faces[j].edges)
    ordered = sorted(groups, key=lambda idx: (-sum(faces[i].area_px for i in idx), idx[0]))
    t3 = time.perf_counter()
    timings = {"edges": (t1 - t0) * 1e3, "segments": (t2 - t1) * 1e3, "faces": (t3 - t2) * 1e3}
    return RGBResult(faces, ordered, adjacency, timings)


def _one_face(faces: list[RGBFace], parts: list[list[int]], dist: np.ndarray, touch: float) -> list[RGBFace]:
    """The faces with each of ``parts`` (indices into ``faces``: the parts of one face, solids.one_face_parts)
    made one face (the outline of the parts together, their seams of up to ``touch`` px closed), in the order of
    ``parts``."""
    out = []
    for part in parts:
        if len(part) == 1:
            out.append(faces[part[0]])
            continue
        poly = _outline(union_outline([faces[i].polygon for i in part], touch))
        edges = frozenset().union(*(faces[i].edges for i in part))
        out.append(RGBFace(poly, edges, edge_support(poly, dist), area(poly)))
    return out


def _silhouettes(polys: list[np.ndarray], hues: list[np.ndarray], solids: np.ndarray, chroma: np.ndarray,
                 color: np.ndarray) -> list[int]:
    """The silhouette each face (``polys``, chromaticities ``hues``) lies in: a region of ``solids``
    (silhouette.foreground), -1 outside every one (floor, shadow), 0 (any) for a face outside them much smoother
    than the floor of its hue (background.smooth_faces: an object of the floor's hue)."""
    region = regions_of(polys, solids)
    outside = [r == 0 for r in region]
    if any(outside):
        smooth = smooth_faces(polys, hues, outside, chroma, log_gradient(color))
        region = [0 if sm else (r or -1) for r, sm in zip(region, smooth)]
    return region


def _faint_cut(poly: np.ndarray, sgrads: np.ndarray, min_area_px: float, lines) -> list[np.ndarray] | None:
    """The parts of a face ``poly`` cut along faint edges (step_edge.py), or None: along a line from a corner
    (``lines``: its step_edge.step_lines, None where there are none), at a fork of three lines from three corners,
    or along a line from side to side."""
    # no line to cut along (step_lines found none): step_cut would find none either
    parts = step_cut(poly, sgrads, min_area_px, lines=lines) if lines is not None else None
    if parts is None and lines is not None:
        # a short faint edge keeps few clear samples; it is taken with 10 when it steps 10 times its control
        # (a small face of one colour beside its neighbour, whose shared edge is short)
        parts = step_cut(poly, sgrads, min_area_px, rel_step=10.0, min_samples=10, lines=lines)
    if parts is None:
        parts = fork_cut(poly, sgrads, min_area_px)
    if parts is None:
        parts = side_cut(poly, sgrads, min_area_px)
    return parts


def _part(q: np.ndarray, edges: frozenset, cut: tuple[int, int], vertices: np.ndarray, dist: np.ndarray) -> tuple:
    """A part ``q`` of a cut traced face as a candidate (polygon, graph edges, edge support, area): it keeps the
    face's ``edges`` whose midpoints lie on or within 2 px of it, and the made-up key ``cut`` it shares with the
    other parts."""
    qc = q.astype(np.float32).reshape(-1, 1, 2)
    own = frozenset(e for e in edges if cv2.pointPolygonTest(
        qc, tuple(float(x) for x in 0.5 * (vertices[e[0]] + vertices[e[1]])), True) >= -2.0)
    return (q, own | {cut}, edge_support(q, dist), area(q))


def _join_on_graph_edges(cands: list, vertices: np.ndarray, dist: np.ndarray,
                         image_cuts: frozenset | set = frozenset(), min_aspect: float = 3.0) -> list:
    """Candidates (polygon, graph edges, edge support, area) with each pair of thin ones that share a graph edge
    and make one convex region joined (``_join_thin_pairs``): the edge between two faces, carried on across a face
    seen edge-on to the silhouette, cuts that sliver in two, and a sliver traced with a slightly reflex corner is
    cut in two by split.split_concave. ``vertices``: (V, 2) the graph's vertex pixels. Parts sharing a key of
    ``image_cuts`` (a cut split.split_by_diagonal made where the image has an edge) are joined only when together
    they are long, their minimum-area rectangle at least ``min_aspect`` times as long as wide: a sliver's diagonal
    runs so close to its long sides that it picks up their gradient, while two small faces, such as a far
    pyramid's, are thin by the width measure too and the edge between them is real."""
    def shared_length(out: list, i: int, j: int) -> float | None:
        shared = out[i][1] & out[j][1]
        if not shared:
            return None
        if shared & image_cuts:
            size = cv2.minAreaRect(np.concatenate([out[i][0], out[j][0]]).astype(np.float32))[1]
            if max(size) < min_aspect * min(size):
                return None
        # a made-up key (< 0) is the cut between two parts of one split outline: it adds no length
        return sum(float(np.hypot(*(vertices[a] - vertices[b]))) for a, b in shared if a >= 0)

    return _join_thin_pairs(cands, dist, shared_length)


def _join_thin_to_traced(cands: list, new_from: int, dist: np.ndarray, touch_px: float = 1.5,
                         min_touch_px: float = 5.0) -> list:
    """Candidates with each thin one from index ``new_from`` on (thin.py's slivers) joined to a thin candidate it
    touches where together they make one convex region (``_join_thin_pairs``): the thin pass closes the part of a
    sliver the graph left, beside the part it traced, with no graph edge in common. Their shared side is where
    one's outline runs within ``touch_px`` of the other's, at least ``min_touch_px`` long."""
    def touch_length(out: list, i: int, j: int) -> float | None:
        if j < new_from:
            return None
        length = _touch_length(out[i][0], out[j][0], touch_px)
        return length if length >= min_touch_px else None

    return _join_thin_pairs(cands, dist, touch_length)


def _join_thin_pairs(cands: list, dist: np.ndarray, shared_length, max_width_px: float = 12.0,
                     max_excess: float = 0.1, max_shared: float = 0.25) -> list:
    """Candidates (polygon, graph edges, edge support, area) with each pair of thin ones (at most ``max_width_px``
    wide: twice the area over the perimeter) that touch and together make one convex region (their hull at most
    ``max_excess`` above their summed area) joined into that region. ``shared_length(out, i, j)``, for i < j
    indices into the current list, is the length (px) of the side they share, or None where they do not touch.
    Two faces seen edge-on side by side share a long side instead and stay apart: the shared side must be at most
    ``max_shared`` of the shorter outline."""
    out = list(cands)
    # each candidate's perimeter and thinness, measured once; a joined pair's replace the first's
    per = [perimeter(c[0]) for c in out]
    thin = [mean_width(c[0], c[3], p) <= max_width_px for c, p in zip(out, per)]
    i = 0
    while i < len(out):
        for j in range(i + 1, len(out)):
            if not thin[i] or not thin[j]:
                continue
            length = shared_length(out, i, j)
            if length is None or length > max_shared * min(per[i], per[j]):
                continue
            hull = cv2.convexHull(np.concatenate([out[i][0], out[j][0]]).astype(np.float32)).reshape(-1, 2)
            if area(hull) > (1.0 + max_excess) * (out[i][3] + out[j][3]):
                continue
            poly = _outline(hull.astype(np.float64))
            out[i] = (poly, out[i][1] ^ out[j][1], edge_support(poly, dist), area(poly))
            per[i] = perimeter(poly)
            thin[i] = mean_width(poly, out[i][3], per[i]) <= max_width_px
            del out[j], per[j], thin[j]
            break
        else:
            i += 1
    return out


def _touch_length(a: np.ndarray, b: np.ndarray, tol_px: float) -> float:
    """Length (px) of polygon ``a``'s outline lying within ``tol_px`` of polygon ``b``'s outline."""
    d = outline_distance(sample_boundary(a, 1.0), b)
    return float(np.count_nonzero(d <= tol_px))


def _touching_cands(cands: list, polys: list[np.ndarray], dist: np.ndarray, made_up, touch_px: float = 2.5) -> list:
    """Faces found beside the kept candidates (``polys``: thin.py's slivers, untraced.py's parts of a silhouette),
    as candidates: each shares a made-up edge key (the next of ``made_up``) with every candidate whose outline runs
    within ``touch_px`` of its own, so that they group and count as neighbours."""
    out = []
    for q in polys:
        key = next(made_up)
        pts = sample_boundary(q, 1.0)
        for n, c in enumerate(cands):
            if np.mean(outline_distance(pts, c[0]) <= touch_px) >= 0.15:
                cands[n] = (c[0], c[1] | {key}, c[2], c[3])
        out.append((q, frozenset({key}), edge_support(q, dist), area(q)))
    return out
