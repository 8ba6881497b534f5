"""Candidate facts of perceived dev scenes with their ground-truth labels and the measurements behind them:
the data the confidence calibration (grounding/_calibration.py) is fitted on and checked against.

    .venv/bin/python -m benchmarks.calibration_data --fresh --seed 30000 --per-class 50 --modalities rgbd,depth --out out/calib/s6_a50.pkl

Scenes are ``render_scene(cls, seed + 1000 * class_index + i, preset)`` for the 7 bench classes: dev seeds
only (never the study's seed-0 data set). Each row: modality, predicate, raw probability (before any
calibration), truth label (True/False; candidates the truth says nothing about are left out) and the
face measurements ``lv3d.describe.calibration_features`` gives (with the candidate's measured ``value``).
Rows are appended per scene, so an interrupted run resumes; ``--fresh`` starts the file over (after
perception or grounding changed, old rows are stale).
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

from benchmarks.grounding_truth import truth_labels

CLASSES = ["cube", "cuboid", "square_pyramid", "triangular_prism", "pentagonal_prism", "hexagonal_prism",
           "tetrahedron"]


def scene_rows(cls: str, seed: int, preset: str, modalities: list[str]) -> list[dict]:
    from lv3d.describe import calibration_features, ground
    from lv3d.perception import perceive
    from lv3d.render import render_scene

    frame, faces_mask = render_scene(cls, seed, preset)
    rows = []
    for mod in modalities:
        scene = perceive(frame, mod, scene_id=f"s{seed:06d}")
        cands, results = ground(scene, frame, refine=True, calibrate=False)
        labels = truth_labels(cands, results, faces_mask, frame.meta["truth"], frame.intrinsics)
        feats = calibration_features(cands, results)
        for (pred, args, p, value), y, f in zip(cands, labels, feats):
            if y is not None:
                rows.append({"modality": mod, "pred": pred, "p": float(p), "y": bool(y), "cls": cls, "seed": seed,
                             "source": f"render:{preset}", **f, "value": value})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=30000)
    ap.add_argument("--per-class", type=int, default=20)
    ap.add_argument("--preset", default="realsense")
    ap.add_argument("--modalities", default="rgbd,depth,rgb")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--fresh", action="store_true", help="start --out over instead of resuming it")
    a = ap.parse_args(argv)
    done = pickle.loads(a.out.read_bytes()) if a.out.exists() and not a.fresh else {"rows": [], "scenes": []}
    done["made_by"] = " ".join(["python -m benchmarks.calibration_data", *(sys.argv[1:] if argv is None else argv)])
    a.out.parent.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    for s in range(a.per_class):
        for ci, cls in enumerate(CLASSES):
            seed = a.seed + 1000 * ci + s
            if seed in done["scenes"]:
                continue
            try:
                done["rows"] += scene_rows(cls, seed, a.preset, a.modalities.split(","))
            except Exception as e:  # noqa: BLE001 - a failing scene is reported, not fatal
                print(f"  {cls} {seed}: {e!r}"[:200], flush=True)
            done["scenes"].append(seed)
            a.out.write_bytes(pickle.dumps(done))
        print(f"{s + 1}/{a.per_class} per class, {len(done['rows'])} rows, {time.time() - t0:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
