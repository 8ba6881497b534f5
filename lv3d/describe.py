"""Scene + frame -> facts with confidences: the only place where lv3d meets the ``grounding`` package.

For each object, its faces become one padded problem (polygons, the faces' depth points, their planes,
the support plane, an edge field), ``grounding.ground_object`` refines it and turns its uncertainty into
the probability of every predicate, and each predicate the faces support becomes a fact
(docs/facts.md, docs/grounding.md). Facts below ``MIN_CONF`` are dropped, not emitted with a small confidence.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field as dc_field
from typing import TYPE_CHECKING, NamedTuple

import cv2
import numpy as np

from .calibration import shipped as shipped_calibration
from .cylinder import Cylinder
from .facts import PREDICATES, REGULAR_CORNERS, Fact, SceneFacts, regular_corner_range
from .interval import probability_between
from .perception.polygons import area
from .plane import column_means
from .rgbd import RGBD
from .scene import Face, Scene, SceneObject

if TYPE_CHECKING:  # grounding (JAX) is imported where it is used, not when lv3d.describe is
    import grounding

MIN_CONF = 0.05
CAP_PX = 30.0  # edge fields are clipped to +-this many pixels
COLOUR_FIRST_PX = 6.0  # rgbd fields near a depth-found face: colour's edge stands where it is within this (px)
SIDE_NAMES = {3: "triangle", 4: "quadrilateral", 5: "pentagon", 6: "hexagon"}
_SIDE_PREDS = frozenset(SIDE_NAMES.values())
# facts about the angle between two faces' planes. An rgbd scene reads them as depth does: its faces are grounded a
# second time against depth's edge field (:func:`ground`), and these facts take that grounding's probabilities and
# measurements. Colour adds nothing to an angle between two depth planes, and colour's edges (print on a box,
# a shadow) change the outline measurements the calibration of an angle reads: colour helps or stays out.
ANGLE_PREDS = frozenset({"perpendicular", "parallel", "acute", "obtuse"})
# facts that describe a face as a polygon: its side count, its shape as a polygon, the kinds of its corners
POLYGON_PREDS = _SIDE_PREDS | {"parallelogram", "square", "rectangle", "regular",
                              "has_right_angle", "has_acute_angle", "has_obtuse_angle"}
# facts that say a face is no polygon: a curved surface, or a planar face with a round outline
ROUND_PREDS = frozenset({"cylindrical", "conical", "spherical", "circular", "elliptical"})


@dataclass(frozen=True)
class CylinderReading:
    """What grounding made of a cylindrical face (:func:`read_cylinder`): its least-squares refinement ``fit``
    (grounding.CylinderFit, with its Laplace spreads), the ``cylinder`` the facts report (the refined one where
    the refinement converged, else perception's) and the ``evidence`` that the face is curved as that cylinder
    says (:func:`curved_evidence`, None where it cannot be measured)."""

    fit: grounding.CylinderFit
    cylinder: Cylinder
    evidence: float | None


@dataclass
class FaceResult:
    """Grounding of one face, kept for inspection and benchmarks."""

    face: Face
    polygon: np.ndarray          # refined polygon (n, 2), pixels
    plane: np.ndarray | None     # refined plane (n, d), camera frame, metres
    vertex_std_px: np.ndarray    # (n,) largest standard deviation of each vertex, pixels
    # measurements the confidence calibration reads (calibration_features)
    features: dict = dc_field(default_factory=dict)
    plane_tilt_std_rad: np.ndarray | None = None  # (2,) spread of the plane normal's two tilts, radians
    cylinder_reading: CylinderReading | None = None  # a cylindrical face's refined cylinder (read_cylinder)
    # the same measurements as ``features`` from the depth reading of an rgbd scene's angles (ANGLE_PREDS), which
    # those facts' calibration reads; None where the face has no such reading (every face outside rgbd)
    angle_features: dict | None = None


@dataclass
class ObjectResult:
    obj: SceneObject
    faces: list[FaceResult]
    dihedral_deg: dict[tuple[str, str], float]  # measured interior dihedral of each pair with planes
    status: int
    # per padded problem: (face ids in slot order, grounding result as nested dicts of numpy arrays)
    raw: list[tuple[list[str], dict]]


class _Job(NamedTuple):
    """One padded grounding problem of :func:`ground`: up to MAX_FACES faces of one object."""

    oi: int                                    # the object's index in the scene
    chunk: list[Face]                          # its faces, in slot order
    polys: list[np.ndarray]                    # their polygons as packed (at most MAX_SIDES vertices)
    has_plane: list[bool]                      # which faces carry a plane with 3 points or more
    index: np.ndarray                          # polygon slot -> union vertex (grounding.pack_object)
    prob: grounding.ObjectProblem              # the packed problem
    refined: bool                              # whether the solver refines its geometry
    points: list[np.ndarray | None]            # each face's depth points, as packed
    adjacency: list[tuple[int, int]]           # touching faces, as slot pairs


def _simplify(poly: np.ndarray, max_sides: int) -> np.ndarray:
    """A polygon with at most ``max_sides`` vertices (Douglas-Peucker with a growing tolerance)."""
    poly = np.asarray(poly, np.float64).reshape(-1, 2)
    eps = 1.0
    while len(poly) > max_sides:
        approx = cv2.approxPolyDP(poly.astype(np.float32).reshape(-1, 1, 2), eps, True).reshape(-1, 2)
        if len(approx) >= 3:
            poly = approx.astype(np.float64)
        eps *= 1.5
    return poly


def _plane_row(plane) -> np.ndarray:
    """(n, d) of a plane as a (4,) float64 array (np.r_ of the same costs ten times as long)."""
    return np.array([*plane.normal, plane.offset], np.float64)


def _first(a, b):
    return b if a is None else a


def dense_face_points(face: Face, frame: RGBD, margin_px: int = 2, gate_m: float = 0.015) -> np.ndarray | None:
    """Every depth reading of ``frame`` inside ``face.polygon`` shrunk by ``margin_px`` (away from flying
    pixels and the neighbouring faces) and within ``gate_m`` of the face's plane: camera-frame points (m, 3)
    in metres. Perception fits on a strided, thinned grid; refinement fits on the full resolution, which has
    several times the readings and so a steadier plane (the noise is independent per pixel). None when the
    face has no plane, the frame no depth, or fewer readings are found than perception's points."""
    if face.plane is None or face.points is None or frame.depth is None:
        return None
    h, w = frame.depth.shape
    poly = np.asarray(face.polygon, np.float64)
    # the box is grown by the margin: erosion treats outside the box as inside, so a side on the box's edge
    # would keep its pixels
    u0, v0 = np.maximum(np.floor(poly.min(0)).astype(int) - margin_px - 1, 0)
    u1, v1 = np.minimum(np.ceil(poly.max(0)).astype(int) + margin_px + 2, (w, h))
    if u1 - u0 < 3 or v1 - v0 < 3:
        return None
    m = np.zeros((v1 - v0, u1 - u0), np.uint8)
    cv2.fillPoly(m, [np.round(poly - (u0, v0)).astype(np.int32)], 1)
    if margin_px > 0:
        m = cv2.erode(m, np.ones((2 * margin_px + 1, 2 * margin_px + 1), np.uint8), borderValue=0)
    z = frame.depth[v0:v1, u0:u1]
    m &= z > 0
    nz = cv2.findNonZero(m)  # raster order, as np.nonzero gives it, several times quicker
    if nz is None or len(nz) < len(face.points):
        return None
    u, v = nz.reshape(-1, 2).T
    pts = frame.intrinsics.back_project(u + u0, v + v0, z[v, u])
    near = np.abs(face.plane.distance(pts)) <= gate_m
    # np.compress: the rows pts[near] picks, several times quicker for (m, 3) arrays
    return np.compress(near, pts, axis=0) if np.count_nonzero(near) >= len(face.points) else None


def _boxes(scene: Scene, margin_px: float, provenance: str | None = None) -> list[tuple[float, float, float, float]]:
    """Boxes (u0, v0, u1, v1) around each object's polygons (only its faces of ``provenance``, if given) plus
    ``margin_px``, overlapping ones merged: the field is needed only near the sides that are sampled, and one box
    around objects spread over the frame would cover most of it."""
    boxes = []
    for o in scene.objects:
        polys = [np.asarray(f.polygon, float).reshape(-1, 2) for f in o.faces
                 if len(f.polygon) and provenance in (None, f.provenance)]
        if polys:
            p = np.concatenate(polys)
            boxes.append([*(p.min(0) - margin_px), *(p.max(0) + margin_px)])
    merged = True
    while merged:  # merge until no two boxes overlap, so each pixel is computed once with its full context
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, b = boxes[i], boxes[j]
                if a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3]:
                    boxes[i] = [min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])]
                    del boxes[j]
                    merged = True
                    break
            if merged:
                break
    return [tuple(b) for b in boxes]


