"""Speed and accuracy of the statistical baselines on a *dev* data set (never the seed protocol's).

    .venv/bin/python -m benchmarks.bench_baselines [--data /tmp/cnndev/data] [--seed 1234]
        [--systems cnn-rgb,cnn-depth,cnn-rgbd,cnn-rgbd-2s,tree-rgbd] [--folds 1] [--threads 2] [--epochs N]

Renders 4 classes x 50 images (realsense noise) with the dev seed unless ``--data`` already holds
them, deals seeded stratified folds with the dev seed, and runs the seed protocol's tasks (4 class
tasks of 40 positives + 60 negatives, one multi-class task of 160 images) through the experiment
runner's own ``run_fold``, for the first ``--folds`` folds. Prints per training: wall and CPU
seconds and epochs run; per task: test accuracy (and balanced accuracy for the class tasks, where
chance is 0.5; multi-class chance is 0.25). The machine may be shared: compare CPU seconds.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", type=Path, default=Path("/tmp/cnndev/data"))
    ap.add_argument("--seed", type=int, default=1234, help="dev seed: data, folds and tasks")
    ap.add_argument("--systems", default="cnn-rgb,cnn-depth,cnn-rgbd,cnn-rgbd-2s,tree-rgbd")
    ap.add_argument("--folds", type=int, default=1, help="how many of the 5 folds to run")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--epochs", type=int, default=None, help="CNN epochs (default: the studies' setting)")
    args = ap.parse_args()

    from lv3d.baselines import cnn as cnn_mod
    from lv3d.experiment import data as data_mod
    from lv3d.experiment.config import from_dict
    from lv3d.experiment.folds import split, stratified_folds
    from lv3d.experiment.runner import run_fold
    from lv3d.experiment.systems import make_system

    baselines = {"threads": args.threads, **({"epochs": args.epochs} if args.epochs is not None else {})}
    cfg = from_dict({"seed": args.seed, "baselines": baselines}, "bench_baselines options")
    if not (args.data / "manifest.json").is_file():
        from lv3d.render import make_dataset
        from lv3d.render.noise import noise_config

        make_dataset(args.data, list(cfg.data.classes), cfg.data.per_class, noise_config("realsense"), args.seed)
    items = data_mod.read_items(args.data)
    pixels = data_mod.ensure_pixels(args.data, items, cfg.baselines.image_size)
    folds = stratified_folds(items, cfg.folds, args.seed)

    # record the wall/CPU time and epochs of every CNN training
    fits: list[tuple[float, float, int]] = []
    original_fit = cnn_mod.CNNClassifier.fit

    def timed_fit(self, *a, **k):
        t, c = time.perf_counter(), time.process_time()
        out = original_fit(self, *a, **k)
        fits.append((time.perf_counter() - t, time.process_time() - c, self.epochs_run))
        return out

    cnn_mod.CNNClassifier.fit = timed_fit
    for name in [s.strip() for s in args.systems.split(",") if s.strip()]:
        for k in range(args.folds):
            fits.clear()
            train, test = split(folds, k)
            t, c = time.perf_counter(), time.process_time()
            record = run_fold(make_system(name, cfg, pixels), cfg, train, test, k, None)
            wall, cpu = time.perf_counter() - t, time.process_time() - c
            accs = []
            for task, r in record["tasks"].items():
                bal = f" bal {r['balanced_accuracy']:.2f}" if "balanced_accuracy" in r else ""
                accs.append(f"{task[:6]} {r['accuracy']:.2f}{bal}")
            print(f"{name:12s} fold {k}: {wall:6.1f} s wall {cpu:6.1f} s CPU | " + " | ".join(accs))
            for w, cp, ep in fits:
                print(f"    training: {w:5.1f} s wall {cp:5.1f} s CPU, {ep} epochs")
            if fits:
                print(f"    mean per training: {np.mean([f[0] for f in fits]):.1f} s wall, "
                      f"{np.mean([f[1] for f in fits]):.1f} s CPU")


if __name__ == "__main__":
    main()
