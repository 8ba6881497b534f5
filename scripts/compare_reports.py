"""How far one study's report moved between two runs: per (condition, system, task), the mean accuracy over folds
in each results.csv and the change, for the systems both hold; then, per system, how many cells moved and the mean
change. Used after a change to lv3d's code, to say which figures of the committed reports the rerun moved.

    .venv/bin/python scripts/compare_reports.py experiments/results/seed_protocol/results.csv \\
        runs/rerun/seed_protocol/results.csv
    .venv/bin/python scripts/compare_reports.py OLD.csv NEW.csv --systems lv3d-rgbd --all   # every cell, moved or not

Accuracies are printed in percent; a cell "moved" when its mean differs by more than 1e-9.
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import defaultdict
from pathlib import Path

KEY = ("condition", "system", "task")


def cell_means(path: Path) -> dict[tuple[str, str, str], float]:
    """Mean accuracy over folds per (condition, system, task) of a study's results.csv."""
    try:
        with path.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise SystemExit(f"{path}: cannot read ({exc.strerror})")
    if not rows or any(k not in rows[0] for k in KEY + ("accuracy",)):
        raise SystemExit(f"{path}: not a study's results.csv (needs the columns {', '.join(KEY)}, accuracy)")
    acc: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for line, row in enumerate(rows, start=2):
        try:
            acc[tuple(row[k] for k in KEY)].append(float(row["accuracy"]))
        except ValueError:
            raise SystemExit(f"{path}:{line}: accuracy {row['accuracy']!r} is not a number")
    return {k: sum(v) / len(v) for k, v in acc.items()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old", type=Path, help="results.csv of the earlier run")
    ap.add_argument("new", type=Path, help="results.csv of the later run")
    ap.add_argument("--systems", help="comma-separated systems to compare (default: every system both hold)")
    ap.add_argument("--all", action="store_true", help="print every cell, not only those that moved")
    args = ap.parse_args(argv)
    old, new = cell_means(args.old), cell_means(args.new)
    wanted = set(args.systems.split(",")) if args.systems else None
    common = sorted(k for k in old.keys() & new.keys() if wanted is None or k[1] in wanted)
    if not common:
        print("no (condition, system, task) cell in both reports", file=sys.stderr)
        return 1
    moved: dict[str, list[float]] = defaultdict(list)
    print(f"{'condition':<28} {'system':<14} {'task':<22} {'old':>6} {'new':>6} {'change':>7}")
    for k in common:
        d = 100 * (new[k] - old[k])
        moved[k[1]].append(d)
        if args.all or abs(d) > 1e-7:
            print(f"{k[0]:<28} {k[1]:<14} {k[2]:<22} {100 * old[k]:6.1f} {100 * new[k]:6.1f} {d:+7.2f}")
    print()
    for system, ds in sorted(moved.items()):
        n = sum(abs(d) > 1e-7 for d in ds)
        print(f"{system}: {n} of {len(ds)} cells moved, mean change {sum(ds) / len(ds):+.2f} points")
    only = sorted({k[1] for k in (old.keys() ^ new.keys()) if wanted is None or k[1] in wanted})
    if only:
        print(f"in one report only: {', '.join(only)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
