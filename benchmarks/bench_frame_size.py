"""A real folder and the same frames at a whole multiple of their size, through bench_real, side by side.

    .venv/bin/python -m benchmarks.bench_frame_size                                   # osd-learn and ycb-realsense
    .venv/bin/python -m benchmarks.bench_frame_size ../shared/data/real/ycb-realsense --factor 3 --limit 5
    .venv/bin/python -m benchmarks.bench_frame_size --full-size      # and the large frames perceived at full size

Perception's settings and the calibration maps are made for frames about 640 px across
(lv3d.rgbd.WORK_SIDE_PX); a camera frame larger than that is read at a whole fraction of its size
(lv3d.rgbd.to_working). This benchmark checks that reading: each folder's first ``--limit`` frames are written
``--factor`` times as large into a temporary folder (depth and label images with every pixel repeated, colour
by bicubic interpolation, the intrinsics and the labelled pixels scaled to match), both folders go through
bench_real (its figures and targets), and benchmarks.compare_real sets the two runs side by side. Depth read
from the large frames is the original depth, reading for reading, so every depth figure should be the
original's and the time about the same; rgbd reads colour low-passed from the interpolated image and may move
by a labelled object or two. ``--full-size`` also runs the large frames at their full size (the working size
lifted in this process): what perception would make of them and what it would cost without the working size.
Exit status: 0, or 2 with one line naming what is wrong.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

from benchmarks import bench_real, compare_real
from benchmarks.frame_copies import copy_objects
from lv3d import rgbd
from lv3d.errors import InputError
from lv3d.frame_folder import FrameFolder
from lv3d.rgbd import read_intrinsics


def enlarge(folder: Path, out: Path, factor: int, limit: int | None) -> Path:
    """``folder``'s first ``limit`` frames (natural order), each ``factor`` times as large, written to ``out`` in
    the same layout; returns ``out``."""
    ff = FrameFolder(folder)
    frames = ff.frames[:limit] if limit else ff.frames
    out.mkdir(parents=True)
    rep = (lambda a: np.repeat(np.repeat(a, factor, axis=0), factor, axis=1))
    intr: dict = {"frames": {}}
    for name in frames:
        c, d = ff.files[name]
        k, scale = read_intrinsics(folder / "intrinsics.json", name)
        color = cv2.imread(str(c), cv2.IMREAD_COLOR)
        h, w = color.shape[:2]
        cv2.imwrite(str(out / f"{name}_rgb.png"), cv2.resize(color, (w * factor, h * factor),
                                                             interpolation=cv2.INTER_CUBIC))
        cv2.imwrite(str(out / f"{name}_depth{d.name.rsplit('_depth', 1)[1]}"), rep(cv2.imread(str(d), cv2.IMREAD_UNCHANGED)))
        label = folder / f"{name}_label.png"
        if label.is_file():
            cv2.imwrite(str(out / label.name), rep(cv2.imread(str(label), cv2.IMREAD_UNCHANGED)))
        # pixel (u, v) of the original is pixel (factor u, factor v) of the large frame, as read back
        intr["frames"][name] = {"fx": k.fx * factor, "fy": k.fy * factor, "cx": k.cx * factor, "cy": k.cy * factor,
                                "width": k.width * factor, "height": k.height * factor, "depth_scale_m": scale}
    (out / "intrinsics.json").write_text(json.dumps(intr, indent=1))
    copy_objects(folder, out, frames, lambda _name, u, v: (u * factor, v * factor))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="bench_frame_size.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="*", type=Path,
                    help="folders in the real layout, or a folder of them (default: bench_real's)")
    ap.add_argument("--factor", type=int, default=2, help="how many times as large (default 2: 1280x960)")
    ap.add_argument("--limit", type=int, default=8, metavar="N", help="the first N frames of each folder (default 8)")
    ap.add_argument("--modalities", default="depth,rgbd", help="bench_real's --modalities (default depth,rgbd)")
    ap.add_argument("--full-size", action="store_true", help="also perceive the large frames at their full size")
    args = ap.parse_args(argv)
    if args.factor < 2:
        ap.error("--factor must be at least 2")
    if args.limit < 1:
        ap.error("--limit must be at least 1")
    with tempfile.TemporaryDirectory(prefix="lv3d-frame-size-") as tmp:
        tmp = Path(tmp)
        try:
            folders = bench_real.folders_to_run(args.folders)
            large = [enlarge(f, tmp / f"{f.name}_x{args.factor}", args.factor, args.limit) for f in folders]
        except (InputError, OSError, ValueError) as e:
            print(f"bench_frame_size.py: error: {e}", file=sys.stderr)
            return 2
        common = ["--limit", str(args.limit), "--modalities", args.modalities]
        # (what the run is, its folders, its JSON, the working size it reads them at)
        runs = [("as they are", folders, tmp / "a.json", rgbd.WORK_SIDE_PX),
                (f"{args.factor} times as large", large, tmp / "b.json", rgbd.WORK_SIDE_PX)]
        if args.full_size:  # a working size no frame exceeds: every frame read at its own size
            runs.append((f"{args.factor} times as large, perceived at full size", large, tmp / "c.json", 10 ** 9))
        for name, fs, out, side in runs:
            print(f"#### the frames {name}")
            kept, rgbd.WORK_SIDE_PX = rgbd.WORK_SIDE_PX, side
            try:
                rc = bench_real.main([str(f) for f in fs] + common + ["--json", str(out)])
            finally:
                rgbd.WORK_SIDE_PX = kept
            if rc:
                return rc
        rc = 0
        for name, _, out, _ in runs[1:]:
            print(f"#### A: the frames as they are, B: {name}")
            rc = rc or compare_real.main([str(tmp / "a.json"), str(out), "--folders"])
        return rc


if __name__ == "__main__":
    sys.exit(main())
