"""Every benchmark, one after the other, each printing its figures beside its targets.

    .venv/bin/python -m benchmarks.run_all --quick     # what `make bench` runs: every benchmark, small
    .venv/bin/python -m benchmarks.run_all             # the full sizes (an hour or more on two cores)
    .venv/bin/python -m benchmarks.run_all --only bench_real,bench_perception --json out/bench

| benchmark | measures | quick | full |
|---|---|---|---|
| bench_real | perception + grounding on the real frames of ../shared/data/real (the arbiter) | 3 frames a folder | every frame |
| bench_creases | the crease cut's h-maxima against scikit-image's on the real frames: ms and same cells | 3 frames a folder | every frame |
| bench_frame_size | the real frames at twice their size, read at perception's working size, against the frames as they are | 2 frames a folder | 8 |
| bench_mirror | the real frames mirrored left to right against the frames as they are (frames perception has not seen) | 2 frames a folder | every frame |
| bench_perception | perception on rendered scenes, every noise preset | 2 scenes a class, 2 presets | 5 a class |
| bench_curved | cylinders, cones and spheres as faces of their kind; boxes without curved faces (rendered) | 3 scenes a class | 10 a class |
| bench_grounding | refinement error, fact calibration, ms per frame | 2 scenes a class, 1 speed run | 6 a class |
| bench_dataset | renderer throughput (images/s) | 8 images | 42 |
| bench_learner | learner accuracy, clean against realsense, and speed | 8 scenes a class | 30 a class |
| bench_pipeline_accuracy | per-class accuracy of each modality on bench_learner's DEV sets | rgbd, 2 folds | 3 modalities |
| bench_baselines | CNN and decision tree: accuracy and seconds per training | one fold, cnn-rgbd (3 epochs) and tree-rgbd | 5 systems |
| bench_tuning | what tuning the CNN baseline costs (seconds per grid setting and per search) | 2 settings of 3 epochs, 2 inner folds | the study's grid |
| bench_metagol | lv3d mil against Metagol on Metagol's example files (../shared/reference/metagol) | the quick files, 10 s | every file, 60 s |

Each runs as ``python -m benchmarks.NAME`` in a process of its own, from the repository root; rendered data
and DEV sets go under ``--work`` (default out/bench) and are reused by the next run. Exit status: 0 when
every benchmark ran, else that of the first that failed. Without real frames under ../shared/data/real,
bench_real, bench_creases, bench_frame_size and bench_mirror are skipped with a message.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REAL = ROOT.parent / "shared" / "data" / "real"
REAL_FRAMES = ("bench_real", "bench_creases", "bench_frame_size", "bench_mirror")  # these read ../shared/data/real
LEARNER_SEED = 778  # bench_learner's default DEV seed: bench_pipeline_accuracy reads the sets it made


def commands(quick: bool, work: Path, json_dir: Path | None) -> list[tuple[str, list[str]]]:
    """(name, arguments) of each benchmark, in the order they run."""
    dev = work / "dev"
    per_class = 8 if quick else 30
    real = (["--limit", "3"] if quick else []) + (["--json", str(json_dir / "bench_real.json")] if json_dir else [])
    return [
        ("bench_real", real),
        ("bench_creases", ["--limit", "3"] if quick else []),
        ("bench_frame_size", ["--limit", "2"] if quick else []),
        ("bench_mirror", ["--limit", "2"] if quick else []),
        ("bench_perception", ["--quick"] if quick else ["--per-class", "5"]),
        ("bench_curved", ["--quick"] if quick else []),
        ("bench_grounding", ["--quick", "--speed-runs", "1", "--speed-frames", "4"] if quick else []),
        ("bench_dataset", ["--images", "8", "--single", "4"] if quick else []),
        ("bench_learner", ["--root", str(dev), "--per-class", str(per_class), "--seed", str(LEARNER_SEED)]
         + (["--quick", "--positives", "4"] if quick else [])),
        ("bench_pipeline_accuracy", [str(dev / f"clean{LEARNER_SEED}"), str(dev / f"realsense{LEARNER_SEED}")]
         + (["--modalities", "rgbd", "--folds", "2", "--positives", "4"] if quick else ["--modalities", "rgbd"])),
        ("bench_baselines", ["--data", str(work / "baselines_data")]
         + (["--systems", "cnn-rgbd,tree-rgbd", "--folds", "1", "--epochs", "3"] if quick else [])),
        ("bench_tuning", ["--data", str(work / "tuning_data")] + (["--quick"] if quick else [])),
        ("bench_metagol", (["--quick"] if quick else []) + (["--json", str(json_dir / "bench_metagol.json")] if json_dir else [])),
    ]


def has_real_frames() -> bool:
    return REAL.is_dir() and any((p / "objects.csv").is_file() for p in REAL.iterdir())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="every benchmark at a small size (a smoke test)")
    ap.add_argument("--only", default="", metavar="B1,B2", help="run only these benchmarks")
    ap.add_argument("--work", type=Path, default=ROOT / "out" / "bench", help="rendered data and DEV sets")
    ap.add_argument("--json", type=Path, metavar="DIR", help="write bench_real's figures to DIR/bench_real.json")
    args = ap.parse_args(argv)
    todo = commands(args.quick, args.work, args.json)
    if args.only:
        wanted = [w.strip() for w in args.only.split(",") if w.strip()]
        unknown = sorted(set(wanted) - {name for name, _ in todo})
        if unknown:
            ap.error(f"--only: unknown benchmark(s) {', '.join(unknown)}; known: {', '.join(n for n, _ in todo)}")
        todo = [(name, argv_) for name, argv_ in todo if name in wanted]
    status = 0
    for name, extra in todo:
        if name in REAL_FRAMES and not has_real_frames():
            print(f"run_all: no real frames with objects.csv under {REAL}: {name} skipped", flush=True)
            continue
        cmd = [sys.executable, "-m", f"benchmarks.{name}", *extra]
        print(f"\n######## {name}: python -m benchmarks.{name} {' '.join(extra)}", flush=True)
        t = time.perf_counter()
        rc = subprocess.run(cmd, cwd=ROOT).returncode
        print(f"######## {name}: exit {rc}, {time.perf_counter() - t:.0f} s", flush=True)
        status = status or rc
    return status


if __name__ == "__main__":
    sys.exit(main())
