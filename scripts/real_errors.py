"""What the wrong answers of a real-objects study are made of: per condition, lv3d system and class task, how many
answers were wrong, and how many of those were on objects whose facts contradict their class, by the evidence
named for each class (a predicate on one of the object's faces at confidence >= 0.5): a labelled object of the
class without it (or with no perceived object under its pixel), or an object of another class with it. A program
resting on that evidence answers all of those wrong, whatever the learner does; the rest are the learner's own
(a program that rests on other facts, or none).

    .venv/bin/python scripts/real_errors.py runs/real_objects runs/real_cache \\
        --evidence cylinder=cylindrical,box=perpendicular

RUN_DIR is the study's --out (its folds/<condition>/<system>/fold<k>.json); CACHE its data.cache, where the facts
of every frame are (facts/real-*/<facts version>/<modality>-refine1/<frame>.json, one folder per version of the
code that made them: --facts-version picks one where there are several).
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


def facts_folder(cache: Path, modality: str, version: str | None) -> Path:
    """The folder of one modality's cached facts (refined) in ``cache``, of ``version`` where given."""
    found = sorted(p for p in cache.glob(f"facts/real-*/*/{modality}-refine1") if version in (None, p.parent.name))
    if not found:
        raise SystemExit(f"{cache}: no cached {modality} facts of real frames"
                         + (f" made by version {version}" if version else ""))
    if len(found) > 1:
        raise SystemExit(f"{cache}: cached {modality} facts of several versions ("
                         + ", ".join(p.parent.name for p in found) + "): name one with --facts-version")
    return found[0]


def object_evidence(folder: Path, preds: set[str]) -> dict[str, dict[str, bool] | None]:
    """Per example id (``<frame>_x<object>``), which of ``preds`` hold on a face of the perceived object under its
    labelled pixel at confidence >= EVIDENCE_CONF; None where no object lies there."""
    out: dict[str, dict[str, bool] | None] = {}
    for path in sorted(folder.glob("*.json")):
        d = json.loads(path.read_text())
        facts = (d.get("facts") or {}).get("facts", [])
        faces = defaultdict(set)
        best: dict[tuple[str, str], float] = {}
        for f in facts:
            if f["pred"] == "face_of":
                faces[f["args"][0]].add(f["args"][1])
            elif f["pred"] in preds:
                key = (f["pred"], f["args"][0])
                best[key] = max(best.get(key, 0.0), f["conf"])
        for label, obj in (d.get("under") or {}).items():
            out[f"{d['frame']}_x{label}"] = None if obj is None else {
                p: any(best.get((p, face), 0.0) >= EVIDENCE_CONF for face in faces[obj]) for p in preds}
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=Path, help="the study's --out folder")
    ap.add_argument("cache", type=Path, help="the study's data.cache folder")
    ap.add_argument("--evidence", type=_evidence, required=True, metavar="CLASS=PRED,...",
                    help="the predicate each class task's evidence is, e.g. cylinder=cylindrical,box=perpendicular")
    ap.add_argument("--facts-version", help="the version folder of the cached facts, where there are several")
    args = ap.parse_args(argv)
    folds = sorted(args.run.glob("folds/*/lv3d-*/fold*.json"))
    if not folds:
        raise SystemExit(f"{args.run}: no lv3d fold files (folds/<condition>/lv3d-*/fold<k>.json)")
    evidence_of: dict[str, dict] = {}
    counts: dict[tuple[str, str, str], Counter] = defaultdict(Counter)
    for path in folds:
        fold = json.loads(path.read_text())
        system = fold["system"]
        modality = system.split("-", 1)[1]
        if modality not in evidence_of:
            evidence_of[modality] = object_evidence(facts_folder(args.cache, modality, args.facts_version),
                                                    set(args.evidence.values()))
        ev = evidence_of[modality]
        truth = dict(zip(fold["test_ids"], fold["test_classes"]))
        for cls, pred in args.evidence.items():
            for draw in fold["predictions"].get(cls, []):
                for example, answer, _ in draw:
                    has = ev.get(example)
                    holds = bool(has and has[pred])
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
