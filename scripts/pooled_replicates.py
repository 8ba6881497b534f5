"""Pool paired lv3d-rgbd − lv3d-depth (or any two systems) differences over replicate runs of one study.

    .venv/bin/python scripts/pooled_replicates.py experiments/results/seed_protocol runs/seed_protocol_seed1 \
        runs/seed_protocol_seed2 [--a lv3d-rgbd --b lv3d-depth]

Each argument is a run folder (or a results folder) holding results.csv. Per condition, the binary accuracy of every
(replicate, fold, class) cell of system a minus that of system b: the mean, a 95% bootstrap interval (cells
resampled 10000 times, seed 0), wins / losses / ties and the two-sided sign and Wilcoxon signed-rank tests, as the
runner's report gives them for one run (lv3d/experiment/stats.py). Where the runs hold multi-class rows, each of the
two systems' multi-class accuracy too, the mean over every (replicate, fold) cell with its 95% bootstrap interval
(the same resampling): how far a multi-class figure moves with the images drawn."""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict
from pathlib import Path

from lv3d.experiment.stats import mean_diff_ci, paired


def accuracies(run: Path) -> dict[tuple[str, str, str, str], float]:
    """{(system, condition, fold, task): binary accuracy} of every row of one run's results.csv."""
    path = run / "results.csv"
    if not path.is_file():
        raise SystemExit(f"{run}: no results.csv (run `lv3d experiment run` into it first)")
    with path.open() as f:
        return {(r["system"], r["condition"], r["fold"], r["task"]): float(r["accuracy"]) for r in csv.DictReader(f)}


def cells(acc: dict, system: str, multiclass: bool = False) -> dict:
    """{(condition, fold, task): binary accuracy} of one system among a run's :func:`accuracies`: its class tasks,
    or with ``multiclass`` its multi-class rows."""
    return {key[1:]: v for key, v in acc.items() if key[0] == system and (key[3] == "multiclass") == multiclass}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", type=Path, nargs="+")
    ap.add_argument("--a", default="lv3d-rgbd")
    ap.add_argument("--b", default="lv3d-depth")
    args = ap.parse_args(argv)
    runs = [(run, accuracies(run)) for run in args.runs]  # each results.csv read once
    pairs = defaultdict(lambda: ([], []))
    for run, acc in runs:
        a, b = cells(acc, args.a), cells(acc, args.b)
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
    for system in (args.a, args.b):
        multi = defaultdict(list)
        for _, acc in runs:
            for (cond, _, _), v in sorted(cells(acc, system, multiclass=True).items()):
                multi[cond].append(100 * v)
        for cond, v in sorted(multi.items()):
            lo, hi = mean_diff_ci(v, [0.0] * len(v))
            print(f"{cond}: {system} multi-class over {len(v)} cells of {len(args.runs)} runs: "
                  f"{sum(v) / len(v):.1f} % (95% interval {lo:.1f} to {hi:.1f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
