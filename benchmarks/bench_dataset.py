"""Throughput of the synthetic data set writer: `make_dataset` with the `realsense` preset at 640x480.

Run: .venv/bin/python benchmarks/bench_dataset.py [--images 40] [--workers 2]
Prints images/s with the target beside it (issue 2: >= 20 images/s on 2 cores), and the wall and CPU time
of one render_scene call (no file writing) for reference.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

from lv3d.render import CLASSES, make_dataset, render_scene

TARGET_IMAGES_PER_S = 20.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--images", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    args = ap.parse_args()

    render_scene("cube", 0, "realsense", args.width, args.height)  # warm imports and caches
    t, c = time.perf_counter(), time.process_time()
    n_single = 10
    for s in range(n_single):
        render_scene(CLASSES[s % len(CLASSES)], s, "realsense", args.width, args.height)
    per_render = (time.perf_counter() - t) / n_single
    cpu_render = (time.process_time() - c) / n_single  # CPU time: less sensitive to a busy machine

    per_class = max(1, -(-args.images // len(CLASSES)))  # at least --images in all
    n = per_class * len(CLASSES)
    root = Path(tempfile.mkdtemp(prefix="lv3d-bench-"))
    try:
        t = time.perf_counter()
        make_dataset(root / "ds", CLASSES, per_class, "realsense", seed=0, workers=args.workers,
                     width=args.width, height=args.height, progress=False)
        wall = time.perf_counter() - t
    finally:
        shutil.rmtree(root, ignore_errors=True)
    rate = n / wall
    print(f"render_scene realsense {args.width}x{args.height}, one process: {1000 * per_render:.0f} ms/image wall, "
          f"{1000 * cpu_render:.0f} ms/image CPU (without writing the files)")
    print(f"make_dataset realsense {args.width}x{args.height}, {n} images, {args.workers} workers: "
          f"{wall:.2f} s, {rate:.1f} images/s (target >= {TARGET_IMAGES_PER_S:.0f} images/s on 2 cores) "
          f"{'MET' if rate >= TARGET_IMAGES_PER_S else 'NOT MET'}")


if __name__ == "__main__":
    main()
