"""The best a program could do on a study's facts, chosen with hindsight: per class task, the most accurate
program over all of the study's examples at once (every test fold together, the labels known), among the
programs a shape learner learns:

- one clause ``c(A) :- face_of(A, B), p1(B), ..., pk(B)``: up to ``--literals`` properties of one face, each a
  face fact of docs/facts.md (``cylindrical``, ``rectangle``, ...) or a derived predicate of prolog/shape_bk.pl
  (``perpendicular_neighbour``, ...; ``c(A) :- right_corner(A)`` covers what ``c(A) :- face_of(A, B),
  perpendicular_neighbour(B)`` covers);
- or two such clauses of one property each (the learner's ``disjunctions``: pairs of one-clause hypotheses);
- or none (``c(A) :- false``: every answer "no", right on every other class's example; where it is the best,
  no program of this shape tells the class from the others better than answering "no" does).

An example is covered where its object has a face on which the clause's confidence, the product of the facts'
confidences as a proof combines them (``face_of`` included), reaches ``--threshold`` (the learner's 0.5); an
example with no perceived object (a labelled pixel on none, a rendered image where perception found none) is
covered by none. The figure is the share of the study's examples answered right (the positives covered, the other
classes' examples not): a ceiling on what a learner of such programs reaches from those facts with any training
sample, which a study's class-task accuracy (the same share, per test fold, mean over folds and draws; printed
beside it from results.json) can be set against. It bounds programs of this shape on all examples at once: a
study's mean over unequal test folds, or a program of another shape (a chain through a neighbour's neighbour),
may come out a point or so above it. Where it lies well below a target, it is the facts, that is perception,
that must change to reach the target, not the learner.

    .venv/bin/python scripts/fact_ceiling.py runs/real_objects
    .venv/bin/python scripts/fact_ceiling.py runs/ten_classes --modalities rgbd --classes cube,cuboid
    .venv/bin/python scripts/fact_ceiling.py runs/real_objects --modalities rgbd --classes cylinder --literals 2

RUN_DIR is a study's --out: its config.yaml says where its examples are (the folders of real frames, or the
rendered data set in data.cache), and each group of its conditions that learns from the same examples (a sweep
of positives does; one of noise presets does not) is measured once. The facts are read as the study reads them,
from the cache of this checkout's facts version; facts the cache lacks are computed.
"""

from __future__ import annotations

import argparse
import itertools
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

# prolog/shape_bk.pl's derived predicates of a face F, each the best over the G it names of the product of its
# body's facts: name -> (relation of F and G, property of G or None). acute_neighbour and obtuse_neighbour rest
# on acute(F, G) / obtuse(F, G) alone. (right_corner(O) is face_of(O, F) with perpendicular_neighbour(F).)
DERIVED = {"perpendicular_neighbour": (("adjacent", "perpendicular"), None),
           "acute_neighbour": (("acute",), None),
           "obtuse_neighbour": (("obtuse",), None),
           "pentagonal_neighbour": (("pentagonal_dihedral",), None),
           "hexagonal_neighbour": (("hexagonal_dihedral",), None),
           "triangle_neighbour": (("adjacent",), "triangle"),
           "quadrilateral_neighbour": (("adjacent",), "quadrilateral"),
           "square_neighbour": (("adjacent",), "square")}


def face_properties(facts, target: str | None) -> dict[str, dict[str, float]]:
    """{face: {property: confidence}} of the object ``target`` in ``facts`` (lv3d.facts.Fact, each with pred,
    args, conf): its faces' own facts and the derived predicates, each times the face's ``face_of``."""
    if target is None:
        return {}
    face_conf, own, rel = {}, defaultdict(dict), defaultdict(lambda: defaultdict(dict))
    for f in facts:
        if f.pred == "face_of":
            if f.args[0] == target:
                face_conf[f.args[1]] = f.conf
        elif len(f.args) == 1:
            own[f.args[0]][f.pred] = f.conf
        elif len(f.args) == 2:
            rel[f.pred][f.args[0]][f.args[1]] = f.conf
    out = {}
    for face, c in face_conf.items():
        props = dict(own[face])
        for name, (rels, prop) in DERIVED.items():
            best = 0.0
            for other in rel[rels[0]].get(face, {}):
                v = 1.0
                for r in rels:
                    v *= rel[r].get(face, {}).get(other, 0.0)
                if prop is not None:
                    v *= own[other].get(prop, 0.0)
                best = max(best, v)
            if best > 0:
                props[name] = best
        out[face] = {k: c * v for k, v in props.items()}
    return out


