"""What tuning the CNN baseline costs, and what it chooses, on a *dev* data set (never a study's).

    .venv/bin/python -m benchmarks.bench_tuning [--data /tmp/cnndev/data] [--seed 1234] [--system cnn-rgbd]
        [--fold 0] [--mode time|tune] [--widths 8,16,32] [--epochs 20,40] [--augment 0,1] [--sizes 32,64]
        [--inner-folds 3]
    .venv/bin/python -m benchmarks.bench_tuning --quick    # --mode time over a grid of two short settings

Renders 4 classes x 50 images (realsense noise) with the dev seed unless ``--data`` already holds them,
deals the study's seeded stratified folds with the dev seed and takes the training folds of ``--fold``.

``--mode time``: one multi-class training per grid setting on the first inner training split (what each
of the search's trainings sees), timed (wall and CPU seconds), then the search's cost per outer fold:
inner folds x the sum over the grid. ``--mode tune``: the whole search as a study runs it
(lv3d.experiment.systems.PixelSystem.tune, seeded like the runner), its choice and time, and the
multi-class accuracy on the held-out outer fold of the chosen setting and of the untuned defaults.
The machine may be shared: compare CPU seconds. ``--quick`` (what ``run_all --quick`` runs) times a grid of
two settings of 3 epochs (widths 8 and 16, no augmentation, 32 px) with 2 inner folds: a smoke test of the
timing, not the study's grid.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np


def _ints(text: str) -> list[int]:
    return [int(v) for v in text.split(",") if v.strip()]


QUICK = {"mode": "time", "widths": "8,16", "epochs": "3", "augment": "0", "sizes": "32", "inner_folds": 2}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", type=Path, default=Path("/tmp/cnndev/data"))
    ap.add_argument("--seed", type=int, default=1234, help="dev seed: data, folds and tuning")
    ap.add_argument("--system", default="cnn-rgbd")
    ap.add_argument("--fold", type=int, default=0, help="the outer fold held out")
    ap.add_argument("--mode", choices=("time", "tune"), default="time")
    ap.add_argument("--widths", default="8,16,32")
    ap.add_argument("--epochs", default="20,40")
    ap.add_argument("--augment", default="0,1")
    ap.add_argument("--sizes", default="32,64")
    ap.add_argument("--inner-folds", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="--mode time over a grid of two short settings "
                                                          "(overrides the grid options)")
    args = ap.parse_args(argv)
    if args.quick:
        for k, v in QUICK.items():
            setattr(args, k, v)

    from lv3d.baselines import CNNClassifier
    from lv3d.baselines.tuning import area_downsample, grid, inner_folds
    from lv3d.experiment import data as data_mod
    from lv3d.experiment.config import from_dict
    from lv3d.experiment.folds import split, stratified_folds
    from lv3d.experiment.runner import tune_seed
    from lv3d.experiment.systems import make_system

    baselines = {"tune": True, "tune_width": _ints(args.widths), "tune_epochs": _ints(args.epochs),
                 "tune_augment": [bool(v) for v in _ints(args.augment)], "tune_image_size": _ints(args.sizes),
                 "tune_folds": args.inner_folds}
    cfg = from_dict({"seed": args.seed, "systems": [args.system], "baselines": baselines}, "bench_tuning options")
    if not (args.data / "manifest.json").is_file():
        from lv3d.render import make_dataset
        from lv3d.render.noise import noise_config

        make_dataset(args.data, list(cfg.data.classes), cfg.data.per_class, noise_config("realsense"), args.seed)
    items = data_mod.read_items(args.data)
    pixels = data_mod.ensure_pixels(args.data, items, cfg.baselines.image_size)
    train, test = split(stratified_folds(items, cfg.folds, args.seed), args.fold)
    system = make_system(args.system, cfg, pixels)
    arch = "twostream" if args.system.endswith("-2s") else "early"
    b = cfg.baselines
    settings = grid(b.tune_width, b.tune_epochs, b.tune_augment, b.tune_image_size, system.modality, arch)
    print(f"{args.system}, fold {args.fold}: {len(train)} training examples, {len(test)} held out; "
          f"{len(settings)} settings x {b.tune_folds} inner folds")

    if args.mode == "time":
        labels = [it.cls for it in train]
        tr, _ = inner_folds(labels, [it.group_key for it in train], b.tune_folds, args.seed)[0]
        x = system._x([it.id for it in train])
        base = system.cnn_settings()
        total_wall = total_cpu = 0.0
        for s in settings:
            xs = area_downsample(x, s.image_size)[tr]
            settings_s = replace(base, width=s.width, epochs=s.epochs, augment=s.augment)
            model = CNNClassifier(system.modality, arch, settings_s)
            t, c = time.perf_counter(), time.process_time()
            model.fit(xs, [labels[i] for i in tr], seed=1)
            wall, cpu = time.perf_counter() - t, time.process_time() - c
            total_wall, total_cpu = total_wall + wall, total_cpu + cpu
            print(f"  width {s.width:3d} epochs {s.epochs:3d} augment {int(s.augment)} size {s.image_size:3d}: "
                  f"{len(tr)} images, {wall:6.2f} s wall {cpu:6.2f} s CPU")
        k = b.tune_folds
        print(f"one pass over the grid: {total_wall:.0f} s wall {total_cpu:.0f} s CPU; the search, x {k} inner "
              f"folds: about {k * total_wall / 60:.1f} min wall {k * total_cpu / 60:.1f} min CPU per outer fold")
        return

    t = time.perf_counter()
    tuned = system.tune(train, tune_seed(args.seed, args.fold))
    print(f"search: {time.perf_counter() - t:.0f} s wall; chosen {tuned['setting']}, inner accuracy "
          f"{tuned['inner_accuracy']:.3f}")
    for row in sorted(tuned["grid"], key=lambda r: -r["accuracy"]):
        print(f"  width {row['width']:3d} epochs {row['epochs']:3d} augment {int(row['augment'])} "
              f"size {row['image_size']:3d}: inner {row['accuracy']:.3f} "
              f"({', '.join(f'{a:.2f}' for a in row['per_fold'])})")
    ids, truth = [it.id for it in train], [it.cls for it in train]
    test_ids = [it.id for it in test]
    for name, sys_ in (("tuned", system), ("defaults", make_system(args.system, cfg, pixels))):
        fitted = sys_.fit(ids, truth, tune_seed(args.seed, args.fold))
        acc = np.mean([label == it.cls for (label, _), it in zip(fitted.predict(test_ids), test)])
        print(f"held-out outer fold, multi-class on all {len(ids)} training examples, {name}: {acc:.3f}")


if __name__ == "__main__":
    main()
