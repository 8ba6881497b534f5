"""A real folder and the same frames mirrored left to right, through bench_real, side by side.

    .venv/bin/python -m benchmarks.bench_mirror                                  # osd-learn and ycb-realsense
    .venv/bin/python -m benchmarks.bench_mirror --modalities rgbd --seed 0,1,2   # pooled over perception seeds
    .venv/bin/python -m benchmarks.bench_mirror ../shared/data/real/ycb-realsense --limit 5
    .venv/bin/python -m benchmarks.bench_mirror --flip both                      # upside down: a camera turned over

The figures of bench_real are measured on the dev frames, and the same code is judged on frames it was never
shown. A mirrored frame is such a frame with nothing else changed: the same scene, sensor, noise and labels,
seen as in a mirror (an object's left is its right), so every quantity perception measures has its mirror
twin, and a figure that holds on the frames and not on their mirror images holds by luck of the frames (which
way a sample consensus or a scan order happens to break a tie), not by what perception reads. The colour,
depth and label images of each folder's first ``--limit`` frames (all by default) are flipped left to right into
a temporary folder, the principal point and the labelled pixels with them (u -> W - 1 - u), both folders go
through bench_real with the same ``--modalities`` and ``--seed``, and benchmarks.compare_real sets the two runs
side by side, pooled and per folder. ``--flip up-down`` mirrors the frames top to bottom (v -> H - 1 - v)
instead, and ``--flip both`` both ways, which turns them upside down (a camera mounted the other way up): in
either the table faces down in the image, which perception does not take for a support plane (it takes the
camera to be upright), so these measure what a camera turned over costs, not luck.
Exit status: 0, or 2 with one line naming what is wrong.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import cv2

from benchmarks import bench_real, compare_real
from benchmarks.frame_copies import copy_objects
from lv3d.errors import InputError
from lv3d.frame_folder import FrameFolder
from lv3d.rgbd import read_intrinsics


FLIPS = {"left-right": 1, "up-down": 0, "both": -1}  # cv2.flip's codes


def mirror(folder: Path, out: Path, limit: int | None, flip: str = "left-right") -> Path:
    """``folder``'s first ``limit`` frames (natural order; all with None), each flipped as ``flip`` says (a key of
    FLIPS), written to ``out`` in the same layout with the intrinsics and labelled pixels to match; returns
    ``out``."""
    code = FLIPS[flip]
    across, down = code != 0, code != 1  # whether u, v run the other way
    ff = FrameFolder(folder)
    frames = ff.frames[:limit] if limit else ff.frames
    out.mkdir(parents=True)
    intr: dict = {"frames": {}}
    sizes = {}
    for name in frames:
        k, scale = read_intrinsics(folder / "intrinsics.json", name)
        images = [*ff.files[name], folder / f"{name}_label.png"]
        for path in images:
            if path.is_file():
                image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
                if image is None:
                    raise InputError(path, "cannot read the image")
                cv2.imwrite(str(out / path.name), cv2.flip(image, code))
        # pixel u of a row is pixel W - 1 - u of the flipped row (v of a column H - 1 - v): the original camera
        # seen in a mirror, or turned over
        intr["frames"][name] = {"fx": k.fx, "fy": k.fy, "cx": k.width - 1 - k.cx if across else k.cx,
                                "cy": k.height - 1 - k.cy if down else k.cy, "width": k.width,
                                "height": k.height, "depth_scale_m": scale}
        sizes[name] = (k.width, k.height)
    (out / "intrinsics.json").write_text(json.dumps(intr, indent=1))
    copy_objects(folder, out, frames, lambda name, u, v: (sizes[name][0] - 1 - u if across else u,
                                                          sizes[name][1] - 1 - v if down else v))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="bench_mirror.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="*", type=Path,
                    help="folders in the real layout, or a folder of them (default: bench_real's)")
    ap.add_argument("--limit", type=int, metavar="N", help="the first N frames of each folder (default: all)")
    ap.add_argument("--modalities", default="depth,rgbd", help="bench_real's --modalities (default depth,rgbd)")
    ap.add_argument("--seed", default="0", metavar="S[,S...]", help="bench_real's perception seeds (default 0)")
    ap.add_argument("--flip", choices=sorted(FLIPS), default="left-right",
                    help="left-right (a mirror, the default), up-down, or both (the frames upside down)")
    args = ap.parse_args(argv)
    if args.limit is not None and args.limit < 1:
        ap.error("--limit must be at least 1")
    with tempfile.TemporaryDirectory(prefix="lv3d-mirror-") as tmp:
        tmp = Path(tmp)
        try:
            folders = bench_real.folders_to_run(args.folders)
            mirrored = [mirror(f, tmp / f.name, args.limit, args.flip) for f in folders]
        except (InputError, OSError, ValueError) as e:
            print(f"bench_mirror.py: error: {e}", file=sys.stderr)
            return 2
        common = ["--modalities", args.modalities, "--seed", args.seed] + (["--limit", str(args.limit)]
                                                                           if args.limit else [])
        flipped = f"flipped {args.flip}"
        for name, fs, out in (("as they are", folders, tmp / "a.json"), (flipped, mirrored, tmp / "b.json")):
            print(f"#### the frames {name}")
            rc = bench_real.main([str(f) for f in fs] + common + ["--json", str(out)])
            if rc:
                return rc
        print(f"#### A: the frames as they are, B: {flipped}")
        return compare_real.main([str(tmp / "a.json"), str(tmp / "b.json"), "--folders"])


if __name__ == "__main__":
    sys.exit(main())
