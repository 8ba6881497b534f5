"""Two runs of bench_real object by object: is a change in a figure more than perception's chance?

    .venv/bin/python -m benchmarks.bench_real --modalities depth --seed 1,2,3 --objects out/before.csv   # one code
    .venv/bin/python -m benchmarks.bench_real --modalities depth --seed 1,2,3 --objects out/after.csv    # the other
    .venv/bin/python -m benchmarks.compare_objects out/before.csv out/after.csv

A figure of bench_real moves by a few hundredths from one perception seed to the next (the RealSense clutter's
boxes and cans are parted differently by each draw of the sample consensus), so two runs' figures side by side
(benchmarks.compare_real) cannot say whether a change of the code moved one. Here the two runs' per-object rows
(``bench_real --objects``: one row per labelled object, modality and seed, with each figure's verdict) are paired
by folder, frame, object, modality and seed, and for each figure and modality both runs measured:

- *n*: the objects (times seeds) both runs count in the figure, and its value in each run over them;
- *better* / *worse*: the objects (times seeds) whose verdict went towards / away from the figure's target
  (cylinder read in B and not in A is better; a box with a curved face in B and not in A is worse);
- *frames + / -*: the frames where more verdicts went better than worse, and the other way;
- *p*: the exact two-sided sign test over those frames (under no effect of the change a frame is as likely to
  change one way as the other). The frame is the unit: objects of one frame, and one frame's seeds, are perceived
  together and change together (one can read again at every seed is one piece of evidence, not three);
- *interval*: a 95 % bootstrap interval of the change of the figure (B - A), frames drawn with replacement
  (``--resamples``, seeded by ``--seed``).

Run both with the same ``--seed`` list: seeds other than 0 are out of the calibration maps' sample (their real rows
come from seed 0; docs/grounding.md), and several seeds average the consensus's luck out. The figures compared are
the per-object verdicts of the ``--objects`` file (``labelled_found`` and ``merged_frac`` from its ``found`` and
``merged`` columns); ECE, recall and time are not per-object verdicts and are not here. Exit status 0, or 2 with one
line naming the file when a file is not bench_real's ``--objects`` CSV.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

from benchmarks.bench_real import OBJECT_COLUMNS, TARGETS

KEY = ("folder", "frame", "object", "modality", "seed")
# --objects column -> (the figure bench_real names it by, whether "yes" is the verdict its target wants)
FIGURES = {
    "found": ("labelled_found", True),
    "merged": ("merged_frac", False),
    "box_perpendicular": ("box_perpendicular_frac", True),
    "box_overfaced": ("box_overfaced_frac", False),
    "as_prism": ("cylinder_as_prism_frac", False),
    "cylinder_read": ("cylinder_read_frac", True),
    "box_curved": ("box_curved_frac", False),
    "bowl_curved": ("bowl_curved_frac", True),
    "cylinder_elliptical": ("cylinder_elliptical_frac", True),
    "box_elliptical": ("box_elliptical_frac", False),
}


class BadRows(Exception):
    pass


def read_rows(path: Path) -> dict[tuple, dict]:
    """bench_real's ``--objects`` CSV at ``path`` as {(folder, frame, object, modality, seed): row}."""
    try:
        with Path(path).open(newline="") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames is None or not set(OBJECT_COLUMNS) <= set(reader.fieldnames):
                raise BadRows(f"{path}: not the CSV of bench_real --objects (its header lacks "
                              f"{', '.join(c for c in OBJECT_COLUMNS if c not in (reader.fieldnames or []))})")
            rows = {}
            for row in reader:
                key = tuple(row[k] for k in KEY)
                if key in rows:
                    raise BadRows(f"{path}: line {reader.line_num}: a second row for {'/'.join(key)}")
                rows[key] = row
            return rows
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise BadRows(f"{path}: cannot be read as CSV ({e})") from None


def paired(a: dict[tuple, dict], b: dict[tuple, dict], column: str, modality: str) -> list[tuple[tuple, bool, bool]]:
    """(frame's key, A's verdict is yes, B's is) for every object of ``modality`` both runs count in ``column``'s
    figure (a yes/no verdict in both), in a's order."""
    out = []
    for key, ra in a.items():
        rb = b.get(key)
        if key[3] != modality or rb is None or ra[column] not in ("yes", "no") or rb[column] not in ("yes", "no"):
            continue
        out.append(((key[0], key[1]), ra[column] == "yes", rb[column] == "yes"))
    return out


