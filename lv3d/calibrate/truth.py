"""Ground truth of rendered scenes for the calibration rows (lv3d.calibrate.rows) and bench_grounding: which
perceived face is which true face, what each candidate fact should have been, and the errors of the quantities
facts are read from (docs/dataset.md truth layout)."""

from __future__ import annotations

import numpy as np

from grounding import (ACUTE_BELOW_DEG, EQUAL_CORNERS_DEG, EQUAL_SIDES_RATIO, OBTUSE_ABOVE_DEG, PARALLEL_SIDES_DEG,
                       PERPENDICULAR_DEG, PLANE_ANGLE_DEG, RIGHT_ANGLE_DEG)
from ..perception.polygons import rasterize

NGONS = {"triangle": 3, "quadrilateral": 4, "pentagon": 5, "hexagon": 6}
FACE_SHAPES = ("parallelogram", "rectangle", "square", "regular")
# the predicates whose truth a rendered scene's ground truth gives (truth_labels); the others (the curved surfaces
# and outlines, the regular corners) have no calibration map, so their candidates get no label and make no row
LABELLED = frozenset({"face_of", *NGONS, *FACE_SHAPES, "horizontal", "vertical", "adjacent", "perpendicular",
                      "parallel", "acute", "obtuse"})


def _angle(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.degrees(np.arccos(np.clip(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)), -1, 1))))


def match_faces(res, faces_mask: np.ndarray, truth: dict, *, containment: bool = False) -> dict:
    """Perceived face id -> true face dict, for faces whose rasterised polygon has IoU >= 0.5 with a true
    face's mask (or, with ``containment``, lies at least half on it: a fragment of a face is on that face's
    plane). Empty when the object is not the target."""
    out = {}
    shape = faces_mask.shape
    for fr in res.faces:
        m = rasterize(fr.face.polygon, shape)
        best, best_iou = None, 0.0
        for g in truth["faces"]:
            gm = faces_mask == g["id"] + 1
            inter = np.count_nonzero(m & gm)
            if inter:
                iou = inter / max(np.count_nonzero(m), 1) if containment else inter / np.count_nonzero(m | gm)
                if iou > best_iou:
                    best, best_iou = g, iou
        if best_iou >= 0.5:
            out[fr.face.id] = best
    return out


def _backproject(poly, plane, k):
    n, d = np.asarray(plane["normal"], float), float(plane["offset"])
    r = np.stack([(poly[:, 0] - k.cx) / k.fx, (poly[:, 1] - k.cy) / k.fy, np.ones(len(poly))], 1)
    return r * (-d / (r @ n))[:, None]


def _corners(p) -> np.ndarray:
    prv, nxt = np.roll(p, 1, 0), np.roll(p, -1, 0)
    return np.array([_angle(a - c, b - c) for a, c, b in zip(prv, p, nxt)])


def _sides(p) -> np.ndarray:
    return np.linalg.norm(np.roll(p, -1, 0) - p, axis=1)


def face_truth(g: dict, k) -> dict:
    poly = np.asarray(g["polygon"], float)
    x = _backproject(poly, g["plane"], k)
    c3, s3 = _corners(x), _sides(x)
    e = np.roll(poly, -1, 0) - poly
    para = [180 - _angle(e[0], e[2]), 180 - _angle(e[1], e[3])] if len(poly) == 4 else [180.0]
    right = bool(np.all(np.abs(c3 - 90) < RIGHT_ANGLE_DEG))
    equal = s3.max() / s3.min() < EQUAL_SIDES_RATIO
    return {"quadrilateral_like": len(poly) == 4, "parallelogram": len(poly) == 4 and max(para) < PARALLEL_SIDES_DEG,
            "rectangle": len(poly) == 4 and right, "square": len(poly) == 4 and right and equal,
            "regular": equal and (c3.max() - c3.min()) < EQUAL_CORNERS_DEG, "corner2d": _corners(poly),
            "corner3d": c3, "log_side": np.log(s3), "poly": poly}


def truth_labels(cands, results, faces_mask, truth, k) -> list:
    """For each candidate (pred, args, p, value): True/False on the ground truth, or None where the truth
    says nothing (objects other than the target, faces cut by occlusion for shape predicates, predicates outside
    ``LABELLED``)."""
    match: dict = {}
    target_faces: set = set()
    for res in results:
        m = match_faces(res, faces_mask, truth, containment=True)
        if m:
            match.update(m)
            target_faces |= {fr.face.id for fr in res.faces}
    support = truth["support_plane"]["normal"]
    adj = {frozenset(a["faces"]): a["dihedral_deg"] for a in truth.get("adjacency", [])}
    cache = {}
    labels = []
    for pred, args, _, _ in cands:
        if pred not in LABELLED or not all(a in target_faces for a in args[-1:]):
            labels.append(None)
            continue
        if pred == "face_of":
            labels.append(args[1] in match)
            continue
        gs = [match.get(a) for a in args]
        if any(g is None for g in gs):
            labels.append(False)  # a fact about something that is no true face
            continue
        if len(args) == 1:
            g = gs[0]
            if g.get("visible_fraction", 1.0) < 0.9:
                labels.append(None)
                continue
            ft = cache.setdefault(g["id"], face_truth(g, k))
            if pred in NGONS:
                labels.append(g["sides"] == NGONS[pred])
            elif pred in FACE_SHAPES:
                labels.append(ft[pred])
            else:
                tilt = _angle(g["plane"]["normal"], support)
                tilt = min(tilt, 180 - tilt)
                labels.append(tilt < PLANE_ANGLE_DEG if pred == "horizontal" else abs(tilt - 90) < PLANE_ANGLE_DEG)
            continue
        ga, gb = gs
        between = _angle(ga["plane"]["normal"], gb["plane"]["normal"])
        dih = 180 - between
        key = frozenset((ga["id"], gb["id"]))
        if pred == "adjacent":
            labels.append(key in adj)
        elif pred == "perpendicular":
            labels.append(abs(dih - 90) < PERPENDICULAR_DEG and ga["id"] != gb["id"])
        elif pred == "parallel":
            labels.append(min(between, 180 - between) < PLANE_ANGLE_DEG)
        elif pred == "acute":
            labels.append(key in adj and adj[key] < ACUTE_BELOW_DEG)
        else:  # obtuse
            labels.append(key in adj and adj[key] > OBTUSE_ABOVE_DEG)
    return labels