def edge_field(frame: RGBD, modality: str, scene: Scene | None = None, margin_px: float = 24.0, *,
               depth_field: np.ndarray | None = None) -> np.ndarray:
    """The edge-distance field (H, W) float32 pixels a system that sees ``modality`` may use: colour edges
    for rgb, edges of the depth image's surface normals and depth steps for depth, and for rgbd colour edges with,
    around each face depth found and colour did not (provenance "depth"), depth's edges where colour has none
    within ``COLOUR_FIRST_PX``. With ``scene``, only the boxes around its objects' polygons (plus ``margin_px``)
    are computed; the rest is the cap. ``depth_field``: the depth field of the same frame and scene, where it is
    already at hand (rgbd reads depth's edges from it rather than computing them again)."""
    import grounding

    boxes = _boxes(scene, margin_px) if scene is not None else []
    k = frame.intrinsics
    intr = (k.fx, k.fy, k.cx, k.cy)
    if modality == "depth":
        # the depth field smooths the whole image anyway: one box around all objects
        roi = (*np.min([b[:2] for b in boxes], 0), *np.max([b[2:] for b in boxes], 0)) if boxes else None
        return grounding.normal_edge_field(frame.depth, intr, roi=roi, cap_px=CAP_PX)
    colour = grounding.edge_distance_field(frame.color, roi=boxes or None, cap_px=CAP_PX)
    if modality == "rgb" or scene is None:
        return colour
    # rgbd: a face that depth found and colour did not is judged against depth's edges too, as it is in the depth
    # system: around such faces colour's edges stand where there is one nearby (they are sharper), and
    # elsewhere depth's, where nearer
    fill = _boxes(scene, margin_px, provenance="depth")
    if not fill:
        return colour
    depth = depth_field if depth_field is not None else \
        grounding.normal_edge_field(frame.depth, intr, roi=fill, cap_px=CAP_PX)
    near = np.abs(colour)
    return np.where((near <= COLOUR_FIRST_PX) | (near <= np.abs(depth)), colour, depth)


def _chunks(faces: list[Face], max_faces: int, max_vertices: int, max_sides: int) -> list[list[Face]]:
    """Consecutive runs of faces that fit one padded problem: at most ``max_faces`` faces and at most
    ``max_vertices`` polygon vertices in all (counted before shared vertices merge, so always enough)."""
    chunks: list[list[Face]] = [[]]
    used = 0
    for f in faces:
        n = min(len(f.polygon), max_sides)
        if chunks[-1] and (len(chunks[-1]) == max_faces or used + n > max_vertices):
            chunks.append([])
            used = 0
        chunks[-1].append(f)
        used += n
    return chunks


