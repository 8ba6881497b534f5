"""Facts read off a rendered item's ground truth (meta.json "truth", docs/dataset.md) instead of
perception: the learner's test bed until perception + grounding land, and the noise-free upper
bound of the study. The tolerances are those of docs/facts.md.

With ``perturb`` > 0 the facts are spoiled on purpose, seeded: confidences drawn below 1, true
facts dropped, false ones added (see :func:`truth_facts`).
"""

from __future__ import annotations

import itertools

import numpy as np

from grounding import (ACUTE_BELOW_DEG, EQUAL_CORNERS_DEG, OBTUSE_ABOVE_DEG, PARALLEL_SIDES_DEG, PERPENDICULAR_DEG,
                       PLANE_ANGLE_DEG, RIGHT_ANGLE_DEG)

from .errors import InputError
from .facts import PREDICATES, REGULAR_CORNERS, Fact, SceneFacts, face_id, object_id, regular_corner_range
from .image_shape import exact_image_shape

SIDES = {3: "triangle", 4: "quadrilateral", 5: "pentagon", 6: "hexagon"}
EQUAL_SIDES_TOL = 0.12     # relative spread of side lengths for square and regular
STRUCTURE = ("object", "face_of")  # never perturbed: without them there is no object to speak of


def _angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    c = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def _corners_deg(poly: np.ndarray) -> np.ndarray:
    """Interior corner angles (degrees) of a convex polygon (n, d) in order."""
    prev, nxt = np.roll(poly, 1, axis=0) - poly, np.roll(poly, -1, axis=0) - poly
    return np.array([_angle_deg(p, q) for p, q in zip(prev, nxt)])


def _sides(poly: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.roll(poly, -1, axis=0) - poly, axis=1)


def _on_plane(poly_px: np.ndarray, normal: np.ndarray, offset: float, k: dict) -> np.ndarray:
    """Back-project pixel vertices (n, 2) onto the camera-frame plane n . X + d = 0: (n, 3) metres."""
    rays = np.stack([(poly_px[:, 0] - k["cx"]) / k["fx"], (poly_px[:, 1] - k["cy"]) / k["fy"],
                     np.ones(len(poly_px))], axis=1)
    t = -offset / (rays @ normal)
    return rays * t[:, None]


def _face_shape(poly_px: np.ndarray, poly_3d: np.ndarray) -> list[str]:
    """The 2D and metric shape predicates that hold for one face."""
    out = []
    n = len(poly_px)
    if n == 4:
        e = np.roll(poly_px, -1, axis=0) - poly_px
        par = [min(_angle_deg(e[i], e[i + 2]), 180 - _angle_deg(e[i], e[i + 2])) for i in (0, 1)]
        if max(par) <= PARALLEL_SIDES_DEG:
            out.append("parallelogram")
    sides, corners = _sides(poly_3d), _corners_deg(poly_3d)
    equal = (sides.max() - sides.min()) / sides.max() <= EQUAL_SIDES_TOL
    if n == 4 and np.all(np.abs(corners - 90) <= RIGHT_ANGLE_DEG):
        out.append("rectangle")
        if equal:
            out.append("square")
    if equal and corners.max() - corners.min() <= EQUAL_CORNERS_DEG:
        out.append("regular")
    return out


