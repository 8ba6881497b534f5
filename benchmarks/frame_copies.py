"""What bench_frame_size and bench_mirror share: the labels of a real-layout folder's copy whose frames were
moved pixel by pixel (enlarged, mirrored), with each labelled pixel moved as its frame was."""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path


def copy_objects(folder: Path, out: Path, frames: list[str], move: Callable[[str, int, int], tuple[int, int]]) -> None:
    """``folder``'s objects.csv written to ``out`` with the rows of ``frames`` only, each labelled pixel (u, v) of
    frame ``name`` moved to ``move(name, u, v)``; every other column as it was."""
    rows = list(csv.reader((folder / "objects.csv").read_text(encoding="utf-8-sig").splitlines()))
    header = [c.strip() for c in rows[0]]
    iu, iv, iframe = header.index("u"), header.index("v"), header.index("frame")
    with (out / "objects.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(rows[0])
        for cells in rows[1:]:
            name = cells[iframe].strip() if len(cells) > max(iu, iv, iframe) else None
            if name in frames:
                cells[iu], cells[iv] = map(str, move(name, int(cells[iu]), int(cells[iv])))
                w.writerow(cells)
