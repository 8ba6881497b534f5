"""What the wrong answers of a real-objects study are made of: per condition, lv3d system and class task, how many
answers were wrong, and how many of those were on objects whose facts contradict their class, by the evidence
named for each class (a predicate on one of the object's faces at confidence >= 0.5): a labelled object of the
class without it (or with no perceived object under its pixel), or an object of another class with it. A program
resting on that evidence answers all of those wrong, whatever the learner does; the rest are the learner's own
(a program that rests on other facts, or none).

    .venv/bin/python scripts/real_errors.py runs/real_objects --evidence cylinder=cylindrical,box=perpendicular

RUN_DIR is the study's --out: its config.yaml (the frames' folders and classes, data.cache, lv3d.refine and
lv3d.perception_seed) and its fold files (folds/<condition>/<system>/fold<k>.json). Each example's facts are read
as the study reads them (lv3d.experiment.runner.study_inputs), from the cache of this
checkout's facts version; facts the cache lacks are computed.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter, defaultdict
from pathlib import Path

EVIDENCE_CONF = 0.5


def _evidence(arg: str) -> dict[str, str]:
    out = {}
    for part in arg.split(","):
        cls, _, pred = part.partition("=")
        if not cls.strip() or not pred.strip():
            raise argparse.ArgumentTypeError(f"{part!r}: give CLASS=PREDICATE, e.g. cylinder=cylindrical")
        out[cls.strip()] = pred.strip()
    return out


def example_evidence(run: Path, modality: str, preds: set[str]) -> dict[str, set[str]]:
    """Per example id of the study in ``run``, which of ``preds`` hold on a face of the perceived object under its
    labelled pixel at confidence >= EVIDENCE_CONF (none where no object lies there), in ``modality``'s facts."""
    from lv3d.experiment.config import load_study
    from lv3d.experiment.runner import study_inputs

    _, inputs = study_inputs(load_study(run / "config.yaml").base, run, progress=False)
    facts = inputs.for_system(f"lv3d-{modality}")
    return {i: {f.pred for f in sf.facts if f.pred in preds and f.conf >= EVIDENCE_CONF} for i, sf in facts.items()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=Path, help="the study's --out folder")
    ap.add_argument("--evidence", type=_evidence, required=True, metavar="CLASS=PRED,...",
                    help="the predicate each class task's evidence is, e.g. cylinder=cylindrical,box=perpendicular")
    args = ap.parse_args(argv)
    folds = sorted(args.run.glob("folds/*/lv3d-*/fold*.json"))
    if not folds or not (args.run / "config.yaml").is_file():
        raise SystemExit(f"{args.run}: not a study's --out folder with lv3d fold files "
                         "(config.yaml, folds/<condition>/lv3d-*/fold<k>.json)")
    evidence_of: dict[str, dict] = {}
    counts: dict[tuple[str, str, str], Counter] = defaultdict(Counter)
    for path in folds:
        fold = json.loads(path.read_text())
        system = fold["system"]
        modality = system.split("-", 1)[1]
        if modality not in evidence_of:
            evidence_of[modality] = example_evidence(args.run, modality, set(args.evidence.values()))
        ev = evidence_of[modality]
        truth = dict(zip(fold["test_ids"], fold["test_classes"]))
        for cls, pred in args.evidence.items():
            for draw in fold["predictions"].get(cls, []):
                for example, answer, _ in draw:
                    holds = pred in ev.get(example, ())
                    positive = truth[example] == cls
                    contradicts = not holds if positive else holds
                    wrong = (answer == cls) != positive
                    c = counts[(fold["condition"], system, cls)]
                    c["answers"] += 1
                    c["wrong"] += wrong
                    c["contradicting"] += contradicts
                    c["wrong_contradicting"] += wrong and contradicts
    print(f"{'condition':<16} {'system':<11} {'task':<10} {'answers':>7} {'wrong':>12} {'of them on contradicting':>25}"
          f" {'contradicting objects':>22}")
    for (cond, system, cls), c in sorted(counts.items()):
        n, w = c["answers"], c["wrong"]
        print(f"{cond:<16} {system:<11} {cls:<10} {n:>7} {w:>5} ({100 * w / n:4.1f} %) {c['wrong_contradicting']:>25}"
              f" {c['contradicting']:>10} ({100 * c['contradicting'] / n:4.1f} %)")
    print(f"\ncontradicting: the object's facts contradict its class by the evidence "
          f"{', '.join(f'{k}={v}' for k, v in args.evidence.items())} (a face with it at >= {EVIDENCE_CONF})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