def ground(scene: Scene, frame: RGBD, *, refine: bool = True, field: np.ndarray | None = None,
           refine_all: bool = False, calibrate: bool = True, dense_points: bool = True,
           refine_ids: frozenset[str] | None = None):
    """Ground every object of ``scene``: (candidate facts with their probabilities, before any is dropped;
    per-object results). Candidates are ``(pred, args, probability, value)``.

    With ``refine``, only the scene's target object (:meth:`Scene.target`, the one a label speaks of) is
    refined unless ``refine_all``, or the objects named by ``refine_ids`` when given (the labelled objects
    of a real frame): the others keep perception's geometry, and their facts still get confidences from
    its Laplace covariance (the solver is three quarters of an object's cost).

    With ``calibrate``, each probability goes through the per-(modality, predicate) calibration map lv3d ships
    (:mod:`lv3d.calibration`, docs/grounding.md); without it, the raw Gaussian probabilities.
    With ``dense_points``, a refined face's plane is fitted to every depth reading inside its outline
    (:func:`dense_face_points`) rather than perception's strided points."""
    import grounding
    import jax.numpy as jnp

    from .image_shape import image_shape

    k = scene.intrinsics
    intr = (k.fx, k.fy, k.cx, k.cy)
    support = None if scene.support_plane is None else _plane_row(scene.support_plane)
    cands: list[tuple[str, tuple[str, ...], float, float | None]] = []
    # facts measured with no calibration map (yet): the curved surfaces and outlines, the regular corners
    uncalibrated: list[tuple[str, tuple[str, ...], float, float | None]] = []
    floors = grounding.Floors()
    results: list[ObjectResult] = []
    # pack every object (in chunks of MAX_FACES faces), ground them all in batched calls, then read facts
    jobs: list[_Job] = []
    target = scene.target()
    for oi, obj in enumerate(scene.objects):
        usable = [f for f in obj.faces if len(f.polygon) >= 3]
        for chunk in _chunks(usable, grounding.MAX_FACES, grounding.MAX_VERTICES, grounding.MAX_SIDES):
            if not chunk:
                continue
            pos = {f.id: i for i, f in enumerate(chunk)}
            polys = [_simplify(f.polygon, grounding.MAX_SIDES) for f in chunk]
            has_plane = [f.plane is not None and f.points is not None and len(f.points) >= 3 for f in chunk]
            refined = refine and (refine_all or (obj.id in refine_ids if refine_ids is not None else obj is target))
            pts = [f.points if hp else None for f, hp in zip(chunk, has_plane)]
            if refined and dense_points:  # only a refined plane moves, so only it needs the full-resolution points
                pts = [p if p is None else _first(dense_face_points(f, frame), p) for f, p in zip(chunk, pts)]
            adjacency = [(pos[a], pos[b]) for a, b in obj.adjacency if a in pos and b in pos]
            prob, index = grounding.pack_object(
                polys, intrinsics=intr,
                planes=[_plane_row(f.plane) if hp else None for f, hp in zip(chunk, has_plane)],
                points=pts, adjacency=adjacency, support_plane=support)
            jobs.append(_Job(oi, chunk, polys, has_plane, index, prob, refined, pts, adjacency))
    # rgbd: depth's field, for the angle facts' second grounding of every problem with two planes or more
    # (ANGLE_PREDS, _angle_readings) and for the depth edges of the rgbd field
    angle_depth = scene.modality == "rgbd" and any(sum(j.has_plane) >= 2 for j in jobs)
    depth_field = edge_field(frame, "depth", scene) if angle_depth else None
    if field is None:
        field = edge_field(frame, scene.modality, scene, depth_field=depth_field)
    field = jnp.asarray(field, jnp.float32)  # moved to the device once for every object
    # every problem is dispatched before any result is read, then each result is read once; the angle readings
    # go after, as they start from the first grounding's refined geometry
    grounded = [_to_numpy(g) for g in [grounding.ground_object(j.prob, field, j.refined) for j in jobs]]
    angle_grounded = _angle_readings(jobs, grounded, depth_field, intr, support) if angle_depth else {}
    for oi, obj in enumerate(scene.objects):
        face_conf: dict[str, float] = {}
        face_results: list[FaceResult] = []
        dihedrals: dict[tuple[str, str], float] = {}
        raw: list[tuple[list[str], dict]] = []
        status = 0
        for ji, (job, g) in enumerate(zip(jobs, grounded)):
            if job.oi != oi:
                continue
            chunk, polys, has_plane, index = job.chunk, job.polys, job.has_plane, job.index
            ga, index_a = angle_grounded.get(ji, (g, index))  # what the angle facts read
            raw.append(([f.id for f in chunk], g))
            status = max(status, int(g["status"]))
            # every number a candidate carries, as Python floats in one call per array (indexing numpy
            # scalars one at a time cost more than the rest of this loop)
            c = {k: v.tolist() for k, v in g["conf"].items()}
            tilt_l = g["quantities"]["tilt_deg"].tolist()
            ca = c if ga is g else {k: ga["conf"][k].tolist() for k in ("p_perpendicular", "p_parallel", "p_acute",
                                                                       "p_obtuse")}
            dih_l = ga["quantities"]["dihedral_deg"].tolist()
            dih_sd = ga["std"]["dihedral_deg"].tolist()
            par_l = ga["quantities"]["parallel_deg"].tolist()
            corner_l, corner_sd = g["quantities"]["corner_deg"].tolist(), g["std"]["corner_deg"].tolist()
            side_l, side_sd = g["quantities"]["side_px"].tolist(), g["std"]["side_px"].tolist()
            # float32 arithmetic, as on the scalars before
            support_l = np.clip(g["conf"]["edge_support"] / grounding.SUPPORT_FULL, 0.0, 1.0).tolist()
            vstd_all = _largest_std(g["vertex_cov"])
            ns = [len(p) for p in polys]
            face_points = [f.points if hp else None for f, hp in zip(chunk, has_plane)]
            feats = _face_features(g, index, ns, face_points)
            angle_feats = None if ga is g else _face_features(ga, index_a, ns, face_points)
            for i, f in enumerate(chunk):
                n = ns[i]
                ids_i = index[i, :n]
                reading = read_cylinder(f, intr)
                face_results.append(FaceResult(f, g["vertices"][ids_i], g["planes"][i] if has_plane[i] else None,
                                               vstd_all[ids_i], feats[i],
                                               g["plane_std"][i][:2] if has_plane[i] else None, reading,
                                               None if angle_feats is None else angle_feats[i]))
                support_term = support_l[i]
                face_conf[f.id] = support_term
                cands.append(("face_of", (obj.id, f.id), support_term, None))
                if n in SIDE_NAMES:
                    cands.append((SIDE_NAMES[n], (f.id,), c["p_sides"][i], float(n)))
                if n - 1 in SIDE_NAMES and has_plane[i]:  # one vertex may be a point on a straight side
                    cands.append((SIDE_NAMES[n - 1], (f.id,), c["p_fewer"][i], float(n - 1)))
                if n == 4:
                    cands.append(("parallelogram", (f.id,), c["p_parallelogram"][i], c["para_dev_deg"][i]))
                if not has_plane[i] and scene.modality == "rgb":  # colour alone: image-plane shape
                    cands += image_shape(f.id, corner_l[i][:n], corner_sd[i][:n], side_l[i][:n], side_sd[i][:n])
                if reading is not None and reading.evidence is not None:
                    uncalibrated.append(("cylindrical", (f.id,), reading.evidence, float(reading.cylinder.radius)))
                uncalibrated += quadric_candidates(f) + ellipse_candidates(f)
                if has_plane[i]:
                    if n == 4:
                        cands.append(("square", (f.id,), c["p_square"][i], c["side_ratio"][i]))
                        cands.append(("rectangle", (f.id,), c["p_rectangle"][i], c["right_dev_deg"][i]))
                    cands.append(("regular", (f.id,), c["p_regular"][i], c["side_ratio"][i]))
                    if support is not None:
                        tilt = tilt_l[i]
                        cands.append(("horizontal", (f.id,), c["p_horizontal"][i], tilt))
                        cands.append(("vertical", (f.id,), c["p_vertical"][i], tilt))
            adjacent = {(a, b) for a, b in obj.adjacency} | {(b, a) for a, b in obj.adjacency}
            for i, fi in enumerate(chunk):
                for j, fj in enumerate(chunk):
                    if i == j or not (has_plane[i] and has_plane[j]):
                        continue
                    dih = dih_l[i][j]
                    dihedrals[(fi.id, fj.id)] = dih
                    args = (fi.id, fj.id)
                    cands.append(("perpendicular", args, ca["p_perpendicular"][i][j], dih))
                    cands.append(("parallel", args, ca["p_parallel"][i][j], par_l[i][j]))
                    if args in adjacent:
                        cands.append(("acute", args, ca["p_acute"][i][j], dih))
                        cands.append(("obtuse", args, ca["p_obtuse"][i][j], dih))
                        uncalibrated += regular_corner_candidates(args, dih, dih_sd[i][j], floors.dihedral_deg)
        for a, b in obj.adjacency:
            if a in face_conf and b in face_conf:
                p = min(face_conf[a], face_conf[b])  # the shared edge is as real as the weaker face
                cands.append(("adjacent", (a, b), p, None))
                cands.append(("adjacent", (b, a), p, None))
        uncalibrated += cap_candidates(obj, face_results, floors.dihedral_deg)
        cands.append(("object", (obj.id,), max(face_conf.values(), default=0.0), None))
        results.append(ObjectResult(obj, face_results, dihedrals, status, raw))
    if calibrate:
        # some kinds of candidate have maps of their own; measurements only for the candidates whose map reads them
        # (they cost more than the maps)
        fewer, shared = one_side_fewer(cands, results), {}  # both read by keys and features: found once
        keys = calibration_keys(cands, results, fewer=fewer, shared=shared)
        needs = _needs(scene.modality)
        picked = [needs[key] for key in keys]
        feats = calibration_features([c for c, pick in zip(cands, picked) if pick], results,
                                     fewer=[f for f, pick in zip(fewer, picked) if pick], shared=shared)
        it = iter(feats)
        calibrate_one, modality = shipped_calibration().calibrate, scene.modality
        cands = [(pred, args, calibrate_one(modality, key, p, next(it) if pick else None), value)
                 for (pred, args, p, value), key, pick in zip(cands, keys, picked)]
    return cands + uncalibrated, results


