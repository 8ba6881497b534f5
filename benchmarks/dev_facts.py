"""Render a DEV data set (a seed other than the study's) and cache its pipeline and truth facts.

    .venv/bin/python benchmarks/dev_facts.py --preset clean --seed 777 --per-class 30 --out /work/runs/dev_clean

Writes <out>/facts_<modality>.pkl: {scene id: (label, pipeline SceneFacts, truth SceneFacts, meta truth)}.
Analysis and tuning use only such DEV sets, never the study's held-out folds.
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

CLASSES = ["cube", "square_pyramid", "triangular_prism", "pentagonal_prism"]
MODALITIES = ("rgbd", "depth", "rgb")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--preset", default="clean")
    ap.add_argument("--seed", type=int, default=777)
    ap.add_argument("--per-class", type=int, default=30)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--modalities", default=",".join(MODALITIES))
    a = ap.parse_args()
    from lv3d.pipeline import scene_facts
    from lv3d.render import make_dataset
    from lv3d.rgbd import load_item
    from lv3d.truth_facts import truth_facts

    make_dataset(a.out, CLASSES, a.per_class, a.preset, seed=a.seed, progress=False)
    man = json.loads((a.out / "manifest.json").read_text())
    for mod in a.modalities.split(","):
        path = a.out / f"facts_{mod}.pkl"
        res = pickle.loads(path.read_bytes()) if path.exists() else {}
        t0 = time.time()
        for it in man["items"]:
            if it["id"] in res:
                continue
            frame = load_item(a.out / it["dir"])
            try:
                pf = scene_facts(frame, it["id"], mod)
            except Exception as e:  # a failure is data for this analysis
                print(it["id"], mod, "pipeline error", repr(e)[:200], flush=True)
                pf = None
            tf = truth_facts(frame.meta, it["id"], mod)
            res[it["id"]] = (it["class"], pf, tf, frame.meta.get("truth"))
        path.write_bytes(pickle.dumps(res))
        print(mod, len(res), f"{time.time() - t0:.0f}s", flush=True)


if __name__ == "__main__":
    main()