def compare(pairs: list[tuple[tuple, bool, bool]], want_yes: bool, resamples: int, seed: int) -> dict:
    """The figure in each run over ``pairs`` (its share of yes), the objects whose verdict went better and worse
    (towards ``want_yes`` and away from it), the sign test's p and the frame bootstrap's 95 % interval of B - A."""
    yes_a = np.array([ya for _, ya, _ in pairs], bool)
    yes_b = np.array([yb for _, _, yb in pairs], bool)
    good_a, good_b = yes_a == want_yes, yes_b == want_yes
    n = len(pairs)
    better, worse = int(np.count_nonzero(good_b & ~good_a)), int(np.count_nonzero(good_a & ~good_b))
    frames = sorted({f for f, _, _ in pairs})
    index = {f: i for i, f in enumerate(frames)}
    of = np.array([index[f] for f, _, _ in pairs])
    net = np.bincount(of, weights=good_b.astype(float) - good_a.astype(float), minlength=len(frames))
    up, down = int(np.count_nonzero(net > 0)), int(np.count_nonzero(net < 0))
    p = binomtest(min(up, down), up + down, 0.5).pvalue if up + down else 1.0
    # per frame: objects counted, and the figure's yes in A and in B
    count = np.bincount(of, minlength=len(frames))
    frame_a = np.bincount(of, weights=yes_a, minlength=len(frames))
    frame_b = np.bincount(of, weights=yes_b, minlength=len(frames))
    rng = np.random.default_rng(seed)
    draws = rng.integers(0, len(frames), size=(resamples, len(frames)))
    w = np.apply_along_axis(np.bincount, 1, draws, minlength=len(frames))  # (resamples, frames): times drawn
    diff = (w @ frame_b - w @ frame_a) / np.maximum(w @ count, 1)
    lo, hi = np.percentile(diff, [2.5, 97.5])
    return {"n": n, "a": float(np.mean(yes_a)), "b": float(np.mean(yes_b)), "better": better, "worse": worse,
            "frames_up": up,
            "frames_down": down, "p": float(p), "interval": (float(lo), float(hi)), "frames": len(frames)}


def table(a: dict, b: dict, resamples: int, seed: int) -> list[str]:
    modalities = sorted({k[3] for k in a} & {k[3] for k in b})
    lines = [f"{'figure':26} {'modality':9} {'n':>5} {'A':>7} {'B':>7} {'B - A':>7}  {'95% interval':>17}"
             f" {'better':>6} {'worse':>5} {'frames + / -':>12} {'p':>7}  target"]
    for column, (figure, want_yes) in FIGURES.items():
        for m in modalities:
            pairs = paired(a, b, column, m)
            if not pairs:
                continue
            c = compare(pairs, want_yes, resamples, seed)
            t = TARGETS.get(figure)
            target = "-" if t is None else f"{t[0]} {t[1]:g}"
            lo, hi = c["interval"]
            moved = f"{c['frames_up']} / {c['frames_down']}"
            lines.append(f"{figure:26} {m:9} {c['n']:>5} {c['a']:>7.3f} {c['b']:>7.3f} {c['b'] - c['a']:>+7.3f}  "
                         f"{f'{lo:+.3f} to {hi:+.3f}':>17} {c['better']:>6} {c['worse']:>5} "
                         f"{moved:>12} {c['p']:>7.3g}  {target}")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="compare_objects.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", type=Path, help="bench_real --objects of one run (A)")
    ap.add_argument("b", type=Path, help="bench_real --objects of the other (B)")
    ap.add_argument("--resamples", type=int, default=2000, help="bootstrap draws of frames (default 2000)")
    ap.add_argument("--seed", type=int, default=0, help="the bootstrap's seed (default 0)")
    args = ap.parse_args(argv)
    if args.resamples < 100:
        ap.error("--resamples: at least 100")
    try:
        a, b = read_rows(args.a), read_rows(args.b)
    except BadRows as e:
        print(f"compare_objects.py: error: {e}", file=sys.stderr)
        return 2
    common = len(a.keys() & b.keys())
    print(f"== A {args.a} ({len(a)} rows), B {args.b} ({len(b)} rows): {common} rows in both")
    if not common:
        print("no object, modality and seed in both runs: run bench_real with the same folders, modalities and --seed")
        return 0
    print("\n".join(table(a, b, args.resamples, args.seed)))
    print("better / worse: objects (times seeds) whose verdict went towards / away from the target; frames + / -: "
          "frames where more went one way than the other; p: exact sign test over those frames; interval: frames "
          "resampled")
    return 0


if __name__ == "__main__":
    sys.exit(main())