def regular_corner_candidates(args: tuple[str, str], dih_deg: float, sd_deg: float, floor_deg: float
                              ) -> list[tuple[str, tuple[str, ...], float, float | None]]:
    """``pentagonal_dihedral`` / ``hexagonal_dihedral`` of two adjacent faces: the probability that their interior
    dihedral is nearer a regular pentagon's (hexagon's) corner than any other regular polygon's, i.e. that
    360 / (180 - dihedral) rounds to 5 (6): between 100.0 and 114.5 deg (114.5 and 124.6 deg). The dihedral's error
    is Gaussian with grounding's Laplace spread ``sd_deg`` and the model-error floor ``floor_deg`` in quadrature
    (grounding.Floors.dihedral_deg), as ``perpendicular``'s; value: the dihedral. The two sides of a prism whose cap
    is missed or misread meet at the angle of the cap's corners, which ``obtuse`` (above 97 deg) does not tell
    apart."""
    if not (math.isfinite(dih_deg) and math.isfinite(sd_deg)):
        return []
    sd = math.hypot(sd_deg, floor_deg)
    return [(pred, args, probability_between(*regular_corner_range(n), dih_deg, sd), dih_deg)
            for pred, n in REGULAR_CORNERS.items()]


def _angle_readings(jobs: list[_Job], grounded: list[dict], depth_field: np.ndarray,
                    intr: tuple[float, float, float, float], support: np.ndarray | None) -> dict[int, tuple[dict, np.ndarray]]:
    """Depth's reading of an rgbd scene's angles (ANGLE_PREDS): per job of :func:`ground` with two planes or more,
    (its grounding against ``depth_field``, the problem's map from polygon slots to union vertices). The faces keep
    the geometry the first grounding gave them (refined polygons and planes, where refined); only their
    uncertainty and their outlines' measurements are read against depth's edges, so no solver runs again."""
    import grounding
    import jax.numpy as jnp

    field = jnp.asarray(depth_field, jnp.float32)
    todo = {}
    for ji, (job, g) in enumerate(zip(jobs, grounded)):
        if sum(job.has_plane) < 2:
            continue
        prob, index = job.prob, job.index
        if job.refined:  # the refined geometry, packed again (its union vertices as the first grounding merged them)
            prob, index = grounding.pack_object(
                [g["vertices"][index[i, :len(p)]] for i, p in enumerate(job.polys)], intrinsics=intr,
                planes=[g["planes"][i] if hp else None for i, hp in enumerate(job.has_plane)],
                points=job.points, adjacency=job.adjacency, support_plane=support)
        todo[ji] = (grounding.ground_object(prob, field, False), index)
    return {ji: (_to_numpy(g), index) for ji, (g, index) in todo.items()}


