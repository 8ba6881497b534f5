"""The seeds of the cut at creases: lv3d's h-maxima (perception/depth/creases.py) against scikit-image's.

    .venv/bin/python -m benchmarks.bench_creases                     # every frame of the real dev folders
    .venv/bin/python -m benchmarks.bench_creases ../shared/data/real/osd-learn --limit 5

Perceives every frame of each folder (depth, seed 0) and keeps the distance maps and heights the crease cut asks
the h-maxima of (``creases.h_maxima``: one call per object the cut looks at), then times both functions on
each of them (CPU time, one core, ``--repeats`` rounds) and checks that they mark the same cells. Prints per
folder the calls, ms per call and ms per frame of each. Where the real frames are absent it says so and exits 0.
"""

from __future__ import annotations

if __name__ == "__main__":  # one core, as bench_real
    import os

    for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
        os.environ[_var] = "1"
    os.environ.setdefault("JAX_PLATFORMS", "cpu")

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.bench_real import _one_core, named_folders, labelled_folder
from lv3d.errors import InputError


def crease_maps(folder: Path, limit: int | None) -> tuple[list[tuple[np.ndarray, float]], int]:
    """The (distance map, height h) of every h-maxima call of the crease cut on the folder's frames (the first
    ``limit``), and the number of frames perceived."""
    from lv3d.perception import perceive
    from lv3d.perception.depth import creases

    ff = labelled_folder(folder)
    frames = ff.frames[:limit] if limit else ff.frames
    calls: list[tuple[np.ndarray, float]] = []
    own = creases.h_maxima

    def keep(image, h):
        calls.append((np.array(image, copy=True), h))
        return own(image, h)

    creases.h_maxima = keep
    try:
        for name in frames:
            perceive(ff.load(name), "depth", scene_id="s000000", seed=0)
    finally:
        creases.h_maxima = own
    return calls, len(frames)


def timed(fn, calls: list[tuple[np.ndarray, float]], repeats: int) -> tuple[float, list[np.ndarray]]:
    """CPU seconds of ``fn`` over every call, the least of ``repeats`` rounds, and its answers."""
    best, out = float("inf"), []
    for _ in range(repeats):
        t = time.process_time()
        out = [fn(image, h) for image, h in calls]
        best = min(best, time.process_time() - t)
    return best, out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="bench_creases.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="*", type=Path,
                    help="folders in the real layout, or a folder of them (default: the dev folders)")
    ap.add_argument("--limit", type=int, metavar="N", help="only the first N frames of each folder")
    ap.add_argument("--repeats", type=int, default=3, help="rounds of timing; the least counts (default 3)")
    args = ap.parse_args(argv)
    if (args.limit is not None and args.limit < 1) or args.repeats < 1:
        ap.error("--limit and --repeats must be at least 1")
    from skimage.morphology import h_maxima as skimage_h_maxima

    from lv3d.perception.depth.creases import h_maxima

    _one_core()  # OpenCV's dilation, as perception's other calls, on one thread
    folders = named_folders(args.folders)
    if not folders:
        print("bench_creases.py: no real frames with objects.csv (../shared/data/real): nothing to time")
        return 0
    status = 0
    for folder in folders:
        try:
            calls, frames = crease_maps(folder, args.limit)
        except InputError as e:
            print(f"bench_creases.py: error: {e}", file=sys.stderr)
            return 2
        if not calls:
            print(f"{folder.name}: {frames} frames, the crease cut asked no h-maxima")
            continue
        t_lib, want = timed(skimage_h_maxima, calls, args.repeats)
        t_own, got = timed(h_maxima, calls, args.repeats)
        same = sum(np.array_equal(a, b) for a, b in zip(want, got))
        status = status or int(same != len(calls))
        n = len(calls)
        print(f"{folder.name}: {n} calls over {frames} frames (maps of {int(np.median([c[0].size for c in calls]))} "
              f"cells, median); skimage.morphology.h_maxima {1e3 * t_lib / n:.1f} ms a call, "
              f"{1e3 * t_lib / frames:.1f} ms a frame; creases.h_maxima {1e3 * t_own / n:.1f} ms a call, "
              f"{1e3 * t_own / frames:.1f} ms a frame; same cells in {same} of {n}")
    return status


if __name__ == "__main__":
    sys.exit(main())
