"""Pool paired lv3d-rgbd − lv3d-depth (or any two systems) differences over replicate runs of one study.

    .venv/bin/python scripts/pooled_replicates.py experiments/results/seed_protocol runs/seed_protocol_seed1 \
        runs/seed_protocol_seed2 [--a lv3d-rgbd --b lv3d-depth]

Each argument is a run folder (or a results folder) holding results.csv. Per condition, the binary accuracy of every
(replicate, fold, class) cell of system a minus that of system b: the mean, a 95% bootstrap interval (cells
resampled 10000 times, seed 0), wins / losses / ties and the two-sided sign and Wilcoxon signed-rank tests, as the
runner's report gives them for one run (lv3d/experiment/stats.py)."""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict
from pathlib import Path

from lv3d.experiment.stats import paired


def cells(run: Path, system: str) -> dict:
    """{(condition, fold, task): binary accuracy} of one system in one run's results.csv (class tasks only)."""
    path = run / "results.csv"
    if not path.is_file():
        raise SystemExit(f"{run}: no results.csv (run `lv3d experiment run` into it first)")
    out = {}
    with path.open() as f:
        for r in csv.DictReader(f):
            if r["system"] == system and r["task"] != "multiclass":
                out[(r["condition"], r["fold"], r["task"])] = float(r["accuracy"])
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", type=Path, nargs="+")
    ap.add_argument("--a", default="lv3d-rgbd")
    ap.add_argument("--b", default="lv3d-depth")
    args = ap.parse_args(argv)
    pairs = defaultdict(lambda: ([], []))
    for run in args.runs:
        a, b = cells(run, args.a), cells(run, args.b)
        if not a or not b:
            raise SystemExit(f"{run}: no class-task rows of {args.a if not a else args.b}")
        for key in sorted(a.keys() & b.keys()):
            pairs[key[0]][0].append(100 * a[key])  # stats rounds the differences
            pairs[key[0]][1].append(100 * b[key])
    for cond, (a, b) in sorted(pairs.items()):
        t = paired(a, b)
        print(f"{cond}: {args.a} - {args.b} over {len(a)} cells of {len(args.runs)} runs: {t['mean_diff']:+.2f} points "
              f"(95% interval {t['ci95'][0]:+.2f} to {t['ci95'][1]:+.2f}), {t['sign']['wins']} wins, "
              f"{t['sign']['losses']} losses, {t['sign']['ties']} ties, sign p = {t['sign']['p']:.3g}, "
              f"Wilcoxon p = {t['wilcoxon']['p']:.3g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