def curved_evidence(points: np.ndarray, cylinder) -> float | None:
    """The probability a face is curved as its cylinder says rather than flat: the share of a plane's residual
    variance over the face's points (m, 3) that the cylinder explains, 1 - rms_cyl^2 / rms_plane^2. A flat face
    that perception took for a cylinder gives near 0 (the cylinder fits no better than the plane: on the real
    dev frames, 0.05-0.2 for box faces), a can's side near 1 (its sagitta is many times the sensor's noise:
    0.94-0.99 on the Kinect cans, 0.5-0.8 on small or far RealSense ones). None for fewer than 10 points."""
    from .perception.depth.curved import cylinder_share

    pts = np.asarray(points, float)
    if len(pts) < 10:
        return None
    return cylinder_share(pts, cylinder)


def refine_cylinder(face: Face, intrinsics: tuple[float, float, float, float]):
    """Grounding's least-squares refinement of a cylindrical face's cylinder against its depth points
    (grounding.fit_cylinder: robust, depth-noise-weighted, with its Laplace uncertainty), started from
    perception's; None for a face that is not cylindrical or has fewer than 10 points."""
    import grounding

    if face.surface != "cylinder" or face.cylinder is None or face.points is None or len(face.points) < 10:
        return None
    c = face.cylinder
    return grounding.fit_cylinder(face.points, np.asarray(c.axis, float), np.asarray(c.point, float),
                                  float(c.radius), intrinsics=intrinsics)


def read_cylinder(face: Face, intrinsics: tuple[float, float, float, float]) -> CylinderReading | None:
    """A cylindrical face's refinement (:func:`refine_cylinder`), the cylinder it gives (:func:`refined_cylinder`)
    and the evidence of a curved face (:func:`curved_evidence`): what ``cylindrical`` reports. None where there
    is no refinement (a face that is not cylindrical or has fewer than 10 points)."""
    fit = refine_cylinder(face, intrinsics)
    if fit is None:
        return None
    cyl = refined_cylinder(face, fit)
    return CylinderReading(fit, cyl, curved_evidence(face.points, cyl))


def refined_cylinder(face: Face, fit) -> Cylinder:
    """The cylinder of a refinement (:func:`refine_cylinder`) that converged to a finite surface; else
    perception's, which the refinement started from."""
    ok = int(fit.status) == 0 and float(fit.radius) > 0 and np.all(np.isfinite(fit.axis)) and \
        np.all(np.isfinite(fit.point)) and np.isfinite(float(fit.radius))
    if not ok:
        return face.cylinder
    return Cylinder(tuple(float(x) for x in fit.axis), tuple(float(x) for x in fit.point), float(fit.radius))


# A planar face meeting a cylindrical face is its cap, bounded by a circle, when its normal lies along the
# cylinder's axis: within CAP_TOL_DEG (degrees; the tolerance of the plane predicates, parallel within 8-10 deg).
CAP_TOL_DEG = 10.0


def cap_candidates(obj: SceneObject, faces: list[FaceResult], floor_deg: float
                   ) -> list[tuple[str, tuple[str, ...], float, float | None]]:
    """``circular`` for each planar face of ``obj`` that meets one of its cylindrical faces with its normal along
    the cylinder's axis: the probability that the angle between them is within CAP_TOL_DEG, value the angle in
    degrees. A can's lid is read as a polygon of a few sides; this says its outline is a circle.

    The angle is read from grounding's refined plane and refined cylinder (``faces``, :class:`FaceResult`), with
    a Gaussian error whose variance is the sum of the normal's and the axis's (each the mean of its two tilts'
    variances: grounding's Laplace spreads) and the model-error floor ``floor_deg`` of grounding's angles between
    planes (grounding.Floors.dihedral_deg), as plane-to-plane facts have theirs."""
    by_id = {fr.face.id: fr for fr in faces}
    out = []
    for a, b in obj.adjacency:
        for cap_id, side_id in ((a, b), (b, a)):
            cap, side = by_id.get(cap_id), by_id.get(side_id)
            if cap is None or side is None or cap.plane is None or side.cylinder_reading is None:
                continue
            axis = side.cylinder_reading.cylinder.axis
            n = np.asarray(cap.plane[:3], float)
            cos = abs(float(np.dot(n / np.linalg.norm(n), np.asarray(axis, float))))
            theta = math.degrees(math.acos(min(1.0, cos)))
            var = float(np.mean(np.square(np.degrees(side.cylinder_reading.fit.axis_std))))
            if cap.plane_tilt_std_rad is not None:
                var += float(np.mean(np.square(np.degrees(cap.plane_tilt_std_rad))))
            p = probability_between(-CAP_TOL_DEG, CAP_TOL_DEG, theta, math.sqrt(var + floor_deg * floor_deg))
            if p > 0:
                out.append(("circular", (cap.face.id,), p, round(theta, 2)))
    best: dict = {}
    for c in out:  # a cap meeting two cylindrical faces: its better reading
        if c[1] not in best or c[2] > best[c[1]][2]:
            best[c[1]] = c
    return list(best.values())


