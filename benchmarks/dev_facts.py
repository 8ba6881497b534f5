"""Render a DEV data set (a seed other than the study's) and cache its pipeline and truth facts.

    .venv/bin/python -m benchmarks.dev_facts --preset clean --seed 777 --per-class 30 --out runs/dev_clean

Writes <out>/facts_<modality>.pkl: {scene id: (label, pipeline SceneFacts, truth SceneFacts, meta truth)}.
bench_learner and bench_pipeline_accuracy learn from such DEV sets, never from the study's data (seed 0).
"""

from __future__ import annotations

import argparse
import json
import pickle
import time
from pathlib import Path

CLASSES = ["cube", "square_pyramid", "triangular_prism", "pentagonal_prism"]
MODALITIES = ("rgbd", "depth", "rgb")


def make_dev_facts(out: Path, preset: str, seed: int, per_class: int, modalities=MODALITIES) -> Path:
    """Render the DEV set ``out`` (resumes) and write ``out/facts_<modality>.pkl`` for each of ``modalities``
    (scenes already in a file are kept)."""
    from lv3d.pipeline import scene_facts
    from lv3d.render import make_dataset
    from lv3d.rgbd import load_item
    from lv3d.truth_facts import truth_facts

    make_dataset(out, CLASSES, per_class, preset, seed=seed, progress=False)
    man = json.loads((out / "manifest.json").read_text())
    for mod in modalities:
        path = out / f"facts_{mod}.pkl"
        res = pickle.loads(path.read_bytes()) if path.exists() else {}
        t0 = time.time()
        for it in man["items"]:
            if it["id"] in res:
                continue
            frame = load_item(out / it["dir"])
            try:
                pf = scene_facts(frame, it["id"], mod)
            except Exception as e:  # a failure is data for the benchmark: the scene answers 'unknown'
                print(it["id"], mod, "pipeline error", repr(e)[:200], flush=True)
                pf = None
            tf = truth_facts(frame.meta, it["id"], mod)
            res[it["id"]] = (it["class"], pf, tf, frame.meta.get("truth"))
        path.write_bytes(pickle.dumps(res))
        print(mod, len(res), f"{time.time() - t0:.0f}s", flush=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", default="clean")
    ap.add_argument("--seed", type=int, default=777)
    ap.add_argument("--per-class", type=int, default=30)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--modalities", default=",".join(MODALITIES))
    a = ap.parse_args()
    make_dev_facts(a.out, a.preset, a.seed, a.per_class, a.modalities.split(","))


if __name__ == "__main__":
    main()
