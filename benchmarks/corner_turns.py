"""Which turn tells a face's true corners from the kinks of a traced outline: in the image, or on the face's plane?

For the target object's faces with a plane in rendered dev scenes (rgbd and depth perception, refined by
grounding), each face matched to its true face (IoU >= 0.5), this prints how often counting the vertices whose turn
exceeds a limit gives the true side count, per limit, for the image turn and for the turn on the refined plane; and
the weakest turn of faces with one vertex too many against that of faces with the right number. It chose the side-count
facts' limits (grounding/_confidence.py: 15 deg in the image, 35 deg on a plane; docs/grounding.md):

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/corner_turns.py --seed 9000 --per-class 15

Scenes are ``render_scene(cls, seed + 1000 * class_index + i, preset)``: dev seeds only, never the study's data.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.grounding_truth import _backproject, _corners, match_faces  # noqa: E402

CLASSES = ["cube", "cuboid", "square_pyramid", "triangular_prism", "pentagonal_prism", "hexagonal_prism",
           "tetrahedron"]
IMAGE_LIMITS = (10, 15, 20, 25)
PLANE_LIMITS = (15, 20, 25, 30, 35, 40)


def turns_deg(p: np.ndarray) -> np.ndarray:
    """How far a closed outline (n, 2 or 3) turns at each vertex, degrees (0: straight on): 180 minus its corners
    (grounding_truth's, which the truth side counts use)."""
    return 180.0 - _corners(p)


def face_rows(cls: str, seed: int, preset: str) -> list[dict]:
    from lv3d.describe import ground
    from lv3d.perception import perceive
    from lv3d.render import render_scene

    frame, faces_mask = render_scene(cls, seed, preset)
    rows = []
    for mod in ("rgbd", "depth"):
        _, results = ground(perceive(frame, mod, scene_id=f"s{seed:06d}"), frame, refine=True, calibrate=False)
        for res in results:
            matched = match_faces(res, faces_mask, frame.meta["truth"])
            for fr in res.faces:
                g = matched.get(fr.face.id)
                if g is None or fr.plane is None:
                    continue
                poly, plane = np.asarray(fr.polygon, float), np.asarray(fr.plane, float)
                on_plane = _backproject(poly, {"normal": plane[:3], "offset": plane[3]}, frame.intrinsics)
                rows.append({"modality": mod, "n": len(poly), "true": g["sides"], "image": turns_deg(poly),
                             "plane": turns_deg(on_plane)})
    return rows


def report(rows: list[dict]) -> None:
    for mod in ("rgbd", "depth"):
        rs = [r for r in rows if r["modality"] == mod]
        if not rs:
            continue
        right_n = np.mean([r["n"] == r["true"] for r in rs])
        print(f"{mod}: {len(rs)} faces; polygon has the true side count {right_n:.3f},"
              f" one vertex too many {np.mean([r['n'] == r['true'] + 1 for r in rs]):.3f}")
        for where, limits in (("image", IMAGE_LIMITS), ("plane", PLANE_LIMITS)):
            print(f"  {where} turn > limit: side count right  "
                  + "  ".join(f"{t}: {np.mean([(r[where] > t).sum() == r['true'] for r in rs]):.3f}" for t in limits))
        extra = [r for r in rs if r["n"] == r["true"] + 1]
        right = [r for r in rs if r["n"] == r["true"]]
        for where in ("image", "plane"):
            if extra and right:
                median = np.median([r[where].min() for r in extra])
                print(f"  weakest {where} turn: one too many, median {median:.1f} deg"
                      f" (n = {len(extra)}); right count, 5th percentile "
                      f"{np.percentile([r[where].min() for r in right], 5):.1f} deg (n = {len(right)})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=9000)
    ap.add_argument("--per-class", type=int, default=15)
    ap.add_argument("--preset", default="realsense")
    a = ap.parse_args(argv)
    rows = []
    for ci, cls in enumerate(CLASSES):
        for i in range(a.per_class):
            rows += face_rows(cls, a.seed + 1000 * ci + i, a.preset)
        print(f"{cls}: {len(rows)} faces so far", file=sys.stderr, flush=True)
    report(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