def quadric_candidates(face: Face) -> list[tuple[str, tuple[str, ...], float, float | None]]:
    """The ``spherical`` or ``conical`` fact of a depth face fitted as a sphere or a cone, as (pred, args, conf,
    value) with no calibration map (yet); none for other faces or where the evidence cannot be measured.
    ``spherical``: the share of a plane's residual variance over the face's points that the sphere explains
    (quadrics.sphere_evidence; a sphere of growing radius tends to a plane), value its radius in metres.
    ``conical``: the share of a least-squares cylinder's residual variance that the cone explains
    (quadrics.cone_evidence; a cone of half-angle near 0 is a cylinder, and a cylinder fits a cone's points at
    least as well as a plane, so the cylinder is the alternative a cone must beat), value its half-angle in
    degrees; and, the two surfaces being nested, ``cylindrical`` of the same face: (1 - conical) times the share
    of a plane's residual variance the least-squares cylinder explains (quadrics.cone_readings), value the
    cylinder's radius in metres."""
    from .perception.depth.quadrics import cone_readings, sphere_evidence

    if face.points is None:
        return []
    if face.surface == "sphere" and face.sphere is not None:
        p = sphere_evidence(face.points, face.sphere)
        return [] if p is None else [("spherical", (face.id,), p, float(face.sphere.radius))]
    if face.surface == "cone" and face.cone is not None:
        read = cone_readings(face.points, face.cone)
        if read is None:
            return []
        conical, cylindrical = read
        out = [("conical", (face.id,), conical, float(face.cone.half_angle_deg))]
        if cylindrical is not None:
            out.append(("cylindrical", (face.id,), cylindrical[0], float(cylindrical[1])))
        return out
    return []


def ellipse_candidates(face: Face) -> list[tuple[str, tuple[str, ...], float, float | None]]:
    """The ``elliptical`` fact of a colour face whose outline an ellipse fits better than its polygon (a lid, a
    ball; perception/rgb/ellipse.py), as (pred, args, conf, value) with no calibration map (yet): the product of
    the logistics of the two residuals' log ratio and of the ellipse's residual over its semi-minor axis
    (ellipse.elliptical_probability); value the log ratio ln(polygon residual / ellipse residual). None for a
    face without a measured outline."""
    from .perception.rgb.ellipse import elliptical_probability

    p = elliptical_probability(face.ellipse)
    return [] if p is None else [("elliptical", (face.id,), p, round(face.ellipse.log_ratio, 4))]


@functools.cache
def _needs(modality: str) -> dict[str, bool]:
    """Per calibration key (grounding.calibration_key) whether its map in ``modality`` reads face measurements."""
    import grounding

    keys = {grounding.calibration_key(pred, fewer, side) for pred in PREDICATES
            for fewer, side in ((False, None), (True, None), (False, 0.0))}
    return {key: bool(shipped_calibration().measures_used(modality, key)) for key in keys}


def _largest_std(cov: np.ndarray) -> np.ndarray:
    """Square root of the larger eigenvalue of each symmetric 2x2 covariance (..., 2, 2), closed form
    (quicker than a batched eigvalsh on a few dozen blocks); its lower triangle is read, as eigvalsh does."""
    a, b, c = cov[..., 0, 0], cov[..., 1, 0], cov[..., 1, 1]
    return np.sqrt(np.clip(0.5 * (a + c) + np.hypot(0.5 * (a - c), b), 0.0, None))


def _face_features(g: dict, index: np.ndarray, ns: list[int], points: list[np.ndarray | None] | None = None) -> list[dict]:
    """Measurements of each face of a grounding result that the calibration may read: the weakest corner's
    turn in units of its spread (grounding's ``corner_z``, on the face's plane where it has one: how sure the side
    count is), edge support, image area and shortest side; how well the problem's outlines sit on straight image
    edges (``edge_scale2``, grounding's variance factor of the edge block: mean squared edge residual over its a
    priori spread, 1 for a polygon whose sides lie on edges as sharp as the noise model says; a curved outline
    traced as a polygon reads several times that); and for a face with a plane and ``points`` (its camera-frame
    depth points, metres) how flat the surface is (``plane_rms_mm``: root mean square distance of the points from
    the refined plane, millimetres; a curved surface read as a plane departs from it by its sagitta, a flat one by
    the sensor's noise). ``index``: (faces, S) union vertex id of each polygon slot; ``ns``: each face's side
    count."""
    nf = len(ns)
    real = np.arange(index.shape[1])[None, :] < np.asarray(ns)[:, None]
    # the minimum over each face's real corners (padding reads +inf); grounding's corner test, as p_sides reads it
    z = np.where(real, g["conf"]["corner_z"][:nf, :index.shape[1]], np.inf)
    weakest = np.argmin(z, axis=1)
    support = g["conf"]["edge_support"][:nf].tolist()
    edge_scale2 = float(g["scale2"][0])
    out = []
    for i, n in enumerate(ns):
        poly = g["vertices"][index[i, :n]]
        f = {"sides": n, "min_turn_z": float(z[i].min()),
             "support": support[i], "log_area_px": float(np.log(max(area(poly), 1.0))),
             "min_side_px": _min_side(poly), "faces": nf, "edge_scale2": edge_scale2}
        pts = None if points is None else points[i]
        if pts is not None and len(pts):
            plane = g["planes"][i]
            f["plane_rms_mm"] = 1e3 * float(np.sqrt(np.mean((pts @ plane[:3] + plane[3]) ** 2)))
        if n > 3:
            # the same measurements of the polygon without its weakest corner: what a (sides - 1) fact reads
            k = weakest[i]
            f["fewer"] = {**f, "sides": n - 1, "min_turn_z": float(np.delete(z[i], k).min()),
                          "min_side_px": _min_side(np.delete(poly, k, 0))}
        out.append(f)
    return out