def _exact_facts(truth: dict, k: dict, scene_id: str, modality: str = "rgbd") -> list[Fact]:
    """Every fact of the contract that the ground truth supports, confidence 1; for colour alone the shape
    facts of the image polygon (lv3d.image_shape) in place of the metric ones.

    Faces of the curved solids (a ``surface`` in the truth): a cylinder's side is ``cylindrical`` (value:
    its radius, as perception gives it), a cone's side ``conical`` (value: its half-angle in degrees), a
    sphere ``spherical`` (value: its radius); they have no plane, so no plane facts. Their ``sides`` is 0:
    a circular cap or base is planar (``horizontal`` / ``vertical`` and the plane pairs hold) and
    ``circular``, and ``elliptical`` (its outline in the image; so is a sphere's), but has no side count, no
    corners and no polygon shape (its outline is sampled along a curve, not a polygon)."""
    o = object_id(scene_id, 1)
    facts = [Fact("object", (o,), 1.0)]
    up = np.asarray(truth["support_plane"]["normal"], float)
    normals, names = {}, {}
    for f in truth["faces"]:
        if not f.get("visible", True):
            continue
        fid = face_id(scene_id, 1, int(f["id"]))
        names[int(f["id"])] = fid
        facts.append(Fact("face_of", (o, fid), 1.0))
        surface = f.get("surface", {"type": "plane"})
        if surface["type"] == "cylinder":
            facts.append(Fact("cylindrical", (fid,), 1.0, float(surface["radius"])))
        elif surface["type"] == "cone":
            facts.append(Fact("conical", (fid,), 1.0, float(surface["half_angle_deg"])))
        elif surface["type"] == "sphere":
            facts.append(Fact("spherical", (fid,), 1.0, float(surface["radius"])))
            facts.append(Fact("elliptical", (fid,), 1.0))  # its silhouette: a circle, an ellipse in the image
        if surface["type"] != "plane":
            continue
        if int(f["sides"]) == 0:  # a planar face bounded by a circle: a cap or a cone's base
            facts.append(Fact("circular", (fid,), 1.0))
            facts.append(Fact("elliptical", (fid,), 1.0))  # the circle seen in the image: an ellipse
        n = np.asarray(f["plane"]["normal"], float)
        normals[int(f["id"])] = n
        if int(f["sides"]) in SIDES:
            facts.append(Fact(SIDES[int(f["sides"])], (fid,), 1.0, float(f["sides"])))
        if int(f["sides"]) >= 3:  # a face bounded by a curve has no corners and no polygon shape
            poly = np.asarray(f["polygon"], float)
            poly3 = _on_plane(poly, n, float(f["plane"]["offset"]), k)
            shape = _face_shape(poly, poly3)
            if modality == "rgb":
                shape = [p for p in shape if p not in ("square", "rectangle", "regular")] + exact_image_shape(poly)
            facts += [Fact(p, (fid,), 1.0) for p in shape]
        tilt = _angle_deg(n, up)
        if tilt <= PLANE_ANGLE_DEG:
            facts.append(Fact("horizontal", (fid,), 1.0, tilt))
        if abs(tilt - 90) <= PLANE_ANGLE_DEG:
            facts.append(Fact("vertical", (fid,), 1.0, tilt))
    for a in truth.get("adjacency", []):
        i, j = (int(x) for x in a["faces"])
        if i not in names or j not in names:
            continue
        d = float(a["dihedral_deg"])
        for x, y in ((names[i], names[j]), (names[j], names[i])):
            facts.append(Fact("adjacent", (x, y), 1.0))
            if d < ACUTE_BELOW_DEG:
                facts.append(Fact("acute", (x, y), 1.0, d))
            elif d > OBTUSE_ABOVE_DEG:
                facts.append(Fact("obtuse", (x, y), 1.0, d))
            for pred, n in REGULAR_CORNERS.items():
                lo, hi = regular_corner_range(n)
                if lo <= d < hi:
                    facts.append(Fact(pred, (x, y), 1.0, d))
    for i, j in itertools.combinations(sorted(normals), 2):
        # visible faces of a convex solid face the camera, so plane normals are outward normals
        d = 180.0 - _angle_deg(normals[i], normals[j])
        for x, y in ((names[i], names[j]), (names[j], names[i])):
            if abs(d - 90) <= PERPENDICULAR_DEG:
                facts.append(Fact("perpendicular", (x, y), 1.0, d))
            if d <= PLANE_ANGLE_DEG or d >= 180 - PLANE_ANGLE_DEG:
                facts.append(Fact("parallel", (x, y), 1.0, d))
    return facts


def _perturb(facts: list[Fact], p: float, modality: str, rng: np.random.Generator) -> list[Fact]:
    """Spoil facts with strength ``p`` in [0, 1]: each non-structural fact is dropped with probability
    p/3, else its confidence is drawn uniformly from [1 - p, 1]; each face gains, with probability p/3,
    a false one-place fact of this modality with a confidence uniform in [0.05, 1]."""
    out = []
    for f in facts:
        if f.pred in STRUCTURE:
            out.append(f)
        elif rng.random() >= p / 3:
            out.append(Fact(f.pred, f.args, float(max(0.05, rng.uniform(1 - p, 1))), f.value))
    have = {f.atom() for f in facts}
    unary = [n for n, (a, mods) in PREDICATES.items() if a == 1 and n != "object" and modality in mods]
    faces = [f.args[1] for f in facts if f.pred == "face_of"]
    for fid in faces:
        if rng.random() < p / 3:
            pred = unary[int(rng.integers(len(unary)))]
            if f"{pred}({fid})" not in have:
                out.append(Fact(pred, (fid,), float(rng.uniform(0.05, 1.0))))
    return out


def truth_facts(meta: dict, scene_id: str, modality: str, *, perturb: float = 0.0, seed: int = 0) -> SceneFacts:
    """Facts of a rendered item from its meta.json dict, as a system seeing ``modality`` would get them
    were perception perfect: confidence 1, or spoiled with strength ``perturb`` in [0, 1] (seeded).

    The target object is ``<scene_id>_o1``; faces are ``<scene_id>_o1_f<face id>``.
    """
    where = f"meta of {scene_id}"
    if not (0.0 <= perturb <= 1.0):
        raise InputError("perturb", f"perturb must lie in [0, 1], got {perturb}")
    try:
        truth, k = meta["truth"], meta["intrinsics"]
        facts = _exact_facts(truth, k, scene_id, modality)
    except (KeyError, TypeError, ValueError, IndexError) as e:
        raise InputError(where, f"ground truth is malformed: {type(e).__name__}: {e}") from None
    scene = SceneFacts(scene_id, modality, facts, object_id(scene_id, 1)).for_modality(modality)
    if perturb > 0:
        rng = np.random.default_rng([int(seed), perturb.__hash__() & 0xFFFF])
        scene = SceneFacts(scene_id, modality, _perturb(scene.facts, perturb, modality, rng), scene.target)
    return scene
