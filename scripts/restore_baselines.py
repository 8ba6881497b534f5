"""Restore a study's baseline fold files from its committed ``results.csv``, so that rerunning the study
after a change to lv3d's code retrains only the lv3d systems (the baselines' fold results do not depend
on lv3d's code: ``lv3d/experiment/code_version.py``).

    .venv/bin/python scripts/restore_baselines.py experiments/seed_protocol.yaml \\
        experiments/results/seed_protocol/results.csv --out runs/seed_protocol
    .venv/bin/lv3d experiment run experiments/seed_protocol.yaml --out runs/seed_protocol

Each restored fold file carries the key the runner computes for that system and fold under the
config as it is now (on real frames, with the crops where the current code's rgbd perception puts them: their
facts are computed here, into the study's cache, where they are not there yet), so the runner skips it; it holds
what the report reads (per task: accuracy,
balanced accuracy, test size, seconds; the setting a tuned baseline chose), not the predictions, and says it
was restored. Pass the
same ``--set`` overrides as the run. A config whose conditions, systems or folds do not match the
CSV stops with an error naming both files.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from collections import defaultdict
from pathlib import Path

from lv3d.errors import InputError
from lv3d.experiment.config import LOGIC_SYSTEMS, load_study
from lv3d.experiment.runner import _write_json, fold_path, result_key, study_inputs
from lv3d.output import claim


def read_rows(path: Path) -> tuple[dict[tuple[str, str, int], dict[str, dict]], dict[tuple[str, str, int], dict]]:
    """For the baseline rows of a results.csv: ((condition, system, fold) -> task -> the task's scores,
    (condition, system, fold) -> the setting a tuned baseline chose there, where the CSV says)."""
    if not path.is_file():
        raise InputError(path, "results file not found")
    cells: dict[tuple[str, str, int], dict[str, dict]] = defaultdict(dict)
    tuned: dict[tuple[str, str, int], dict] = {}
    with path.open(newline="") as f:
        for line, row in enumerate(csv.DictReader(f), start=2):
            if row["system"] in LOGIC_SYSTEMS:
                continue
            bal = row["balanced_accuracy"]
            key = (row["condition"], row["system"], int(row["fold"]))
            cells[key][row["task"]] = {
                "accuracy": float(row["accuracy"]), "balanced_accuracy": float(bal) if bal else None,
                "n": int(row["n"]), "seconds": float(row["seconds"])}
            if row.get("tuned"):
                try:
                    tuned[key] = json.loads(row["tuned"])
                except json.JSONDecodeError as e:
                    raise InputError(path, f"line {line}: the tuned column is no JSON ({e})") from None
    return cells, tuned


def restore(config: Path, results: Path, out: Path, overrides: list[str] = ()) -> int:
    """Write the baseline fold files of ``config``'s run into ``out`` from ``results``; returns how many."""
    study = load_study(config, list(overrides))
    cells, tuned = read_rows(results)
    written = 0
    claim(out, (config, results))  # the study's --out: refused unless new, empty or lv3d's own
    for cname, ccfg in study.conditions.items():
        # on real frames a baseline's key holds where its crops lie, as the runner's does
        inputs = study_inputs(ccfg, out, progress=False)[1] if ccfg.data.folders else None
        for s in ccfg.systems:
            if s in LOGIC_SYSTEMS:
                continue
            seen = inputs.seen(s) if inputs is not None else None
            for k in range(ccfg.folds):
                tasks = cells.get((cname, s, k))
                if not tasks:
                    raise InputError(results, f"no rows for condition {cname!r}, system {s!r}, fold {k} of {config}")
                tasks = {t: {n: v for n, v in sc.items() if v is not None} for t, sc in tasks.items()}
                record = {"key": result_key(ccfg, s, k, seen), "condition": cname, "system": s, "fold": k,
                          "tasks": tasks, "seconds": round(sum(sc["seconds"] for sc in tasks.values()), 3), "pipeline_errors": {},
                          "code": None, "restored_from": str(results)}
                if (cname, s, k) in tuned:
                    record["tuned"] = tuned[(cname, s, k)]
                _write_json(fold_path(out, cname, s, k), record)
                written += 1
    return written


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config", type=Path)
    ap.add_argument("results", type=Path, help="the study's committed results.csv")
    ap.add_argument("--out", type=Path, required=True, help="the run folder the study will be run into")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    try:
        n = restore(args.config, args.results, args.out, args.overrides)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"restored {n} baseline fold files into {args.out / 'folds'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
