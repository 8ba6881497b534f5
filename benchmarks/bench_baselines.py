"""Speed and accuracy of the statistical baselines on a *dev* data set (never the seed protocol's).

    .venv/bin/python -m benchmarks.bench_baselines [--data /tmp/cnndev/data] [--seed 1234]
        [--systems cnn-rgb,cnn-depth,cnn-rgbd,cnn-rgbd-2s,tree-rgbd,effnet-rgb,effnet-depth,effnet-rgbd]
        [--folds 1] [--threads 2] [--epochs N] [--positives 40]
        [--effnet-c 0.01,0.1,1] [--effnet-input-size 224,128] [--effnet-compare]

Renders 4 classes x 50 images (realsense noise) with the dev seed unless ``--data`` already holds
them, deals seeded stratified folds with the dev seed, and runs the seed protocol's tasks (4 class
tasks of 40 positives + 60 negatives, one multi-class task of 160 images; ``--positives`` for fewer)
through the experiment runner's own ``run_fold``, for the first ``--folds`` folds. Prints per training:
wall and CPU seconds and epochs run; per task: test accuracy (and balanced accuracy for the class tasks,
where chance is 0.5; multi-class chance is 0.25); per system, the means over the folds. The machine may
be shared: compare CPU seconds.

The pretrained baseline (effnet-*): first the network's features of every image of the data set, per
stream (rgb, jet-coloured depth) and input size, timed (milliseconds per image, wall and CPU; they are
cached in the process, so the folds then only train the linear classifier); then each effnet system
once for every ``--effnet-c`` x ``--effnet-input-size`` (default: the studies' settings), and with
``--effnet-compare`` also, at the studies' C and input size, with the other normalisation of the
network's input ('imagenet') and the other scaling of the features ('per_feature';
lv3d.baselines.pretrained.PretrainedSettings).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", type=Path, default=Path("/tmp/cnndev/data"))
    ap.add_argument("--seed", type=int, default=1234, help="dev seed: data, folds and tasks")
    ap.add_argument("--systems", default="cnn-rgb,cnn-depth,cnn-rgbd,cnn-rgbd-2s,tree-rgbd,"
                                         "effnet-rgb,effnet-depth,effnet-rgbd")
    ap.add_argument("--folds", type=int, default=1, help="how many of the 5 folds to run")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--epochs", type=int, default=None, help="CNN epochs (default: the studies' setting)")
    ap.add_argument("--positives", type=int, default=None, help="per class task (default: the studies' 40)")
    ap.add_argument("--effnet-c", default=None, help="comma-separated C values of effnet-* (default: the studies')")
    ap.add_argument("--effnet-input-size", default=None,
                    help="comma-separated input sizes of effnet-*, pixels a side (default: the studies')")
    ap.add_argument("--effnet-compare", action="store_true",
                    help="effnet-* also with normalisation 'imagenet' and with scaling 'per_feature'")
    args = ap.parse_args()

    from lv3d.baselines import cnn as cnn_mod
    from lv3d.baselines import pretrained
    from lv3d.experiment import data as data_mod
    from lv3d.experiment.config import from_dict
    from lv3d.experiment.folds import split, stratified_folds
    from lv3d.experiment.runner import run_fold
    from lv3d.experiment.systems import make_system

    baselines = {"threads": args.threads, **({"epochs": args.epochs} if args.epochs is not None else {})}
    train = {"positives": args.positives} if args.positives is not None else {}
    cfg = from_dict({"seed": args.seed, "baselines": baselines, "train": train}, "bench_baselines options")
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
    names = [s.strip() for s in args.systems.split(",") if s.strip()]
    b = cfg.baselines
    cs = [float(v) for v in args.effnet_c.split(",")] if args.effnet_c else [b.effnet_c]
    sizes = [int(v) for v in args.effnet_input_size.split(",")] if args.effnet_input_size else [b.effnet_input_size]
    if any(n.startswith("effnet-") for n in names):
        time_features(pixels, names, sizes, args.threads)
    # the classifier's settings beyond the study's, for --effnet-compare (PretrainedClassifier reads them)
    extra: dict = {}
    original_init = pretrained.PretrainedClassifier.__init__

    def init(self, modality, settings=None):
        original_init(self, modality, replace(settings or pretrained.PretrainedSettings(), **extra))

    pretrained.PretrainedClassifier.__init__ = init
    summary = []
    for name in names:
        variants = [(name, cfg, {})]
        if name.startswith("effnet-"):
            variants = []
            for size in sizes:
                for c in cs:
                    vcfg = from_dict({"seed": args.seed, "train": train,
                                      "baselines": {**baselines, "effnet_c": c, "effnet_input_size": size}},
                                     "effnet options")
                    variants.append((f"{name} C={c:g} {size}px", vcfg, {}))
            if args.effnet_compare:  # at the studies' C and input size
                variants += [(f"{name} C={b.effnet_c:g} {b.effnet_input_size}px {k}={v}", cfg, {k: v})
                             for k, v in (("normalisation", "imagenet"), ("scaling", "per_feature"))]
        for label, vcfg, more in variants:
            extra.clear()
            extra.update(more)
            records = []
            for k in range(args.folds):
                fits.clear()
                train_items, test = split(folds, k)
                t, c = time.perf_counter(), time.process_time()
                record = run_fold(make_system(name, vcfg, pixels), vcfg, train_items, test, k, None)
                wall, cpu = time.perf_counter() - t, time.process_time() - c
                accs = []
                for task, r in record["tasks"].items():
                    bal = f" bal {r['balanced_accuracy']:.2f}" if "balanced_accuracy" in r else ""
                    accs.append(f"{task[:6]} {r['accuracy']:.2f}{bal}")
                print(f"{label:12s} fold {k}: {wall:6.1f} s wall {cpu:6.1f} s CPU | " + " | ".join(accs))
                print_fits(fits)
                records.append(record)
            summary.append((label, means(records)))
    print(f"means over {args.folds} fold(s), {cfg.train.positives} positives per class task "
          "(class tasks: accuracy, balanced accuracy; multi-class: accuracy):")
    for label, (acc, bal, multi) in summary:
        print(f"  {label:40s} class tasks {acc:.3f} balanced {bal:.3f} | multi-class {multi:.3f}")


def means(records: list[dict]) -> tuple[float, float, float]:
    """Over the folds' records: the class tasks' mean accuracy and balanced accuracy, the multi-class accuracy."""
    binary = [r for rec in records for task, r in rec["tasks"].items() if task != "multiclass"]
    multi = [rec["tasks"]["multiclass"]["accuracy"] for rec in records if "multiclass" in rec["tasks"]]
    return (float(np.mean([r["accuracy"] for r in binary])), float(np.mean([r["balanced_accuracy"] for r in binary])),
            float(np.mean(multi)) if multi else float("nan"))


def time_features(pixels: dict, names: list[str], sizes: list[int], threads: int) -> None:
    """The network's features of every image, per stream the effnet systems of ``names`` need and per input
    size, computed (and so cached for the folds) and timed."""
    from lv3d.baselines import pretrained

    x = np.stack(list(pixels.values()))
    streams = {s for n in names if n.startswith("effnet-") for s in pretrained.STREAMS[n.split("-")[1]]}
    for size in sizes:
        settings = pretrained.PretrainedSettings(input_size=size, threads=threads)
        pretrained.network(size)  # loading the weights is not the features' time
        for stream in ("rgb", "depth"):
            if stream not in streams:
                continue
            t, c = time.perf_counter(), time.process_time()
            f = pretrained.features(x[:, :3] if stream == "rgb" else x[:, 3:4], stream, settings)
            wall, cpu = time.perf_counter() - t, time.process_time() - c
            print(f"effnet features {stream:5s} {size}px: {1000 * wall / len(x):6.1f} ms/image wall, "
                  f"{1000 * cpu / len(x):6.1f} ms CPU ({len(x)} images, {f.shape[1]} numbers each, {threads} threads)")


def print_fits(fits: list[tuple[float, float, int]]) -> None:
    """The wall/CPU seconds and epochs of each CNN training of one fold."""
    for w, cp, ep in fits:
        print(f"    training: {w:5.1f} s wall {cp:5.1f} s CPU, {ep} epochs")
    if fits:
        print(f"    mean per training: {np.mean([f[0] for f in fits]):.1f} s wall, "
              f"{np.mean([f[1] for f in fits]):.1f} s CPU")


if __name__ == "__main__":
    main()