def truth_quantities(res, match, truth, k) -> list[tuple[str, tuple[float, float]]]:
    """(floor name, (error, Laplace std)) of each measured quantity with a true counterpart."""
    out = []
    support = truth["support_plane"]["normal"]
    adj = {frozenset(a["faces"]): a["dihedral_deg"] for a in truth.get("adjacency", [])}
    for ids, g in res.raw:
        q, sd = g["quantities"], g["std"]
        for i, fid in enumerate(ids):
            t = match.get(fid)
            if t is None:
                continue
            fr = next(f for f in res.faces if f.face.id == fid)
            if fr.plane is not None:
                tilt = _angle(t["plane"]["normal"], support)
                out.append(("tilt_deg", (float(q["tilt_deg"][i]) - min(tilt, 180 - tilt), float(sd["tilt_deg"][i]))))
            if len(fr.polygon) != t["sides"] or t.get("visible_fraction", 1.0) < 0.9:
                continue
            ft = face_truth(t, k)
            d = np.linalg.norm(ft["poly"][:, None] - fr.polygon[None], axis=2)
            near = d.argmin(0)  # true vertex of each slot
            if len(set(near)) != len(near):
                continue
            n = len(near)
            for j in range(n):
                out.append(("corner_deg", (float(q["corner_deg"][i, j]) - ft["corner2d"][near[j]], float(sd["corner_deg"][i, j]))))
                if fr.plane is not None:
                    out.append(("corner3d_deg", (float(q["corner3d_deg"][i, j]) - ft["corner3d"][near[j]],
                                                 float(sd["corner3d_deg"][i, j]))))
                    a, b = near[j], near[(j + 1) % n]
                    if (b - a) % n in (1, n - 1):
                        side = ft["log_side"][a if (b - a) % n == 1 else b]
                        out.append(("log_side", (float(q["log_side_m"][i, j]) - side, float(sd["log_side_m"][i, j]))))
        for i, fa in enumerate(ids):
            for j, fb in enumerate(ids):
                ta, tb = match.get(fa), match.get(fb)
                if i < j and ta is not None and tb is not None and frozenset((ta["id"], tb["id"])) in adj:
                    if float(sd["dihedral_deg"][i, j]) > 0:
                        out.append(("dihedral_deg", (float(q["dihedral_deg"][i, j]) - adj[frozenset((ta["id"], tb["id"]))],
                                                     float(sd["dihedral_deg"][i, j]))))
    return out


def truth_scene(frame, faces_mask: np.ndarray, scene_id: str, rng: np.random.Generator, vertex_noise_px: float = 1.5,
                min_pixels: int = 200):
    """A Scene made from the ground truth as a perception step with known errors would make it: true
    polygons with Gaussian vertex noise, planes fitted (least squares) to the frame's depth inside each
    true face mask (eroded by 2 px, away from flying pixels), true adjacency and support plane."""
    import cv2

    from ..plane import Plane
    from ..scene import Face, Scene, SceneObject

    truth = frame.meta["truth"]
    k = frame.intrinsics
    faces = []
    for g in truth["faces"]:
        m = cv2.erode((faces_mask == g["id"] + 1).astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
        m &= frame.depth > 0
        if np.count_nonzero(m) < min_pixels:
            continue
        v, u = np.nonzero(m)
        pts = k.back_project(u, v, frame.depth[v, u])
        c = pts.mean(0)
        n = np.linalg.svd(pts - c, full_matrices=False)[2][-1]
        poly = np.asarray(g["polygon"], float) + rng.normal(0, vertex_noise_px, (len(g["polygon"]), 2))
        faces.append(Face(f"{scene_id}_o1_f{g['id'] + 1}", poly, "rgbd", plane=Plane.from_arrays(n, -n @ c), points=pts))
    ids = {f.id for f in faces}
    adj = [(f"{scene_id}_o1_f{a + 1}", f"{scene_id}_o1_f{b + 1}") for a, b in (x["faces"] for x in truth.get("adjacency", []))]
    adj = [p for p in adj if p[0] in ids and p[1] in ids]
    obj = SceneObject(f"{scene_id}_o1", faces, adj, pixel_count=int(np.count_nonzero(faces_mask)),
                      centroid_px=(k.width / 2, k.height / 2))
    sp = truth["support_plane"]
    return Scene(scene_id, "rgbd", k, [obj] if faces else [], support_plane=Plane.from_arrays(sp["normal"], sp["offset"]))
