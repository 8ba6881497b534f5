"""Learning shape concepts from scenes' facts: one program per class, classification by the most
confident proof, and the proof as the explanation. Depends on the fact contract only."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, read_json
from ..facts import PREDICATES, SceneFacts
from . import engine
from .engine import LearnError
from .program import Program
from .resemblance import Reference, Resemblance, contrast, profile, resemble
from .settings import EXCLUDED, NOT_MIL, check_settings

# Metarules for shape concepts, in search order: a part with a property, a part with two, a
# conjunction on the object, then a part in a relation with another part.
SHAPE_METARULES = ("part", "part2", "part_pair")
# When no program proves a scene, a model of several classes names the class of the training object it
# resembles most (resemblance.py; docs/learner.md, "Classifying") and shows that class's near proof: a fact
# the scene lacks counts as holding with this confidence, the chance that perception missed a true fact.
NEAR_MISS = 0.1
ANSWER_KINDS = ("proof", "arbiter", "near", "unknown")  # how Model.answer reached an answer
# Learning from many examples (docs/learner.md, "Imperfect labels"): 16 samples of 2 positives and
# 6 negatives; with 20 % wrong labels, 3 to 7 of them hold none, where 8 samples of 2 + 12 held 0.3 to 2.
# In few-shot tasks a `regular` literal costs 0.5 nats of prior (docs/learner.md, Settings): every class
# shows a regular face in most views, so among the clauses one positive cannot tell apart, those
# resting on it generalise worst.
SHAPE_SETTINGS = {"max_clauses": 1, "max_literals": 6, "max_inventions": 0, "time_limit": 20, "disjunctions": 20,
                  "extra_literals": 1,
                  "samples": 16, "sample_neg": 6, "predicate_prior": [["regular", 0.5]]}
# Shape learning by invention instead of shape_bk's hand-written derived predicates: a second clause
# for one invented face property (docs/learner.md, "Invention"). On the seed protocol and the few-shot
# study it comes within 1.4 points of SHAPE_SETTINGS on the class tasks of lv3d-rgbd and -depth and
# re-invents some derived predicates (an obtuse neighbour), but the derived predicates are as good or
# better in 14 of 18 cells and bound the time, so SHAPE_SETTINGS keeps them.
INVENTION_SETTINGS = {"derived": False, "max_inventions": 1, "max_clauses": 2,
                      "metarules": ["part", "part2", "part_pair", "part_rel", "has"]}
FIT_MODULE, SCENE_MODULE = "lv3d_fit", "lv3d_scene"


# Search order of the body predicates, which decides among equally good hypotheses (the first
# found wins): what a face is (sides, metric shape), what faces it meets, at which angles, then
# the 2D outline, and last the face's orientation to the table, which depends on how the solid
# happens to rest and so generalises worst from one view.
BODY_ORDER = ("face_of", "cylindrical", "conical", "spherical", "circular", "elliptical", "triangle", "quadrilateral", "pentagon", "hexagon", "square", "rectangle", "regular",
              "triangle_neighbour", "quadrilateral_neighbour", "square_neighbour",
              "perpendicular_neighbour", "acute_neighbour", "obtuse_neighbour", "pentagonal_neighbour",
              "hexagonal_neighbour", "right_corner",
              "adjacent", "perpendicular", "acute", "obtuse", "pentagonal_dihedral", "hexagonal_dihedral", "parallel", "parallelogram", "horizontal", "vertical")


def body_preds(modality: str, derived: bool = True) -> list[tuple[str, int]]:
    """The body predicates a system seeing ``modality`` learns with, in search order: the contract's
    (but object/1, true of every target) and, with ``derived``, the derived ones of prolog/shape_bk.pl
    whose facts the modality emits."""
    own = [(p, a) for p, (a, mods) in PREDICATES.items() if modality in mods and p not in EXCLUDED]
    seen = {p for p, (_, mods) in PREDICATES.items() if modality in mods}
    uses = engine.derived_uses()
    # a derived predicate whose rule rests on a fact the modality never emits can never be proved
    preds = own + [(p, a) for p, a in engine.derived_preds() if derived and uses.get(p, frozenset()) <= seen]
    rank = {p: i for i, p in enumerate(BODY_ORDER)}
    return sorted(preds, key=lambda pa: rank.get(pa[0], len(rank)))


def _facts_text(scene: SceneFacts) -> list[str]:
    return [f"{f.pred}({','.join(f.args)},{f.conf:.6g})" for f in scene.facts]


def _load(module: str, scenes: list[SceneFacts]) -> str:
    facts = [t for s in scenes for t in _facts_text(s)]
    return f"lv3d_bridge:load_scene({module}, {engine.fact_pred_specs()}, {engine.plist(facts)})"


def _check_scenes(scenes: list[SceneFacts]) -> str:
    if not scenes:
        raise InputError("scenes", "no scenes to learn from")
    modalities = {s.modality for s in scenes}
    if len(modalities) != 1:
        raise InputError("scenes", f"scenes of several modalities {sorted(modalities)}; learn one at a time")
    targets = [s.target for s in scenes]
    for s in scenes:
        if s.target is None:
            raise InputError(s.scene, "scene has no target object")
    if len(set(targets)) != len(targets):
        raise InputError("scenes", "two scenes share a target object id; scene ids must be unique")
    return modalities.pop()


def predicate_name(label: str) -> str:
    """The predicate a class's program defines: the label itself, or is_<label> when the label names a
    body predicate (a fact of the contract or a derived one), which a learned clause could not
    otherwise tell from it (Program.label keeps the class)."""
    taken = set(PREDICATES) | {p for p, _ in engine.derived_preds()}
    return f"is_{label}" if label in taken else label


def few_negatives(n_neg: int) -> int:
    """Negatives a sample holds when the task has only ``n_neg``: two thirds of them, rounded up (at least one).
    With every negative in every sample, one negative whose facts are wrong (a bowl read as a cylinder's side)
    would veto the right hypothesis in all samples; with two thirds, some samples leave it out, and scoring on
    all examples still counts it against the hypothesis."""
    return max(1, math.ceil(2 * n_neg / 3))


def precision(score: dict) -> float:
    """How often a program's proof named its class on the training examples: (tp + 1) / (tp + fp + 2), the
    Laplace estimate, so that one or two examples move it little; 1 for a program saved without its counts.
    Several programs may prove one object (a triangle face proves an over-general tetrahedron program on a
    triangular prism, whose own program proves it too); their proofs are weighed by it, as the chance that
    the class is right given its program holds."""
    tp, fp = score.get("tp"), score.get("fp")
    if not isinstance(tp, (int, float)) or not isinstance(fp, (int, float)):
        return 1.0
    return (tp + 1) / (tp + fp + 2)


def fit(scenes: list[SceneFacts], labels: list[str], target: str, *, settings: dict | None = None,
        seed: int = 0) -> Program:
    """Learn ``target(O)`` from the scenes' target objects: positives where label == target,
    negatives the rest. ``settings`` override SHAPE_SETTINGS and mil's defaults (docs/learner.md).
    A target named like a body predicate (``triangle``) is learned as ``is_triangle``, its program's
    label saying so. LearnError when no hypothesis covers any sample or the search runs out of time."""
    if len(scenes) != len(labels):
        raise InputError("labels", f"{len(labels)} labels for {len(scenes)} scenes")
    modality = _check_scenes(scenes)
    pos = [s.target for s, y in zip(scenes, labels) if y == target]
    neg = [s.target for s, y in zip(scenes, labels) if y != target]
    if not pos:
        raise InputError("labels", f"no scene is labelled {target!r}")
    user = check_settings(settings)
    opts = {**SHAPE_SETTINGS, **user, "seed": int(seed)}
    if "sample_neg" not in user:  # few negatives: a sample holds at most two thirds of them (docs/learner.md)
        opts["sample_neg"] = min(opts["sample_neg"], few_negatives(len(neg)))
    label, target = target, predicate_name(target)
    opts.pop("arbiters", None)  # Model.fit's, not the search's
    preds = engine.plist(f"{p}/{a}" for p, a in body_preds(modality, opts.pop("derived", True)))
    mrs = engine.plist(opts.pop("metarules", SHAPE_METARULES))
    goal = (f"{_load(FIT_MODULE, scenes)}, "
            f"lv3d_bridge:fit({FIT_MODULE}, {target}, {preds}, {mrs}, {engine.plist(pos)}, {engine.plist(neg)}, "
            f"{engine.settings_term(opts)}, result(Texts, J, Soft, TP, NP, FP, NN, Thr)), "
            f"lv3d_bridge:drop_scene({FIT_MODULE})")
    try:
        ans = engine.query(goal, where=f"learning {target}")
    finally:
        engine.query(f"lv3d_bridge:drop_scene({FIT_MODULE})")
    if not ans:
        raise LearnError(f"learning {target}: no program covers any sample of the positives")
    a = ans[0]
    score = {"j": float(a["J"]), "soft": float(a["Soft"]), "tp": int(a["TP"]), "n_pos": int(a["NP"]),
             "fp": int(a["FP"]), "n_neg": int(a["NN"]), "threshold": float(a["Thr"])}
    return Program(target, tuple(str(t) for t in a["Texts"]), score, modality, opts,
                   label=label if label != target else None)


@dataclass
class Explanation:
    """Why a scene got its label: the best proof's clauses and the facts it used."""

    label: str
    confidence: float
    target: str | None
    clauses: list[str] = field(default_factory=list)
    facts: list[tuple[str, float]] = field(default_factory=list)
    derived: list[str] = field(default_factory=list)
    others: dict[str, float] = field(default_factory=dict)
    missing: list[str] = field(default_factory=list)  # facts the scene lacks (a near miss)
    near: bool = False  # no program proves the scene at its threshold: this is the nearest one
    # the class whose program proved it too and ranked first or second, and the arbiter that told them apart: the
    # label's, proving it (rival_clauses, rival_facts: the proof), or the rival's, failing to (rival_fails)
    rival: str | None = None
    rival_clauses: list[str] = field(default_factory=list)
    rival_facts: list[tuple[str, float]] = field(default_factory=list)
    # the arbiter is the rival's, learned with the rival's examples as its positives, and fails to prove it
    rival_fails: bool = False
    # a near answer: the training objects whose facts the scene's resemble most, of its class and of another
    # (resemblance.Resemblance), (predicate, the scene's confidence, the training object's) shown by both / by one
    # of the scene and the nearest, and its class program's near proof confidence
    resembles: Resemblance | None = None
    shared: list[tuple[str, float, float]] = field(default_factory=list)
    differ: list[tuple[str, float, float]] = field(default_factory=list)
    near_confidence: float = 0.0

    def _proof_lines(self, indent: str) -> list[str]:
        """The clauses, the facts they used and those the scene lacks, each line indented by ``indent``."""
        lines = [indent + c.replace("\n", "\n" + indent) for c in self.clauses]
        lines += [f"{indent}with {a} ({c:.3f})" for a, c in self.facts]
        lines += [f"{indent}but not {a} (absent)" for a in self.missing]
        return lines

    def __str__(self) -> str:
        if self.label == "unknown":
            return f"{self.target}: unknown (no class's program proves it)"
        if self.resembles:
            r = self.resembles
            lines = [f"{self.target} is most likely a {self.label} (confidence {self.confidence:.3f}): no program "
                     f"proves it, and of the training objects it resembles {r.ref.object}, a {r.ref.label}, "
                     f"most (distance {r.distance:.2f})"
                     + (f"; of another class, {r.other.object}, a {r.other.label}, at {r.other_distance:.2f}"
                        if r.other else "")]
            lines += [f"  both show {p} ({a:.3f} here, {b:.3f} there)" for p, a, b in self.shared]
            lines += [f"  {'it shows' if a >= b else 'that one shows'} {p} ({a:.3f} here, {b:.3f} there)"
                      for p, a, b in self.differ]
            if self.clauses:
                lines.append(f"  the {self.label}'s program, which it misses (near proof {self.near_confidence:.3f}):")
                lines += self._proof_lines("    ")
            if self.others:
                lines.append("  nearest proofs of the others: " + ", ".join(f"{k} {v:.3f}" for k, v in self.others.items()))
            return "\n".join(lines)
        if self.missing:
            lines = [f"{self.target} is most likely a {self.label} (confidence {self.confidence:.3f}): no program "
                     f"proves it, and this one misses by {len(self.missing)} of its "
                     f"{len(self.facts) + len(self.missing)} fact(s), the least"]
        elif self.near:
            lines = [f"{self.target} is most likely a {self.label} (confidence {self.confidence:.3f}): no program "
                     f"proves it above its threshold, and this one comes nearest"]
        else:
            lines = [f"{self.target} is a {self.label} (confidence {self.confidence:.3f}) because"]
        lines += self._proof_lines("  ")
        lines += [f"  where {d} (background)" for d in self.derived]
        if self.rival:
            why = (f"no clause of what tells a {self.rival} from a {self.label} proves it:" if self.rival_fails
                   else "")
            lines.append(f"  rather than a {self.rival} (whose program proves it too), because {why}".rstrip())
            lines += ["    " + c.replace("\n", "\n    ") for c in self.rival_clauses]
            lines += [f"    with {a} ({c:.3f})" for a, c in self.rival_facts]  # none where the arbiter fails
        if self.others:
            lines.append("  also proved: " + ", ".join(f"{k} {v:.3f}" for k, v in self.others.items()))
        return "\n".join(lines)


class Model:
    """One program per class. ``predict`` names the class whose program proves the scene's target
    with the highest confidence times the program's training :func:`precision` (ties: the program with
    the higher training J), answering with the proof's confidence. When the two first-ranked classes'
    programs both prove it and the model holds arbiters for that pair (``arbiters``: (class, rival) ->
    a program that proves the class's training examples and not the rival's, :meth:`fit`), the class
    whose arbiter proves it while the other's does not comes first; where the pair has one arbiter only (the
    other's search found none), its class comes first when it proves the scene and the other when it does not
    (negation as failure: the arbiter was learned on the two classes alone). When none proves
    it: a class task (one class), "unknown" (its negative answer); a model of several classes, the class of the
    training object whose facts it resembles most (``references``, resemblance.py; a class whose search found no
    program among them), with that class's near proof (absent facts at NEAR_MISS) as what its program misses, and
    a confidence of how much nearer that class's training objects lie than any other's (resemblance.closeness).
    A model without references (a model.json without a "references" list) names the class whose program it misses
    by least instead (:func:`_near_rank`: the largest share of the program's facts present, then the highest
    per-fact confidence of those, times precision), with its near proof's confidence."""

    def __init__(self, programs: dict[str, Program], settings: dict | None = None,
                 failures: dict[str, str] | None = None,
                 arbiters: dict[tuple[str, str], Program] | None = None,
                 references: list[Reference] | None = None):
        self.programs = dict(programs)
        self.settings = dict(settings or {})
        self.failures = dict(failures or {})  # class -> why no program was learned
        self.arbiters = dict(arbiters or {})  # (class, rival) -> the program telling the class from the rival
        self.references = list(references or [])  # the training objects a scene no program proves is likened to

    @classmethod
    def fit(cls, scenes: list[SceneFacts], labels: list[str], settings: dict | None = None, seed: int = 0,
            classes: list[str] | None = None) -> "Model":
        """A program for each class in ``classes`` (default: every label). A class whose search finds
        nothing or runs out of time gets no program (it is never predicted); ``failures`` says why.
        With several classes each search shrinks its samples where none gives a hypothesis
        (``shrink_samples``, docs/learner.md), unless ``settings`` say otherwise: a class without a
        program is never the answer, while one class's task without a program answers "no". With several
        classes the model also learns arbiters between rival classes (:meth:`_learn_arbiters`) unless
        ``settings`` hold ``arbiters: false``."""
        settings = check_settings(settings) or None  # a bad setting stops here, not as every class's failure
        classes = classes or sorted(set(labels))
        search = dict(settings or {})
        if len(classes) > 1:  # a class without a program is never named: its search shrinks its samples
            search.setdefault("shrink_samples", True)
        programs, failures = {}, {}
        for c in classes:
            try:
                programs[c] = fit(scenes, labels, c, settings=search or None, seed=seed)
            except LearnError as e:
                failures[c] = str(e)
        references = []
        if len(classes) > 1:  # a class task answers "unknown" where its program fails: it likens nothing
            references = [Reference(sc.target, y, profile(sc)) for sc, y in zip(scenes, labels) if sc.target is not None]
        model = cls(programs, settings, failures, references=references)
        if len(programs) > 1 and search.get("arbiters", True):
            model.arbiters = model._learn_arbiters(scenes, labels, search or None, seed)
        return model

    def _learn_arbiters(self, scenes: list[SceneFacts], labels: list[str], settings: dict | None, seed: int
                        ) -> dict[tuple[str, str], Program]:
        """Programs that tell rival classes apart: two classes are rivals where a training example's own
        program proves it and the other's proof ranks above it (two classes' programs alike, such as "a
        rectangle face with an obtuse neighbour" for both pentagonal and hexagonal prisms, which their
        one-against-all tasks cannot tell from the better J of the general clause). For each class of a
        rival pair, a program learned on the two classes' training examples alone, its own as positives
        (the search of :func:`fit`, with the model's settings); none where that search finds none."""
        rivals = set()
        for scene, y in zip(scenes, labels):
            proofs = self._proofs(scene)
            if proofs and proofs[0]["label"] != y and any(p["label"] == y for p in proofs):
                rivals.add(tuple(sorted((y, proofs[0]["label"]))))
        arbiters = {}
        for a, b in sorted(rivals):
            pair = [(s, y) for s, y in zip(scenes, labels) if y in (a, b)]
            for c, other in ((a, b), (b, a)):
                name = f"{self.programs[c].target}_over_{self.programs[other].target}"
                try:
                    arbiters[(c, other)] = fit([s for s, _ in pair], [name if y == c else other for _, y in pair],
                                               name, settings=settings, seed=seed)
                except LearnError:
                    continue
        return arbiters

    def _proofs(self, scene: SceneFacts, near: bool = False) -> list[dict]:
        if scene.target is None:
            raise InputError(scene.scene, "scene has no target object")
        arbiters = {} if near else self.arbiters  # a near answer is no proof for an arbiter to weigh
        progs = engine.plist(f"{p.target}-{engine.plist(engine.quote(c) for c in p.clauses)}"
                             for p in [*self.programs.values(), *arbiters.values()])
        preds = engine.plist(f"{p}/{a}" for p, a in body_preds(scene.modality))
        opts = {k: v for k, v in {**SHAPE_SETTINGS, **self.settings}.items() if k not in NOT_MIL}
        thr = self._thresholds(opts)
        arb_thr = self._thresholds(opts, {p.target: p for p in arbiters.values()})
        # every program proves it when near, missing facts at NEAR_MISS each
        opts["threshold"] = 0.0 if near else min([*thr.values(), *arb_thr.values()], default=0.5)
        if near:
            opts["miss"] = NEAR_MISS
        goal = (f"{_load(SCENE_MODULE, [scene])}, lv3d_bridge:classify({SCENE_MODULE}, {progs}, {preds}, "
                f"{scene.target}, {engine.settings_term(opts)}, Rs), lv3d_bridge:drop_scene({SCENE_MODULE})")
        ans = engine.query(goal, where=f"classifying {scene.scene}")
        classes = {p.target: c for c, p in self.programs.items()}
        out, settled = [], {}
        for r in ans[0]["Rs"] if ans else []:
            pred, conf, trace = _result_parts(r)
            if pred in arb_thr:
                if conf >= arb_thr[pred]:
                    settled[pred] = trace
                continue
            label = classes.get(pred, pred)
            if near or conf >= thr[label]:
                matched, rank = _near_rank(trace) if near else (1.0, conf)
                out.append({"label": label, "conf": conf, "trace": trace, "matched": matched, "rank": rank})
        j = {k: p.score.get("j", 0.0) for k, p in self.programs.items()}
        prec = {k: precision(p.score) for k, p in self.programs.items()}
        for r in out:
            r["rank"] *= prec.get(r["label"], 1.0)
        out.sort(key=lambda r: (r["matched"], r["rank"], j.get(r["label"], 0.0)), reverse=True)
        return self._arbitrate(out, settled)

    def _arbitrate(self, proofs: list[dict], settled: dict[str, list]) -> list[dict]:
        """``proofs`` ranked, with the two first swapped where the pair's arbiters say so: the second's arbiter
        proves the scene (``settled``: arbiter target -> its proof's trace) and the first's does not. The one
        ranked first then carries ``rival`` (the other class) and ``rival_trace`` when an arbiter decided."""
        if len(proofs) < 2:
            return proofs
        first, second = proofs[0]["label"], proofs[1]["label"]
        told, held = {}, []
        for c, other in ((first, second), (second, first)):
            arb = self.arbiters.get((c, other))
            if arb is not None:
                held.append((other, arb))
                if arb.target in settled:
                    told[c] = (arb, settled[arb.target])
        if not told and len(held) == 1:
            # the pair's one arbiter (learned on the two classes alone, its class's examples the positives and
            # the other's the negatives) does not prove the scene: by negation as failure, it is the other class
            other, arb = held[0]
            told[other] = (arb, None)
        if len(told) != 1:  # neither or both: the arbiters cannot tell them apart
            return proofs
        winner = next(iter(told))
        ranked = list(proofs) if winner == first else [proofs[1], proofs[0], *proofs[2:]]
        loser = second if winner == first else first
        arb, trace = told[winner]
        ranked[0] = {**ranked[0], "rival": loser, "rival_program": arb, "rival_trace": trace}
        return ranked

    def _decide(self, scene: SceneFacts) -> list[dict]:
        proofs = self._proofs(scene)
        if proofs or (len(self.programs) < 2 and not self.references):  # a class task: "unknown"
            return proofs
        proofs = [{**p, "near": True} for p in self._proofs(scene, near=True)] if self.programs else []
        prof = profile(scene)
        found = resemble(prof, self.references)
        if found is None:
            return proofs
        mine = next((p for p in proofs if p["label"] == found.ref.label), None)
        first = {**(mine or {"label": found.ref.label, "conf": 0.0, "trace": [], "near": True}),
                 "conf": found.confidence, "resembles": (found, prof), "near_conf": mine["conf"] if mine else 0.0}
        return [first, *(p for p in proofs if p is not mine)]

    def _thresholds(self, opts: dict, programs: dict[str, Program] | None = None) -> dict[str, float]:
        """Each program's coverage threshold (of ``programs``, default the classes'), by the same keys: the one it
        was learned with, else the settings'."""
        default = float(opts.get("threshold", 0.5))
        programs = self.programs if programs is None else programs
        return {k: float(p.score.get("threshold", default)) for k, p in programs.items()}

    def predict(self, scene: SceneFacts) -> tuple[str, float]:
        label, conf, _ = self.answer(scene)
        return label, conf

    def answer(self, scene: SceneFacts) -> tuple[str, float, str]:
        """:meth:`predict`'s (label, confidence) and how the answer was reached (``ANSWER_KINDS``): "proof" (a
        program proves the scene and ranks first), "arbiter" (two classes' programs prove it and an arbiter put
        this one first), "near" (no program proves it: the nearest, several programs only) or "unknown"."""
        proofs = self._decide(scene)
        if not proofs:
            return "unknown", 0.0, "unknown"
        best = proofs[0]
        how = "near" if best.get("near") else "arbiter" if "rival" in best else "proof"
        return best["label"], best["conf"], how

    def explain(self, scene: SceneFacts) -> Explanation:
        proofs = self._decide(scene)
        if not proofs:
            return Explanation("unknown", 0.0, scene.target)
        best = proofs[0]
        program = self.programs.get(best["label"])
        clauses, facts = _proof_parts(program, best["trace"]) if program is not None else ([], [])
        return Explanation(
            best["label"], best["conf"], scene.target, clauses=clauses, facts=facts,
            derived=[a for k, a, _ in best["trace"] if k == "derived"],
            others={p["label"]: p["conf"] for p in proofs[1:]},
            missing=[a for k, a, _ in best["trace"] if k == "missing"], near=best.get("near", False),
            **self._rival_parts(best), **self._resemblance_parts(best))

    @staticmethod
    def _resemblance_parts(best: dict) -> dict:
        """The Explanation fields of the training object a near answer likened the scene to, if one did."""
        if "resembles" not in best:
            return {}
        found, prof = best["resembles"]
        shared, differ = contrast(prof, found.ref)
        return {"resembles": found, "shared": shared, "differ": differ, "near_confidence": best["near_conf"]}

    @staticmethod
    def _rival_parts(best: dict) -> dict:
        """The Explanation fields of the arbiter that ranked ``best`` first, if one did."""
        if "rival" not in best:
            return {}
        if best["rival_trace"] is None:  # the rival's arbiter fails to prove it: every clause of it fails
            return {"rival": best["rival"], "rival_clauses": list(best["rival_program"].clauses), "rival_fails": True}
        clauses, facts = _proof_parts(best["rival_program"], best["rival_trace"])
        return {"rival": best["rival"], "rival_clauses": clauses, "rival_facts": facts}

    def save(self, out_dir: Path) -> Path:
        out_dir = Path(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        for p in [*self.programs.values(), *self.arbiters.values()]:
            p.save(out_dir / f"{p.target}.pl")
        (out_dir / "model.json").write_text(json.dumps(
            {"classes": sorted(self.programs), "settings": self.settings,
             "scores": {k: p.score for k, p in self.programs.items()},
             "predicates": {k: p.target for k, p in self.programs.items() if p.target != k},
             "arbiters": [{"class": c, "rival": r, "predicate": p.target, "score": p.score}
                          for (c, r), p in sorted(self.arbiters.items())],
             "references": [{"object": r.object, "class": r.label, "profile": r.profile} for r in self.references]},
            indent=1))
        return out_dir

    @classmethod
    def load(cls, in_dir: Path) -> "Model":
        in_dir = Path(in_dir)
        index = in_dir / "model.json"
        if not index.is_file():
            raise InputError(in_dir, "not a model directory (no model.json)")
        meta = read_json(index, "model.json")
        try:
            classes = list(meta["classes"])
        except (KeyError, TypeError) as e:
            raise InputError(index, f"malformed: {e}") from None
        programs = {}
        preds = meta.get("predicates", {}) if isinstance(meta.get("predicates"), dict) else {}
        for c in classes:
            pred = preds.get(c, c)
            p = Program.load(in_dir / f"{pred}.pl", target=pred)
            programs[c] = Program(p.target, p.clauses, meta.get("scores", {}).get(c, {}), p.modality,
                                  label=c if pred != c else None)
        arbiters = {}
        for a in meta.get("arbiters", []) if isinstance(meta.get("arbiters"), list) else []:
            try:
                c, r, pred = str(a["class"]), str(a["rival"]), str(a["predicate"])
            except (KeyError, TypeError) as e:
                raise InputError(index, f"malformed arbiter {a!r}: {e}") from None
            if c not in programs or r not in programs:
                raise InputError(index, f"an arbiter of {c!r} over {r!r}, a class the model does not hold")
            p = Program.load(in_dir / f"{pred}.pl", target=pred)
            arbiters[(c, r)] = Program(p.target, p.clauses, a.get("score", {}) or {}, p.modality)
        references = []
        for r in meta.get("references", []) if isinstance(meta.get("references"), list) else []:
            try:
                references.append(Reference(str(r["object"]), str(r["class"]),
                                            {str(k): float(v) for k, v in dict(r["profile"]).items()}))
            except (KeyError, TypeError, ValueError) as e:
                raise InputError(index, f"malformed reference {r!r}: {e}") from None
        return cls(programs, meta.get("settings", {}), arbiters=arbiters, references=references)


def _proof_parts(program: Program, trace: list[tuple[str, str, float]]) -> tuple[list[str], list[tuple[str, float]]]:
    """The clauses of ``program`` a proof's ``trace`` used, in order, and the facts it used with their confidences."""
    used = sorted({int(i) for k, i, _ in trace if k == "clause"})
    return ([program.clauses[i - 1] for i in used if 0 < i <= len(program.clauses)],
            [(a, c) for k, a, c in trace if k == "fact"])


def _near_rank(trace: list[tuple[str, str, float]]) -> tuple[float, float]:
    """How nearly a near proof (``trace`` of a proof with absent facts at NEAR_MISS) proves its scene: the share
    of its program's facts the scene holds, and the per-fact (geometric mean) confidence of those it holds
    (1 when it holds none). The share ranks first: a program whose every fact is there, believed below its
    threshold, is a weak proof where one missing a fact is no proof; a program of four facts missing one
    matches more of the scene than one of two missing one, where the product would rank them alike."""
    held = [c for k, _, c in trace if k == "fact"]
    missing = sum(k == "missing" for k, _, _ in trace)
    if not held:
        return 0.0, 1.0
    return len(held) / (len(held) + missing), math.exp(sum(math.log(max(c, 1e-12)) for c in held) / len(held))


def _result_parts(r) -> tuple[str, float, list[tuple[str, str, float]]]:
    """[Label, Conf, [[Kind, Atom, Conf], ...]] as lv3d_bridge:classify/6 hands it back."""
    label, conf, trace = r
    return str(label), float(conf), [(str(k), str(a), float(c)) for k, a, c in trace]
