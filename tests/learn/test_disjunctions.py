"""Two-clause shape programs (setting ``disjunctions``): positives whose views need different clauses."""

from lv3d.facts import Fact, SceneFacts
from lv3d.learn import fit


def _scene(k: int, sides: str) -> SceneFacts:
    """One object with one face of the given kind ('triangle', 'pentagon', 'quadrilateral')."""
    s, o, f = f"s{k:06d}", f"s{k:06d}_o1", f"s{k:06d}_o1_f1"
    return SceneFacts(s, "rgbd", [Fact("object", (o,), 1.0), Fact("face_of", (o, f), 1.0),
                                  Fact(sides, (f,), 0.95)], target=o)


def _task():
    kinds = ["triangle"] * 4 + ["pentagon"] * 4 + ["quadrilateral"] * 6
    labels = ["odd"] * 8 + ["even"] * 6
    return [_scene(k, s) for k, s in enumerate(kinds)], labels


def test_pairs_cover_positives_one_clause_cannot():
    scenes, labels = _task()
    # enough samples of two positives that both one-clause hypotheses are proposed
    prog = fit(scenes, labels, "odd", settings={"disjunctions": 20, "samples": 30})
    assert len(prog.clauses) == 2
    assert prog.score["tp"] == 8 and prog.score["fp"] == 0
    assert {"triangle", "pentagon"} <= {w for c in prog.clauses for w in ("triangle", "pentagon") if w in c}


def test_off_keeps_one_clause():
    scenes, labels = _task()
    prog = fit(scenes, labels, "odd", settings={"disjunctions": 0})
    assert len(prog.clauses) == 1
    assert prog.score["tp"] == 4 and prog.score["fp"] == 0
