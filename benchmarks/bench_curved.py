"""Curved surfaces in depth on rendered scenes: cylinders, cones and spheres found as faces of their kind, their
size and axis, and boxes kept free of curved faces. Each figure is printed beside its target (issue 40).

    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.bench_curved            # 10 scenes a class, clean and realsense
    OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.bench_curved --quick    # 3 a class
    .venv/bin/python -m benchmarks.bench_curved --presets realistic --modalities depth,rgbd --json out/curved.json
    .venv/bin/python -m benchmarks.bench_curved --polyhedra --set quadrics.max_step_deg=65.0   # depth settings other than the defaults

Scenes: ``--per-class`` of each of cylinder, cone and sphere, and of the boxes cube and cuboid, rendered from
seeds ``--seed`` on (lv3d.render.render_scene, 640x480), per preset; each perceived once per modality
(lv3d.perception.perceive). The other polyhedra (prisms, pyramid, tetrahedron) with ``--polyhedra``.

Definitions
-----------
*The curved truth face* of a cylinder, cone or sphere scene is the target's face whose ``surface`` is of that
type (the side; the sphere), counted where it covers ``--min-face-px`` pixels of the face mask or more.
A perceived face *overlaps* it when the face's polygon (filled with cv2.fillPoly, a curved face's outline is not
convex) and the true face's pixels have IoU >= 0.5, as bench_perception counts a face found.

``recall``: share of curved truth faces overlapped by a perceived face of the same surface type (any object).
``confused``: share overlapped by a curved face of another type (a cone read as a cylinder).
``radius_err``: median relative error of the found faces' radius: a cylinder's and a sphere's radius; a cone's
radius in the plane of its true base (the perceived cone's radius at the true base centre's distance along its
axis from its apex), against the true base radius.
``axis_deg``: median angle between the found face's axis and the true one (cylinders: either direction; cones:
from the apex towards the base).
``half_angle_deg``: median error of a found cone's half-angle (a diagnostic).
``radius_err_refined`` / ``axis_deg_refined``: the same two of a found cylinder after grounding's refinement
(lv3d.describe.read_cylinder: the cylinder its facts report); nan for cones and spheres, which have none.
``conf``: median of the found faces' fact confidences (lv3d.describe: cylindrical: curved_evidence of the
refined cylinder;
spherical: sphere_evidence; conical: cone_evidence), and how many faces have none (None: too few points or a
number that is not finite).
``box_curved``: share of box scenes (cube, cuboid) in which any perceived object has a curved face (target 0).
With ``--polyhedra``, the same share for each other polyhedron, split by surface (a diagnostic).
``unconverged``: sphere and cone least-squares fits that did not converge (lv3d.scene.Scene.unconverged_fits;
no face came of them), over all scenes; ``nan``: faces whose parameters are not finite (must be 0).
``ms``: median wall-clock time of perceive per frame (a machine shared with other jobs).

Colour alone (``--modalities rgb``) finds no curved surface; what it says instead is ``elliptical``, a face whose
outline is an ellipse (lv3d/perception/rgb/ellipse.py; the facts from lv3d.describe). ``elliptical``: per class,
the share of scenes whose target (Scene.target) has a face with an ``elliptical`` fact of confidence >= 0.5
(a ball, a lid; target 0 for the polyhedra), and ``elliptical_any``: the same for any object of the scene.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import cv2
import numpy as np
from tqdm import tqdm

from lv3d import compile_cache
from lv3d.errors import InputError
from lv3d.describe import curved_evidence, describe, read_cylinder
from lv3d.perception import perceive
from lv3d.perception.depth.quadrics import cone_evidence, sphere_evidence
from lv3d.render import render_scene
from benchmarks.bench_real import depth_settings
from benchmarks.targets import mark, meets

CURVED = ["cylinder", "cone", "sphere"]
BOXES = ["cube", "cuboid"]
POLYHEDRA = ["square_pyramid", "triangular_prism", "pentagonal_prism", "hexagonal_prism", "tetrahedron"]
TARGETS = {  # preset -> figure -> (comparison, value)
    "clean": {"recall": (">=", 0.95), "radius_err": ("<=", 0.05), "axis_deg": ("<=", 3.0), "box_curved": ("<=", 0.0)},
    "realsense": {"recall": (">=", 0.90), "radius_err": ("<=", 0.05), "box_curved": ("<=", 0.0)},
}


def _fill(poly: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    m = np.zeros(shape, np.uint8)
    cv2.fillPoly(m, [np.round(np.asarray(poly, float)).astype(np.int32).reshape(-1, 1, 2)], 1)
    return m.astype(bool)


def _angle(a, b, signed: bool) -> float:
    c = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(np.degrees(np.arccos(np.clip(c if signed else abs(c), -1.0, 1.0))))


def _params(face) -> np.ndarray:
    m = face.cylinder or face.sphere or face.cone
    return np.array([x for v in m.to_dict().values() for x in np.atleast_1d(v)], float) if m is not None else \
        np.zeros(0)


def _confidence(face) -> float | None:
    if face.points is None:
        return None
    if face.surface == "cylinder":
        return curved_evidence(face.points, face.cylinder)
    if face.surface == "sphere":
        return sphere_evidence(face.points, face.sphere)
    if face.surface == "cone":
        return cone_evidence(face.points, face.cone)
    return None


def evaluate(cls: str, seed: int, scene, frame, faces_mask: np.ndarray, min_face_px: int) -> dict:
    """One scene's figures against the truth in ``frame.meta['truth']`` and ``faces_mask``."""
    h, w = faces_mask.shape
    curved = [(o, f) for o in scene.objects for f in o.faces if f.surface != "plane"]
    out = {"cls": cls, "seed": seed, "curved_faces": {s: sum(f.surface == s for _, f in curved) for s in CURVED},
           "unconverged": scene.unconverged_fits,
           "nan": sum(not np.all(np.isfinite(_params(f))) for _, f in curved)}
    if cls not in CURVED:
        return out
    truth = [f for f in frame.meta["truth"]["faces"] if f.get("surface", {}).get("type") == cls]
    if not truth or np.count_nonzero(faces_mask == truth[0]["id"] + 1) < min_face_px:
        out["gt"] = 0
        return out
    g = truth[0]
    gm = faces_mask == g["id"] + 1
    best, best_iou = None, 0.0
    for _, f in curved:
        m = _fill(f.polygon, (h, w))
        inter = np.count_nonzero(m & gm)
        iou = inter / max(1, np.count_nonzero(m | gm))
        if iou > best_iou:
            best, best_iou = f, iou
    out.update(gt=1, found=0, confused=0)
    if best is None or best_iou < 0.5:
        return out
    if best.surface != cls:
        out["confused"] = 1
        return out
    out["found"] = 1
    s = g["surface"]
    if cls == "cylinder":
        k = scene.intrinsics
        reading = read_cylinder(best, (k.fx, k.fy, k.cx, k.cy))
        cyl = best.cylinder if reading is None else reading.cylinder
        out["conf"] = _confidence(best) if reading is None else reading.evidence
        out["radius_err"] = abs(best.cylinder.radius - s["radius"]) / s["radius"]
        out["axis_deg"] = _angle(best.cylinder.axis, s["axis"], signed=False)
        out["radius_err_refined"] = abs(cyl.radius - s["radius"]) / s["radius"]
        out["axis_deg_refined"] = _angle(cyl.axis, s["axis"], signed=False)
        return out
    out["conf"] = _confidence(best)
    if cls == "sphere":
        out["radius_err"] = abs(best.sphere.radius - s["radius"]) / s["radius"]
    else:
        c = best.cone
        true_r = s["height"] * np.tan(np.radians(s["half_angle_deg"]))
        base = np.asarray(s["apex"]) + s["height"] * np.asarray(s["axis"])
        r = c.radius_at(float((base - np.asarray(c.apex)) @ np.asarray(c.axis)))
        out["radius_err"] = abs(r - true_r) / true_r
        out["axis_deg"] = _angle(c.axis, s["axis"], signed=True)
        out["half_angle_deg"] = abs(c.half_angle_deg - s["half_angle_deg"])
    return out