def _min_side(poly: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(poly, axis=0, append=poly[:1]), axis=1).min())


def shared_side_px(a: np.ndarray, b: np.ndarray) -> float:
    """Length in pixels of the longest side two refined polygons (n, 2) and (m, 2) have in common, 0 if none.
    Grounding merges vertices of different faces closer than its ``merge_px`` into one union vertex, so a
    shared vertex has the same coordinates in both: two faces that meet along an edge share a side, two that
    touch at a point (opposite laterals of a pyramid at its apex) share one vertex and no side."""
    same = np.all(a[:, None, :] == b[None, :, :], axis=2)  # (n, m)
    ia, ib = np.nonzero(same)
    if len(ia) < 2:
        return 0.0
    in_b = dict(zip(ia.tolist(), ib.tolist()))
    n, m = len(a), len(b)
    best = 0.0
    for i, j in in_b.items():
        k = in_b.get((i + 1) % n)
        if k is not None and (k - j) % m in (1, m - 1):  # consecutive in both: a common side
            best = max(best, float(np.linalg.norm(a[(i + 1) % n] - a[i])))
    return best


def plane_gap_mm(a: FaceResult, b: FaceResult) -> float | None:
    """How far two faces are from lying on one plane: the larger of the distances (mm) of each face's depth
    points' centroid from the other's refined plane; None unless both have a plane. Two pieces of one face (a face
    perception split) lie a few mm apart, two faces of a solid centimetres."""
    if a.plane is None or b.plane is None:
        return None
    ca, cb = column_means(a.face.points), column_means(b.face.points)
    return 1e3 * max(abs(float(ca @ b.plane[:3] + b.plane[3])), abs(float(cb @ a.plane[:3] + a.plane[3])))


def one_side_fewer(cands: list, results: list[ObjectResult]) -> list[bool]:
    """For each candidate ``(pred, args, p, value)`` of :func:`ground`, whether it is an (n - 1) side count: a side
    count one short of its face's polygon (the polygon without its weakest corner). Its calibration key is its own
    (grounding.calibration_key) and its measurements are the polygon's without that corner
    (:func:`calibration_features`)."""
    sides = {fr.face.id: fr.features["sides"] for res in results for fr in res.faces}
    return [pred in _SIDE_PREDS and args[0] in sides and value == sides[args[0]] - 1 for pred, args, _, value in cands]


def _shared_side(shared: dict, by_result: dict, args) -> float | None:
    """:func:`shared_side_px` of the two faces ``args``, memoised in ``shared`` by unordered pair (a pair has up to
    six facts, each in both orders); None unless ``args`` names two grounded faces."""
    if len(args) != 2 or args[0] not in by_result or args[1] not in by_result:
        return None
    key = (min(args), max(args))
    if key not in shared:
        shared[key] = shared_side_px(by_result[key[0]].polygon, by_result[key[1]].polygon)
    return shared[key]


def calibration_keys(cands: list, results: list[ObjectResult], *, fewer: list[bool] | None = None,
                     shared: dict | None = None) -> list[str]:
    """Each candidate's calibration key (grounding.calibration_key): its predicate, or a key of its own for an
    (n - 1) side count (:func:`one_side_fewer`; pass ``fewer`` where it is known) and for a fact about two faces that
    share no side (:func:`shared_side_px` 0, the measurement their maps read; ``shared`` is a memo by pair that
    :func:`calibration_features` may reuse)."""
    import grounding

    by_result = {fr.face.id: fr for res in results for fr in res.faces}
    fewer = one_side_fewer(cands, results) if fewer is None else fewer
    shared = {} if shared is None else shared
    return [grounding.calibration_key(pred, few, _shared_side(shared, by_result, args)
                                      if pred in grounding.SHARED_SIDE_PREDS else None)
            for (pred, args, _, _), few in zip(cands, fewer)]


# face measurements of which the larger value is the weaker face (for the others, the smaller)
_LARGER_IS_WEAKER = frozenset({"plane_rms_mm", "edge_scale2"})


def _weaker(name: str, values: list[float]) -> float:
    """The weaker of two faces' values of the measurement ``name``."""
    return max(values) if name in _LARGER_IS_WEAKER else min(values)