def ceilings(examples: list[tuple[str, dict[str, dict[str, float]]]], cls: str, literals: int,
             threshold: float) -> list[tuple[float, str, int, int]]:
    """The programs for ``cls`` by accuracy over ``examples`` ((class, face properties) each), best first: (accuracy,
    program text, positives covered, others covered)."""
    names = sorted({k for _, faces in examples for p in faces.values() for k in p})
    index = {n: i for i, n in enumerate(names)}
    # every example's faces stacked, row by row: the logarithms of their properties' confidences, which a
    # clause's literals add; an example without a face gets one row that covers nothing
    rows, starts = [], []
    for _, faces in examples:
        starts.append(len(rows))
        for props in faces.values() or [{}]:
            r = np.zeros(len(names))
            for k, v in props.items():
                r[index[k]] = v
            rows.append(r)
    with np.errstate(divide="ignore"):
        logs = np.log(np.array(rows))
    starts = np.array(starts)
    pos = np.array([c == cls for c, _ in examples])
    log_t = np.log(threshold)

    def covers(combos: np.ndarray) -> np.ndarray:
        """(combos, examples): whether each clause (a row of property indices) covers each example."""
        out = []
        for chunk in np.array_split(combos, max(1, len(combos) // 2000)):
            on_face = logs[:, chunk].sum(axis=2) >= log_t                 # (faces, clauses)
            out.append(np.maximum.reduceat(on_face, starts, axis=0).T)   # any face of each example
        return np.concatenate(out)

    def scored(cov: np.ndarray, text: str):
        right = np.count_nonzero(cov & pos) + np.count_nonzero(~cov & ~pos)
        return right / len(pos), text, int(np.count_nonzero(cov & pos)), int(np.count_nonzero(cov & ~pos))

    def body(combo) -> str:
        return ", ".join(f"{names[i]}(B)" for i in combo)

    if not names:                                   # no example has a face: no clause covers anything
        return [scored(np.zeros(len(pos), bool), "false")]
    singles = covers(np.arange(len(names))[:, None])
    out = [scored(cov, f"face_of(A, B), {body((i,))}") for i, cov in enumerate(singles)]
    for k in range(2, literals + 1):
        combos = np.array(list(itertools.combinations(range(len(names)), k)))
        if len(combos):
            out += [scored(cov, f"face_of(A, B), {body(c)}") for c, cov in zip(combos, covers(combos))]
    out += [scored(singles[i] | singles[j], f"face_of(A, B), {body((i,))} ; face_of(A, B), {body((j,))}")
            for i, j in itertools.combinations(range(len(names)), 2)]
    out = [s for s in out if s[2]]                 # a clause that covers no positive is the empty program's
    out.append(scored(np.zeros(len(pos), bool), "false"))  # no program: every answer "no"
    out.sort(key=lambda s: (-s[0], len(s[1]), s[1]))
    return out


def study_examples(cfg, run: Path, modality: str) -> list[tuple[str, dict[str, dict[str, float]]]]:
    """(class, face properties of its perceived object) of every example of the study condition ``cfg`` (a
    StudyConfig) whose --out is ``run``: the labelled objects of its real frames, or the images of its rendered
    data set, with the facts lv3d-``modality`` learns from there (lv3d.experiment.runner.study_inputs)."""
    from lv3d.experiment.runner import study_inputs

    items, inputs = study_inputs(cfg, run, progress=False)
    facts = inputs.for_system(f"lv3d-{modality}")
    return [(it.cls, face_properties(facts[it.id].facts, facts[it.id].target)) for it in items]


def data_groups(study) -> dict[str, list]:
    """The study's conditions grouped by the examples they learn from (a sweep of positives shares them; one of
    noise presets does not): {data key: [(condition name, its config), ...]}."""
    from lv3d.experiment.config import digest
    from lv3d.experiment.data import data_key

    groups: dict[str, list] = {}
    for name, cfg in study.conditions.items():
        key = digest({"data": data_key(cfg), "folders": list(cfg.data.folders or []),
                      "lv3d": [cfg.lv3d.refine, cfg.lv3d.confidences, cfg.lv3d.perception_seed]})
        groups.setdefault(key, []).append((name, cfg))
    return groups


def study_results(run: Path) -> dict:
    """The conditions of the study's results.json ({} where the run has none yet)."""
    import json

    path = run / "results.json"
    return json.loads(path.read_text()).get("conditions", {}) if path.is_file() else {}


def study_figures(found: dict, system: str, cls: str, conditions: list[str]) -> list[tuple[str, float]]:
    """(condition, the class task's mean accuracy over folds) of ``system`` in the study's results (``found``,
    :func:`study_results`), for each of ``conditions`` it has."""
    out = []
    for cond in conditions:
        mean = found.get(cond, {}).get("systems", {}).get(system, {}).get("classes", {}).get(cls, {}).get("mean")
        if mean is not None:
            out.append((cond, mean))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=Path, help="the study's --out folder")
    ap.add_argument("--modalities", default="rgbd,depth", help="comma-separated, of rgb, depth, rgbd")
    ap.add_argument("--classes", default=None, help="comma-separated class tasks (default: the study's classes)")
    ap.add_argument("--literals", type=int, default=3, help="most face properties in one clause (default 3)")
    ap.add_argument("--threshold", type=float, default=0.5, help="confidence at which a clause covers (0.5)")
    ap.add_argument("--top", type=int, default=3, help="programs shown per class task")
    args = ap.parse_args(argv)
    if not (args.run / "config.yaml").is_file():
        raise SystemExit(f"{args.run}: not a study's --out folder (no config.yaml)")
    if not 0 < args.threshold <= 1 or args.literals < 1 or args.top < 1:
        raise SystemExit("--threshold must lie in (0, 1], --literals and --top be 1 or more")
    modalities = [m.strip() for m in args.modalities.split(",") if m.strip()]
    if bad := [m for m in modalities if m not in ("rgb", "depth", "rgbd")]:
        raise SystemExit(f"--modalities: unknown {bad}; choose among rgb, depth, rgbd")
    from lv3d.experiment.config import load_study

    groups = data_groups(load_study(args.run / "config.yaml"))
    known = {c for conds in groups.values() for _, cfg in conds for c in cfg.data.classes}
    if args.classes and (bad := [c for c in args.classes.split(",") if c not in known]):
        raise SystemExit(f"--classes: {bad} not among the study's classes {sorted(known)}")
    found = study_results(args.run)
    for conds in groups.values():
        names = [name for name, _ in conds]
        where = f" ({', '.join(names)})" if len(groups) > 1 else ""
        for modality in modalities:
            examples = study_examples(conds[0][1], args.run, modality)
            classes = args.classes.split(",") if args.classes else list(conds[0][1].data.classes)
            for cls in classes:
                n_pos = sum(c == cls for c, _ in examples)
                best = ceilings(examples, cls, args.literals, args.threshold)[:args.top]
                print(f"{modality} {cls}{where}: {len(examples)} examples ({n_pos} {cls}); ceiling "
                      f"{100 * best[0][0]:.1f} %")
                if study := study_figures(found, f"lv3d-{modality}", cls, names):
                    print(f"  the study's lv3d-{modality}: " + ", ".join(f"{c} {100 * m:.1f} %" for c, m in study))
                for acc, text, tp, fp in best:
                    print(f"  {100 * acc:5.1f} %  {cls}(A) :- {text}.   covers {tp}/{n_pos} {cls}, "
                          f"{fp}/{len(examples) - n_pos} others")
    return 0


if __name__ == "__main__":
    sys.exit(main())