ELLIPTICAL_CONF = 0.5  # an elliptical face counts at this confidence or more


def elliptical_faces(scene, frame) -> tuple[bool, bool]:
    """Whether the scene's target, and whether any of its objects, has a face with an ``elliptical`` fact of
    confidence >= ELLIPTICAL_CONF (colour alone)."""
    facts = describe(scene, frame)
    owner = {f.args[1]: f.args[0] for f in facts.facts if f.pred == "face_of"}
    objs = {owner.get(f.args[0]) for f in facts.facts if f.pred == "elliptical" and f.conf >= ELLIPTICAL_CONF}
    return facts.target in objs, bool(objs)


def summarise(rows: list[dict], classes: list[str]) -> dict:
    med = lambda xs: float(np.median(xs)) if xs else float("nan")  # noqa: E731
    out = {}
    for cls in classes:
        rs = [r for r in rows if r["cls"] == cls]
        if cls in CURVED:
            gt = [r for r in rs if r.get("gt")]
            found = [r for r in gt if r["found"]]
            confs = [r["conf"] for r in found]
            out[cls] = {"scenes": len(rs), "gt": len(gt), "recall": len(found) / max(1, len(gt)),
                        "confused": sum(r["confused"] for r in gt) / max(1, len(gt)),
                        "radius_err": med([r["radius_err"] for r in found]),
                        "axis_deg": med([r["axis_deg"] for r in found if "axis_deg" in r]),
                        "half_angle_deg": med([r["half_angle_deg"] for r in found if "half_angle_deg" in r]),
                        "radius_err_refined": med([r["radius_err_refined"] for r in found if "radius_err_refined" in r]),
                        "axis_deg_refined": med([r["axis_deg_refined"] for r in found if "axis_deg_refined" in r]),
                        "conf": med([c for c in confs if c is not None]), "no_conf": sum(c is None for c in confs)}
        else:
            n = max(1, len(rs))
            out[cls] = {"scenes": len(rs), "any_curved": sum(any(r["curved_faces"].values()) for r in rs) / n,
                        **{s: sum(r["curved_faces"][s] > 0 for r in rs) / n for s in CURVED}}
        if rs and all("elliptical" in r for r in rs):
            out[cls]["elliptical"] = sum(r["elliptical"] for r in rs) / len(rs)
            out[cls]["elliptical_any"] = sum(r["elliptical_any"] for r in rs) / len(rs)
    gts = [r for r in rows if r["cls"] in CURVED and r.get("gt")]
    found = [r for r in gts if r["found"]]
    boxes = [r for r in rows if r["cls"] in BOXES]
    out["all"] = {"recall": len(found) / max(1, len(gts)), "radius_err": med([r["radius_err"] for r in found]),
                  "axis_deg": med([r["axis_deg"] for r in found if "axis_deg" in r]),
                  "box_curved": sum(any(r["curved_faces"].values()) for r in boxes) / max(1, len(boxes)),
                  "unconverged": sum(r["unconverged"] for r in rows), "nan": sum(r["nan"] for r in rows)}
    return out