def calibration_features(cands: list, results: list[ObjectResult], *, fewer: list[bool] | None = None,
                         shared: dict | None = None) -> list[dict]:
    """Per candidate the face measurements its calibration may read (:func:`_face_features`; for an angle
    fact of an rgbd scene, those of depth's reading, ``FaceResult.angle_features``); for a fact about two faces,
    the weaker of each (the smaller value; the larger of ``plane_rms_mm`` and ``edge_scale2``), the length of the
    side they share (``shared_side_px``, :func:`shared_side_px`) and, where both have planes, how far they are
    from one plane (``plane_gap_mm``, :func:`plane_gap_mm`); for ``object`` the object's best face; and, for a
    candidate with a measured value, that value as ``value``. An (n - 1) side count reads the face's measurements
    without its weakest corner, marked ``is_fewer`` (its calibration key is its own: grounding.calibration_key).
    ``fewer`` and ``shared`` as :func:`calibration_keys` takes them."""
    by_face = {fr.face.id: fr.features for res in results for fr in res.faces}
    # an angle fact reads the measurements of the reading it came from (ANGLE_PREDS: depth's, in an rgbd scene)
    by_face_angle = {fr.face.id: fr.features if fr.angle_features is None else fr.angle_features
                     for res in results for fr in res.faces}
    by_result = {fr.face.id: fr for res in results for fr in res.faces}
    by_obj = {res.obj.id: [fr.features for fr in res.faces] for res in results}
    fewer = one_side_fewer(cands, results) if fewer is None else fewer
    shared = {} if shared is None else shared
    weaker: dict[tuple, dict] = {}  # by faces: a pair has up to six facts, each in both orders

    def combined(args, angle: bool):
        key = args if len(args) < 2 or args[0] <= args[1] else args[::-1]  # (a, b) and (b, a) share one
        if (key, angle) not in weaker:
            source = by_face_angle if angle else by_face
            fs = [source[a] for a in key if a in source]
            f = {k: _weaker(k, [f[k] for f in fs if k in f]) for k in fs[0] if k != "fewer"} if fs else {}
            side = _shared_side(shared, by_result, key)
            if side is not None:
                f["shared_side_px"] = side
                gap = plane_gap_mm(by_result[key[0]], by_result[key[1]])
                if gap is not None:
                    f["plane_gap_mm"] = gap
            weaker[(key, angle)] = f
        return weaker[(key, angle)]

    out = []
    for (pred, args, _, value), few in zip(cands, fewer):
        if pred == "object":
            fs = by_obj.get(args[0], [])
            out.append(max(fs, key=lambda f: f["support"]) if fs else {})
        else:
            f = combined(args, pred in ANGLE_PREDS)
            if few:  # the (sides - 1) fact reads the polygon without its weakest corner
                f = {**by_face[args[0]]["fewer"], "is_fewer": 1.0}
            out.append(f if value is None else {**f, "value": value})
    return out


def _to_numpy(tree) -> dict:
    """A grounding result (equinox modules of arrays) as nested dicts of numpy arrays, keyed by field name."""
    import jax

    leaves, treedef = jax.tree.flatten(tree)
    leaves = jax.device_get(leaves)  # all at once: one array at a time took half as long again
    out: dict = {}
    for path, leaf in zip(_leaf_paths(treedef), leaves):
        d = out
        for name in path[:-1]:
            d = d.setdefault(name, {})
        d[path[-1]] = np.asarray(leaf)
    return out


@functools.cache
def _leaf_paths(treedef) -> list[tuple[str, ...]]:
    """The field names leading to each leaf of a result's structure (found once: walking the modules per
    result cost more than reading its arrays)."""
    import jax

    paths, _ = jax.tree_util.tree_flatten_with_path(jax.tree.unflatten(treedef, range(treedef.num_leaves)))
    return [tuple(k.name for k in path) for path, _ in paths]


def polygon_given_round(cands: list[tuple[str, tuple[str, ...], float, float | None]]
                        ) -> list[tuple[str, tuple[str, ...], float, float | None]]:
    """``cands`` (pred, args, conf, value) with each polygon fact of a face (``POLYGON_PREDS``: its side count,
    its shape, its corners) weighed by the probability that the face is a polygon at all.

    A face read as a curved surface (cylindrical, conical, spherical) or as a planar face with a round outline
    (circular, elliptical: ``ROUND_PREDS``) is no polygon: the polygon its outline is drawn with (a can's lid as
    a hexagon, a can's side as a quadrilateral with bowed ends) has as many corners as the outline's sampling
    left, and they change from view to view. Each polygon fact's confidence measures the outline's shape given
    that it is a polygon, so its confidence becomes that times 1 - r, r the face's strongest round reading
    (the readings are of one outline, and the likelier one bounds the chance of the other)."""
    round_conf: dict[str, float] = {}
    for pred, args, p, _ in cands:
        if pred in ROUND_PREDS and math.isfinite(p):
            round_conf[args[0]] = max(round_conf.get(args[0], 0.0), min(max(p, 0.0), 1.0))
    if not round_conf:
        return cands
    return [(pred, args, p * (1.0 - round_conf[args[0]]), value)
            if pred in POLYGON_PREDS and args[0] in round_conf else (pred, args, p, value)
            for pred, args, p, value in cands]


def describe(scene: Scene, frame: RGBD, *, refine: bool = True, refine_ids: frozenset[str] | None = None
             ) -> SceneFacts:
    """Facts of ``scene`` (perceived in ``frame``) with confidences, for the scene's modality.

    ``refine=False`` keeps perception's polygons and planes but still computes their covariances and
    the confidences from them. A face's polygon facts are weighed by the chance that it is a polygon at all
    (:func:`polygon_given_round`). Facts whose probability is below ``MIN_CONF`` are absent. ``refine_ids``: the
    objects to refine (default: the scene's target), see :func:`ground`.
    """
    cands, _ = ground(scene, frame, refine=refine, refine_ids=refine_ids)
    cands = polygon_given_round(cands)
    facts = []
    for pred, args, p, value in cands:
        if scene.modality not in PREDICATES[pred][1] or not math.isfinite(p) or p < MIN_CONF:
            continue
        facts.append(Fact(pred, tuple(args), float(min(p, 1.0)), None if value is None else round(float(value), 4)))
    target = scene.target()
    return SceneFacts(scene.id, scene.modality, facts, target.id if target else None)
