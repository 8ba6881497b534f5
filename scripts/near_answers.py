"""How a study's answers by resemblance would fare under other rules: per condition and lv3d system, the
multi-class answers no program proved (``answered_by`` "near" in the fold files), how many of them each rule for
the class gets right, and the expected calibration error (ECE, 10 bins) of all the multi-class answers with each
confidence for those answers (proofs keep theirs). The models are the study's own (its saved programs and their
training objects' profiles), so the rule in use (``nn`` with ``ratio``, lv3d.learn.resemblance) reproduces the
study's figures exactly; the others answer "what if" without relearning anything.

Rules for the class: ``nn`` the nearest training object's (in use); ``mean2`` the class whose two nearest training
objects lie nearest on average; ``vote3`` the most frequent among the three nearest (ties: the nearer); ``l2``
the nearest by squared differences.
Confidences: ``ratio`` d_o / (d_c + d_o), d_c to the answered class's nearest training object and d_o to another
class's (resemblance.Resemblance.confidence, in use); ``inverse`` (1 / d_c) over the sum of 1 / d_k over every class's nearest;
beside them the ECE of the answers as the fold files hold them (the code the study ran).

    .venv/bin/python scripts/near_answers.py runs/real_objects
    .venv/bin/python scripts/near_answers.py runs/ten_classes --systems lv3d-depth,lv3d-rgbd

RUN_DIR is the study's --out: its config.yaml, fold files (folds/<condition>/<system>/fold<k>.json) and programs
(programs/<condition>/<system>/fold<k>/multiclass[/draw<d>]/). Each example's facts are read as the study reads
them (lv3d.experiment.runner.study_inputs), from the cache of this checkout's facts version; facts the cache lacks
are computed.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path

RULES = ("nn", "mean2", "vote3", "l2")
CONFIDENCES = ("ratio", "inverse")


def _ranked(prof: dict, refs: list) -> list[tuple[float, str, str]]:
    """(distance, class, object) of each training object in ``refs`` to an object of profile ``prof``, nearest
    first (ties as resemblance.nearest breaks them)."""
    from lv3d.learn.resemblance import distance

    return sorted((distance(prof, r.profile), r.label, r.object) for r in refs)


def _rules(ranked: list, prof: dict, refs: list) -> dict[str, str]:
    """The class each rule names for an object of profile ``prof``, ``ranked`` its :func:`_ranked` among ``refs``."""
    per = defaultdict(list)
    for d, label, _ in ranked:
        per[label].append(d)
    top, votes = ranked[:3], defaultdict(int)
    for _, label, _ in top:
        votes[label] += 1
    squared = min((sum((prof.get(k, 0.0) - r.profile.get(k, 0.0)) ** 2 for k in prof.keys() | r.profile.keys()),
                   r.label, r.object) for r in refs)
    return {"nn": ranked[0][1],
            "mean2": min(per, key=lambda c: (sum(per[c][:2]) / len(per[c][:2]), c)),
            "vote3": max(votes, key=lambda c: (votes[c], -min(d for d, lab, _ in top if lab == c))),
            "l2": squared[1]}


def _inverse(ranked: list, label: str) -> float:
    """The inverse-distance share of ``label`` over every class's nearest training object in ``ranked``."""
    nearest: dict[str, float] = {}
    for d, c, _ in ranked:
        nearest.setdefault(c, d)  # ranked nearest first: a class's first is its nearest
    if label not in nearest:
        return 0.0
    if nearest[label] == 0:
        return 1.0 / sum(1 for d in nearest.values() if d == 0)
    return (1.0 / nearest[label]) / sum(1.0 / d if d > 0 else float("inf") for d in nearest.values())


def weigh(records: list[tuple[str, dict]], load_model, facts: dict, truth: dict[str, str]) -> dict:
    """The figures of one condition and system: ``records`` its fold files as (fold name, record), ``load_model``
    (fold name, draw, draws) -> the multi-class model of that draw, ``facts`` example id -> SceneFacts, ``truth``
    example id -> class. {"answers", "near", "right": {rule: near answers right}, "ece": {confidence: ECE of every
    answer}, "ece_held": ECE of the answers as the fold files hold them}; None without multi-class answers."""
    import numpy as np

    from lv3d.experiment.report import _multiclass_draws
    from lv3d.experiment.stats import ece
    from lv3d.learn.resemblance import profile, resemble

    right, n_near = {r: 0 for r in RULES}, 0
    conf, ok, held = {c: [] for c in CONFIDENCES}, [], []
    for name, rec in records:
        draws = _multiclass_draws(rec)  # the report's reading of a fold file's multi-class answers
        for d, (answers, how) in enumerate(zip(draws, rec.get("answered_by") or [])):
            model = load_model(name, d, len(draws))
            for (sid, label, c), kind in zip(answers, how):
                ok.append(label == truth[sid])
                held.append(float(c))
                if kind != "near" or not model.references:
                    for cname in CONFIDENCES:
                        conf[cname].append(float(c))
                    continue
                prof = profile(facts[sid])
                ranked = _ranked(prof, model.references)
                n_near += 1
                for rule, answer in _rules(ranked, prof, model.references).items():
                    right[rule] += answer == truth[sid]
                conf["ratio"].append(resemble(prof, model.references).confidence)  # the code in use
                conf["inverse"].append(_inverse(ranked, label))
    if not ok:
        return None
    y = np.asarray(ok, float)
    return {"answers": len(ok), "near": n_near, "right": right,
            "ece": {c: ece(np.asarray(v), y) for c, v in conf.items()}, "ece_held": ece(np.asarray(held), y)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=Path, help="the study's --out folder")
    ap.add_argument("--systems", default=None, help="comma-separated lv3d systems (default: every one it ran)")
    args = ap.parse_args(argv)
    if not (args.run / "config.yaml").is_file():
        raise SystemExit(f"{args.run}: not a study's --out folder (no config.yaml)")
    from lv3d.experiment.config import load_study
    from lv3d.experiment.runner import study_inputs
    from lv3d.learn import Model

    study = load_study(args.run / "config.yaml")
    for cond, cfg in study.conditions.items():
        systems = args.systems.split(",") if args.systems else [s for s in cfg.systems if s.startswith("lv3d-")]
        inputs, truth = None, {}
        for system in systems:
            paths = sorted((args.run / "folds" / cond / system).glob("fold*.json"))
            if not paths:
                continue
            if inputs is None:
                items, inputs = study_inputs(cfg, args.run, progress=False)
                truth = {it.id: it.cls for it in items}
            where = args.run / "programs" / cond / system

            def load_model(fold: str, draw: int, draws: int, where=where):
                return Model.load(where / fold / "multiclass" / (f"draw{draw}" if draws > 1 else ""))

            found = weigh([(p.stem, json.loads(p.read_text())) for p in paths], load_model,
                          inputs.for_system(system), truth)
            if found is None:
                continue
            rules = ", ".join(f"{r} {found['right'][r]}" for r in RULES)
            eces = ", ".join(f"{c} {found['ece'][c]:.3f}" for c in CONFIDENCES)
            print(f"{cond} {system}: {found['near']} answers by resemblance of {found['answers']}; right by rule: "
                  f"{rules}; ECE of all answers: {eces}, as the fold files hold them {found['ece_held']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
