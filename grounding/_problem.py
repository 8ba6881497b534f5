"""The padded, fixed-shape description of one object that every grounding program takes.

Shapes are fixed (``MAX_FACES`` faces of at most ``MAX_SIDES`` vertices, ``MAX_VERTICES`` distinct
vertices, ``MAX_POINTS`` depth points per face, ``MAX_LINKS`` shared-vertex links) so that one compiled
program serves every object and nothing recompiles between frames; masks say which slots are real.

Frames and units: pixels (u right, v down, pixel centres at integers) for vertices; the camera frame
(x right, y down, z forward, metres) for planes and points. A plane is ``(n, d)`` with
``n . X + d = 0`` and ``n`` a unit normal towards the camera.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import equinox as eqx
import jax
import numpy as np
from jaxtyping import Array, Bool, Float, Int

MAX_FACES = 6
MAX_SIDES = 8
MAX_VERTICES = 24
MAX_POINTS = 64
MAX_LINKS = 24
EDGE_SAMPLES = 12  # points sampled along each polygon edge
# padded shapes (F, S, U, P, L), smallest first: an object goes into the first that holds it. Most targets
# (3-4 faces of at most 6 sides) fit the small one, whose solver runs ~3x faster than the large one's
# (the work scales with the padded sizes, not the real ones); each shape is one compiled program
SIZES = [(4, 6, 16, MAX_POINTS, 16), (MAX_FACES, MAX_SIDES, MAX_VERTICES, MAX_POINTS, MAX_LINKS)]


class _TooBig(ValueError):
    """The object does not fit the padded shape asked for."""


class Settings(eqx.Module):
    """Noise models and robust scales. Plain floats: they are traced, so changing them does not recompile."""

    depth_sigma_a_m: float = 0.001     # depth noise sigma(z) = a + b z^2, metres
    depth_sigma_b_per_m: float = 0.0018
    edge_sigma_px: float = 0.7        # a priori spread of a well-localised edge around the edge field's zero
    edge_cauchy_px: float = 2.0       # Cauchy scale of edge residuals (pixels)
    depth_cauchy: float = 3.0         # Cauchy scale of depth residuals (in units of sigma(z))
    # shared-vertex links are this many sigma(z) loose: tight, since refined planes fitted to a face's full-
    # resolution depth are far surer than one reading (0.1 mm at the vertices on realsense dev scenes), and
    # a true shared vertex lies on both planes exactly; a Cauchy loss (scale in units of this spread) keeps a
    # wrongly merged vertex or a wrong adjacency from bending the faces
    link_sigma_factor: float = 0.25
    link_cauchy: float = 6.0
    support_px: float = 1.5           # an edge sample within this distance of an image edge counts as supported


class ObjectProblem(eqx.Module):
    """One object, padded. ``F = MAX_FACES``, ``S = MAX_SIDES``, ``U = MAX_VERTICES``, ``P = MAX_POINTS``,
    ``L = MAX_LINKS``."""

    vertices: Float[Array, "U 2"]          # union of the faces' vertices, pixels
    vertex_mask: Bool[Array, " U"]
    vertex_sigma_px: Float[Array, " U"]    # prior spread of each vertex around its first guess, pixels
    face_index: Int[Array, "F S"]          # vertex ids in order around each face
    face_vmask: Bool[Array, "F S"]
    face_mask: Bool[Array, " F"]
    use_edges: Bool[Array, " F"]           # the face's sides are pulled onto the edge field
    edge_support_prior: Float[Array, " F"]  # edge support from perception, used where use_edges is False
    has_plane: Bool[Array, " F"]
    planes: Float[Array, "F 4"]            # first-guess planes (n, d), camera frame, metres
    pivots: Float[Array, "F 3"]            # centre of each face's points: planes tilt about it, camera frame, metres
    points: Float[Array, "F P 3"]          # the face's depth points, camera frame, metres
    point_weight: Float[Array, "F P"]      # how many readings a point stands for (0 for padding)
    links: Int[Array, "L 3"]               # (vertex, face a, face b): the vertex on plane a must lie on plane b
    link_mask: Bool[Array, " L"]
    adjacency: Bool[Array, "F F"]          # faces sharing an edge (symmetric)
    support_plane: Float[Array, " 4"]      # (n, d) of the support plane, camera frame, metres
    has_support: Bool[Array, ""]
    intrinsics: Float[Array, " 4"]         # fx, fy, cx, cy in pixels


@functools.cache
def _problem_structure():
    """The pytree structure of an :class:`ObjectProblem` (every field one array leaf)."""
    return jax.tree.structure(ObjectProblem(*[0] * len(dataclasses.fields(ObjectProblem))))


def _compress(points: np.ndarray, n: int, intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """At most ``n`` points that stand for ``points`` ((m, 3) metres): the means of the points in the
    cells of an image-space grid, each weighted by its count (a cell mean's noise is sigma / sqrt(count)),
    so a fit to them is the fit to all points at a fraction of the cost."""
    if len(points) <= n:
        return points, np.ones(len(points))
    fx, fy, cx, cy = intrinsics
    # contiguous columns and in-place updates: for a refined face's thousands of full-resolution points
    # this takes ~60% of the time the same arithmetic took on strided (m, 2) arrays (same results)
    x, y, z0 = np.ascontiguousarray(points.T)
    z = np.where(np.abs(z0) < 1e-9, 1e-9, z0)
    u = fx * x / z + cx
    v = fy * y / z + cy
    lo_u, lo_v = u.min(), v.min()
    area = (u.max() + 1e-6 - lo_u) * (v.max() + 1e-6 - lo_v)
    u -= lo_u  # >= 0, so truncation is the floor
    v -= lo_v

    def occupied(side):  # (cell of each point, points per cell), by bincount over a dense grid
        key = (u / side).astype(np.intp)
        cv = (v / side).astype(np.intp)
        key *= int(cv.max()) + 1
        key += cv
        return key, np.bincount(key)

    # cell side for about n cells over the area the points cover (a fine grid's occupied cells measure it;
    # the bounding box would overestimate it for a slanted or triangular face)
    fine = np.sqrt(area / (4 * n))
    side = fine * np.sqrt(np.count_nonzero(occupied(fine)[1]) / n)
    while True:
        key, counts = occupied(side)
        if np.count_nonzero(counts) <= n:
            break
        side *= 1.1
    used = np.flatnonzero(counts)
    sums = np.stack([np.bincount(key, col, minlength=len(counts))[used] for col in (x, y, z0)], 1)
    return sums / counts[used, None], counts[used].astype(np.float64)


def pack_object(polygons: list[np.ndarray], *, intrinsics: tuple[float, float, float, float],
                planes: list[np.ndarray | None] | None = None, points: list[np.ndarray | None] | None = None,
                use_edges: list[bool] | None = None, edge_support: list[float | None] | None = None,
                adjacency: list[tuple[int, int]] = (), support_plane: np.ndarray | None = None,
                merge_px: float = 6.0, boundary_sigma_px: float = 2.0, free_sigma_px: float = 20.0,
                gate_m: float = 0.015, size: tuple[int, int, int, int, int] | None = None
                ) -> tuple[ObjectProblem, np.ndarray]:
    """Pad one object's faces into an :class:`ObjectProblem` (numpy, outside jit).

    ``polygons``: per face an (n, 2) array of pixel vertices in order (3 <= n <= MAX_SIDES).
    Vertices of different faces closer than ``merge_px`` become one shared vertex (greedy, in order).
    ``planes``: per face (4,) (n, d) or None; ``points``: per face (m, 3) camera-frame metres or None
    (more than MAX_POINTS are merged into weighted cell means, see ``_compress``; before that, points
    farther than ``gate_m`` from the first-guess plane are dropped, since a cell mean would hide them
    from the robust loss).
    ``use_edges``: per face whether an edge field guides its sides (default all True); a vertex that
    no edge-guided face uses keeps the prior spread ``boundary_sigma_px`` (perception's own error),
    the others a weak ``free_sigma_px``. ``size`` = (F, S, U, P, L) pads to other shapes than the
    ``MAX_*`` ones (each shape is its own compiled program). Returns the problem and the (F, S) map from
    each face's polygon slot to its union vertex id. Without ``size``, the first of ``SIZES`` that holds
    the object.
    """
    kw = dict(intrinsics=intrinsics, planes=planes, points=points, use_edges=use_edges, edge_support=edge_support,
              adjacency=adjacency, support_plane=support_plane, merge_px=merge_px, boundary_sigma_px=boundary_sigma_px,
              free_sigma_px=free_sigma_px, gate_m=gate_m, memo={})  # memo: compressed points, shared by tries
    if size is None:
        for small in SIZES[:-1]:
            try:
                return _pack(polygons, size=small, strict=True, **kw)
            except _TooBig:
                pass
        size = SIZES[-1]
    return _pack(polygons, size=size, strict=False, **kw)


def _pack(polygons, *, intrinsics, planes, points, use_edges, edge_support, adjacency, support_plane, merge_px,
          boundary_sigma_px, free_sigma_px, gate_m, size, strict, memo):
    """:func:`pack_object` into one shape; with ``strict``, _TooBig where the object would not fit whole
    (more faces, sides, vertices or links than the shape holds)."""
    MAX_FACES, MAX_SIDES, MAX_VERTICES, MAX_POINTS, MAX_LINKS = size  # noqa: N806
    nf = len(polygons)
    if strict and (nf > MAX_FACES or max((len(np.asarray(q).reshape(-1, 2)) for q in polygons), default=0) > MAX_SIDES):
        raise _TooBig("does not fit")
    if not 1 <= nf <= MAX_FACES:
        raise ValueError(f"an object needs 1..{MAX_FACES} faces, got {nf}")
    planes = planes or [None] * nf
    points = points or [None] * nf
    use_edges = [True] * nf if use_edges is None else list(use_edges)
    edge_support = edge_support or [None] * nf
    verts: list[list[float]] = []  # plain floats: a few dozen tiny vectors are far quicker without numpy
    guided: list[bool] = []
    face_index = np.zeros((MAX_FACES, MAX_SIDES), np.int32)
    face_vmask = np.zeros((MAX_FACES, MAX_SIDES), bool)
    for f, poly in enumerate(polygons):
        poly = np.asarray(poly, np.float64).reshape(-1, 2)
        if not 3 <= len(poly) <= MAX_SIDES:
            raise ValueError(f"face {f} has {len(poly)} vertices; need 3..{MAX_SIDES}")
        ids: list[int] = []
        for pu, pv in poly.tolist():
            k, dk = -1, math.inf
            for i, (qu, qv) in enumerate(verts):  # nearest vertex so far (the first of equals)
                d = math.hypot(pu - qu, pv - qv)
                if d < dk:
                    k, dk = i, d
            if k < 0 or dk > merge_px or k in ids:
                if len(verts) >= MAX_VERTICES:
                    raise (_TooBig if strict else ValueError)(
                        f"an object has more than {MAX_VERTICES} distinct vertices")
                verts.append([pu, pv])
                guided.append(False)
                k = len(verts) - 1
            else:
                verts[k] = [(verts[k][0] + pu) / 2, (verts[k][1] + pv) / 2]  # merged vertices meet halfway
            guided[k] = guided[k] or bool(use_edges[f])
            ids.append(k)
        face_index[f, : len(ids)] = ids
        face_vmask[f, : len(ids)] = True
    vertices = np.zeros((MAX_VERTICES, 2))
    if verts:
        vertices[: len(verts)] = verts
    vmask = np.zeros(MAX_VERTICES, bool)
    vmask[: len(verts)] = True
    vsig = np.ones(MAX_VERTICES)
    vsig[: len(verts)] = [free_sigma_px if g else boundary_sigma_px for g in guided]

    plane_arr = np.tile(np.array([0.0, 0.0, -1.0, 1.0]), (MAX_FACES, 1))
    has_plane = np.zeros(MAX_FACES, bool)
    pts = np.zeros((MAX_FACES, MAX_POINTS, 3))
    pts[..., 2] = 1.0  # padding sits in front of the camera so that no division meets zero
    pw = np.zeros((MAX_FACES, MAX_POINTS))
    pivots = np.zeros((MAX_FACES, 3))
    for f in range(nf):
        if planes[f] is not None and points[f] is not None and len(points[f]) >= 3:
            plane_arr[f] = np.asarray(planes[f], np.float64)
            has_plane[f] = True
            if (f, MAX_POINTS) not in memo:
                p = np.asarray(points[f], np.float64)
                if len(p) > MAX_POINTS:
                    near = np.abs(p @ plane_arr[f, :3] + plane_arr[f, 3]) <= gate_m
                    kept = np.count_nonzero(near)
                    # np.compress: the rows p[near] picks, several times quicker for (m, 3) arrays; no copy
                    # where every point passes (describe's full-resolution points were gated already)
                    p = np.compress(near, p, axis=0) if 3 <= kept < len(p) else p
                memo[f, MAX_POINTS] = _compress(p, MAX_POINTS, intrinsics)
            p, w = memo[f, MAX_POINTS]
            pts[f, : len(p)] = p
            pw[f, : len(p)] = w
            pivots[f] = (p * w[:, None]).sum(0) / w.sum()
    adj = np.zeros((MAX_FACES, MAX_FACES), bool)
    links = np.zeros((MAX_LINKS, 3), np.int32)
    lmask = np.zeros(MAX_LINKS, bool)
    nl = 0
    for a, b in adjacency:
        adj[a, b] = adj[b, a] = True
        if not (has_plane[a] and has_plane[b]):
            continue
        shared = set(face_index[a][face_vmask[a]]) & set(face_index[b][face_vmask[b]])
        for u in sorted(shared):
            for fa, fb in ((a, b), (b, a)):
                if strict and nl == MAX_LINKS:
                    raise _TooBig("too many links")
                if nl < MAX_LINKS:
                    links[nl] = (u, fa, fb)
                    lmask[nl] = True
                    nl += 1
    fmask = np.zeros(MAX_FACES, bool)
    fmask[:nf] = True
    ue = np.zeros(MAX_FACES, bool)
    ue[:nf] = use_edges
    es = np.ones(MAX_FACES)
    es[:nf] = [1.0 if s is None else float(s) for s in edge_support]
    sp = np.array([0.0, -1.0, 0.0, 1.0]) if support_plane is None else np.asarray(support_plane, np.float64)
    fields = dict(
        vertices=np.asarray(vertices, np.float32), vertex_mask=np.asarray(vmask),
        vertex_sigma_px=np.asarray(vsig, np.float32),
        face_index=np.asarray(face_index), face_vmask=np.asarray(face_vmask), face_mask=np.asarray(fmask),
        use_edges=np.asarray(ue), edge_support_prior=np.asarray(es, np.float32), has_plane=np.asarray(has_plane),
        planes=np.asarray(plane_arr, np.float32), pivots=np.asarray(pivots, np.float32),
        points=np.asarray(pts, np.float32), point_weight=np.asarray(pw, np.float32),
        links=np.asarray(links), link_mask=np.asarray(lmask), adjacency=np.asarray(adj),
        support_plane=np.asarray(sp, np.float32), has_support=np.asarray(support_plane is not None),
        intrinsics=np.asarray(intrinsics, np.float32))
    # unflattening skips equinox's checked __init__, which costs more than the rest of packing a small object
    prob = jax.tree.unflatten(_problem_structure(), [fields[f.name] for f in dataclasses.fields(ObjectProblem)])
    return prob, face_index[:nf]
