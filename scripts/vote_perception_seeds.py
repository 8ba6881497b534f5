"""How much of perception's luck a vote over perception seeds takes out: the answers of one study run on several
perception seeds (``--set lv3d.perception_seed=S``), per seed and as the answer most seeds give.

    .venv/bin/python scripts/vote_perception_seeds.py runs/real_objects runs/real_objects_pseed1 \
        runs/real_objects_pseed2 [--systems lv3d-depth,lv3d-rgbd]

Each argument is a study's run folder (``lv3d experiment run --out``; the fold files under ``folds/``, which
results folders do not keep); the runs must share the study seed, so that every (condition, system, fold, task,
draw) was trained on the same objects and tested on the same ones. Each seed's models are those that seed's
facts taught; the vote is the answer most of them give to a test object (a class task: "yes" where most say yes;
the multi-class task: the class most name, ties to the larger summed confidence), a bagging of perception's
sample consensus that costs one perception and one learning per seed. Printed per condition and system: the mean
binary accuracy over the class tasks (as the reports' *mean* column: each (fold, task) the mean over its draws)
and the multi-class accuracy, for each seed, their mean, and the vote.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np


def fold_files(run: Path) -> dict[tuple[str, str, str], dict]:
    """{(condition, system, fold file name): the fold record} of one run folder."""
    folds = run / "folds"
    if not folds.is_dir():
        raise SystemExit(f"{run}: no folds/ (a run folder of `lv3d experiment run --out` holds them)")
    return {(p.parent.parent.name, p.parent.name, p.name): json.loads(p.read_text()) for p in folds.glob("*/*/fold*.json")}


def accuracy(truth: dict[str, str], answers: dict[str, str], task: str) -> float:
    """Binary accuracy of a class task (``task`` a class) or the multi-class accuracy (``task`` "multiclass")."""
    if task == "multiclass":
        return float(np.mean([answers[i] == truth[i] for i in answers]))
    return float(np.mean([(answers[i] == task) == (truth[i] == task) for i in answers]))


def vote(per_seed: list[dict[str, tuple[str, float]]], task: str) -> dict[str, str]:
    """The answer most seeds give to each test object (``per_seed``: {object: (answer, confidence)} per seed)."""
    out = {}
    for i in per_seed[0]:
        answers = [d[i] for d in per_seed]
        if task != "multiclass":
            yes = sum(a == task for a, _ in answers)
            out[i] = task if 2 * yes > len(answers) else "no"
            continue
        count, conf = Counter(), Counter()
        for a, c in answers:
            if a != "unknown":
                count[a] += 1
                conf[a] += c
        out[i] = max(count, key=lambda a: (count[a], conf[a])) if count else "unknown"
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", type=Path, nargs="+", help="run folders of one study, one perception seed each")
    ap.add_argument("--systems", default="lv3d-depth,lv3d-rgbd", help="the lv3d systems to vote (comma-separated)")
    args = ap.parse_args(argv)
    if len(args.runs) < 3:
        ap.error("a vote needs at least three runs")
    systems = [s.strip() for s in args.systems.split(",") if s.strip()]
    runs = [fold_files(r) for r in args.runs]
    keys = sorted(k for k in runs[0] if k[1] in systems and all(k in r for r in runs[1:]))
    if not keys:
        raise SystemExit(f"no fold file of {', '.join(systems)} in every run")
    # (condition, system) -> kind -> [accuracy per (fold, task) cell], kind: seed index, "vote"
    cells: dict = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))
    for key in keys:
        recs = [r[key] for r in runs]
        if any(rec["test_ids"] != recs[0]["test_ids"] for rec in recs):
            raise SystemExit(f"{'/'.join(key)}: the runs tested different objects (another study seed?)")
        truth = dict(zip(recs[0]["test_ids"], recs[0]["test_classes"]))
        for task, draws in recs[0]["predictions"].items():
            for d in range(len(draws)):
                per_seed = [{i: (a, c) for i, a, c in rec["predictions"][task][d]} for rec in recs]
                kind = "multi" if task == "multiclass" else "class"
                for s, answers in enumerate(per_seed):
                    cells[key[:2]][kind][s].append(((key[2], task), accuracy(truth, {i: a for i, (a, _) in answers.items()}, task)))
                cells[key[:2]][kind]["vote"].append(((key[2], task), accuracy(truth, vote(per_seed, task), task)))

    def mean_of_cells(rows) -> float:  # each (fold, task) cell the mean over its draws, then the mean of the cells
        by = defaultdict(list)
        for cell, a in rows:
            by[cell].append(a)
        return 100 * float(np.mean([np.mean(v) for v in by.values()]))

    n = len(args.runs)
    print(f"mean binary accuracy over the class tasks / multi-class accuracy, %, over {n} perception seeds")
    for s, r in enumerate(args.runs):
        print(f"  run {s}: {r}")
    for (cond, system), kinds in sorted(cells.items()):
        seeds = [(mean_of_cells(kinds["class"][s]), mean_of_cells(kinds["multi"][s])) for s in range(n)]
        mean = tuple(float(np.mean([x[j] for x in seeds])) for j in range(2))
        v = (mean_of_cells(kinds["class"]["vote"]), mean_of_cells(kinds["multi"]["vote"]))
        print(f"{cond:14s} {system:11s} " + "  ".join(f"run {s}: {a:.1f} / {b:.1f}" for s, (a, b) in
                                                      zip(range(n), seeds))
              + f"  mean {mean[0]:.1f} / {mean[1]:.1f}  vote {v[0]:.1f} / {v[1]:.1f}"
              + f"  (vote - mean {v[0] - mean[0]:+.1f} / {v[1] - mean[1]:+.1f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