def _target(preset: str, key: str, value: float) -> str:
    if preset not in TARGETS or key not in TARGETS[preset]:
        return "-"
    op, t = TARGETS[preset][key]
    return f"{op} {t} {mark(meets(op, t, value))}"


def main(argv=None) -> int:
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="3 scenes a class")
    ap.add_argument("--per-class", type=int, default=10)
    ap.add_argument("--presets", default="clean,realsense")
    ap.add_argument("--modalities", default="depth")
    ap.add_argument("--seed", type=int, default=1000)
    ap.add_argument("--polyhedra", action="store_true", help="also the prisms, pyramid and tetrahedron (a diagnostic)")
    ap.add_argument("--min-face-px", type=int, default=200, help="ignore true faces with fewer visible pixels")
    ap.add_argument("--json", type=Path, metavar="FILE", help="write the figures as JSON")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a depth-stage setting other than its default, as bench_real takes it (repeatable)")
    args = ap.parse_args(argv)
    try:
        settings = depth_settings(args.set)
    except InputError as e:
        print(f"bench_curved.py: error: {e}", file=sys.stderr)
        return 2
    per_class = 3 if args.quick else args.per_class
    classes = CURVED + BOXES + (POLYHEDRA if args.polyhedra else [])
    modalities = args.modalities.split(",")
    report = {}
    for preset in args.presets.split(","):
        rows: dict[str, list[dict]] = {m: [] for m in modalities}
        ms: dict[str, list[float]] = {m: [] for m in modalities}
        t0 = time.perf_counter()
        for cls in tqdm(classes, desc=preset, disable=None, leave=False):
            for i in range(per_class):
                frame, faces_mask = render_scene(cls, args.seed + i, noise=preset)
                for m in modalities:
                    t = time.perf_counter()
                    scene = perceive(frame, m, scene_id=f"s{i:06d}", depth_settings=settings)
                    ms[m].append((time.perf_counter() - t) * 1e3)
                    rows[m].append(evaluate(cls, args.seed + i, scene, frame, faces_mask, args.min_face_px))
                    if m == "rgb":
                        rows[m][-1]["elliptical"], rows[m][-1]["elliptical_any"] = elliptical_faces(scene, frame)
        print(f"\n== preset {preset}: {per_class} scenes a class, seeds {args.seed}-{args.seed + per_class - 1} "
              f"({time.perf_counter() - t0:.0f} s)")
        report[preset] = {}
        for m in modalities:
            s = summarise(rows[m], classes)
            report[preset][m] = dict(s, ms_median=float(np.median(ms[m])))
            a = s["all"]
            print(f"-- {m}")
            print(f"{'figure':22} {'all':>7} " + " ".join(f"{c:>9}" for c in CURVED) + "   target")
            for key, fmt in (("recall", "{:.3f}"), ("radius_err", "{:.3f}"), ("axis_deg", "{:.2f}")):
                per = " ".join(f"{fmt.format(s[c][key]):>9}" for c in CURVED)
                print(f"{key:22} {fmt.format(a[key]):>7} {per}   {_target(preset, key, a[key])}")
            for key, fmt in (("radius_err_refined", "{:.3f}"), ("axis_deg_refined", "{:.2f}"),
                             ("confused", "{:.3f}"), ("half_angle_deg", "{:.2f}"), ("conf", "{:.3f}"),
                             ("no_conf", "{:d}"), ("gt", "{:d}")):
                per = " ".join(f"{fmt.format(s[c][key]):>9}" for c in CURVED)
                print(f"{key:22} {'':>7} {per}   -")
            print(f"{'box_curved':22} {a['box_curved']:7.3f}   {_target(preset, 'box_curved', a['box_curved'])}")
            for c in BOXES + (POLYHEDRA if args.polyhedra else []):
                print(f"{c + ' curved':22} {s[c]['any_curved']:7.3f}   (" +
                      ", ".join(f"{k} {s[c][k]:.2f}" for k in CURVED) + ")   -")
            missed = [f"{r['cls']}:{r['seed']}" for r in rows[m] if r.get("gt") and not r["found"]]
            curved_boxes = [f"{r['cls']}:{r['seed']}" for r in rows[m]
                            if r["cls"] in BOXES and any(r["curved_faces"].values())]
            print(f"{'missed (class:seed)':22} {' '.join(missed) or '-'}")
            print(f"{'boxes with curved':22} {' '.join(curved_boxes) or '-'}")
            print(f"{'unconverged fits':22} {a['unconverged']:7d}   -")
            print(f"{'nan parameters':22} {a['nan']:7d}   = 0 {mark(a['nan'] == 0)}")
            print(f"{'ms per frame, median':22} {np.median(ms[m]):7.0f}   -")
            if m == "rgb":
                print(f"{'elliptical (target / any object), confidence >= 0.5':52}   target")
                for c in classes:
                    goal = "-" if c in CURVED else "0 " + mark(s[c]["elliptical"] == 0)
                    print(f"  {c:20} {s[c]['elliptical']:7.3f} {s[c]['elliptical_any']:7.3f}   {goal}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
