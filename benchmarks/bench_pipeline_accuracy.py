"""Per-class binary and multi-class accuracy of lv3d on a DEV set, per modality, beside the targets (issue 6).

    .venv/bin/python -m benchmarks.bench_pipeline_accuracy out/bench/dev/clean778 out/bench/dev/realsense778

The DEV sets are those bench_learner makes (``--root R --seed S``: R/clean<S> and R/realsense<S>, with the facts
of its ``--modality``; benchmarks.run_all makes them under out/bench/dev before this runs);
``--make PER_CLASS`` renders a DEV set named <preset><seed> that is not there yet and caches the facts of
every ``--modalities`` a set lacks (bench_learner.make_dev_facts).

The study's protocol on a smaller DEV set (never the study's data): stratified folds, per class task
positives + 1.5 negatives per positive spread over the other classes, a multi-class task, tested on
the held-out fold; the figure is the mean over folds. ``--facts truth`` learns from ground-truth facts
instead (the learner's ceiling). ``--explain`` prints the programs learned and the misclassified scenes.
"""

from __future__ import annotations

import argparse
import json
import pickle
import re
from pathlib import Path

import numpy as np

from benchmarks.bench_learner import make_dev_facts

from lv3d import compile_cache
from lv3d.experiment.folds import Item, class_task, multiclass_task, split, stratified_folds
from lv3d.experiment.runner import score_binary
from lv3d.experiment.systems import LogicSystem, negative_label

TARGETS = {"clean": 0.95, "realsense": 0.85}


def evaluate(data: dict, folds: int, positives: int, seed: int, settings: dict, explain: bool) -> dict:
    """{task: [accuracy per fold]} for the scenes ``data`` (id -> (label, SceneFacts))."""
    items = [Item(i, y, i) for i, (y, _) in sorted(data.items())]
    facts = {i: f for i, (_, f) in data.items()}
    classes = sorted({it.cls for it in items})
    system = LogicSystem("lv3d", facts, settings)
    out: dict = {}
    for k, fold in enumerate(stratified_folds(items, folds, seed)):
        train, test = split(stratified_folds(items, folds, seed), k)
        ids = [it.id for it in test]
        for j, cls in enumerate(classes):
            ex, positive = class_task(train, cls, positives, 1.5, seed + 10 * k + j)
            fitted = system.fit([it.id for it in ex], [cls if p else negative_label(cls) for p in positive],
                                seed, positive=cls)
            preds = fitted.predict(ids)
            out.setdefault(cls, []).append(score_binary(preds, test, cls)["accuracy"])
            if explain:
                prog = fitted.model.programs.get(cls)
                print(f"  fold {k} {cls}: " + (" | ".join(prog.clauses).replace("\n", " ") if prog else
                                               f"no program {fitted.model.failures}"), prog.score if prog else "")
                for (lab, conf), it in zip(preds, test):
                    if (lab == cls) != (it.cls == cls):
                        print(f"     wrong {it.id} {it.cls} -> {lab} {conf:.2f}")
        ex = multiclass_task(train, positives, seed + 10 * k + 9)
        fitted = system.fit([it.id for it in ex], [it.cls for it in ex], seed)
        preds = fitted.predict(ids)
        out.setdefault("multiclass", []).append(float(np.mean([p == it.cls for (p, _), it in zip(preds, test)])))
    return out


def main() -> None:
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    ap = argparse.ArgumentParser()
    ap.add_argument("dev", nargs="+", type=Path,
                    help="DEV data sets bench_learner made (<root>/<preset><seed>, e.g. out/bench/dev/clean778)")
    ap.add_argument("--make", type=int, metavar="PER_CLASS",
                    help="make what a DEV set lacks: render it (PER_CLASS images a class, preset and seed from its "
                         "name) and cache the facts of --modalities")
    ap.add_argument("--modalities", default="rgbd,depth,rgb")
    ap.add_argument("--facts", choices=("pipeline", "truth"), default="pipeline")
    ap.add_argument("--folds", type=int, default=3)
    ap.add_argument("--positives", type=int, default=20)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--explain", action="store_true")
    ap.add_argument("--set", action="append", default=[], help="learner setting name=value (Python literal)")
    a = ap.parse_args()
    import ast
    settings = {k: ast.literal_eval(v) for k, v in (s.split("=", 1) for s in a.set)}
    mods = a.modalities.split(",")
    for dev in a.dev:
        lacking = [m for m in mods if not (dev / f"facts_{m}.pkl").is_file()]
        if lacking and a.make is None:
            ap.error(f"{dev}: no facts of {', '.join(lacking)} (make them with bench_learner, or --make PER_CLASS)")
        if lacking:
            named = re.fullmatch(r"([a-z]+)(\d+)", dev.name)
            if named is None:
                ap.error(f"{dev}: --make needs a DEV set named <preset><seed>, e.g. clean778")
            make_dev_facts(dev, named[1], int(named[2]), a.make, lacking)
    for dev in a.dev:
        preset = json.loads((dev / "manifest.json").read_text())["noise"]  # the preset the DEV set was rendered with
        target = TARGETS.get(preset)
        goal = f"rgbd mean >= {target:.2f}, " if target is not None else ""
        print(f"== {dev} ({preset}; facts: {a.facts}; target {goal}rgbd >= rgb, depth)")
        rows = {}
        for mod in mods:
            raw = pickle.loads((dev / f"facts_{mod}.pkl").read_bytes())
            col = 1 if a.facts == "pipeline" else 2
            data = {i: (v[0], v[col]) for i, v in raw.items() if v[col] is not None}
            if a.explain:
                print(f" -- {mod}")
            rows[mod] = evaluate(data, a.folds, a.positives, a.seed, settings, a.explain)
        tasks = list(next(iter(rows.values())))
        print(f"{'modality':9s}" + "".join(f"{t[:16]:>18s}" for t in tasks) + f"{'mean':>8s}")
        for mod, r in rows.items():
            means = [float(np.mean(r[t])) for t in tasks]
            flag = "" if mod != "rgbd" or target is None else \
                ("  ok" if np.mean(means) >= target else f"  < target {target}")
            print(f"{mod:9s}" + "".join(f"{m:10.3f} [{min(r[t]):.2f}-{max(r[t]):.2f}]" for m, t in zip(means, tasks))
                  + f"{np.mean(means):8.3f}{flag}")


if __name__ == "__main__":
    main()
