"""Arbiters of a multi-class model: where two classes' programs both prove the same training examples, a
program learned on the two classes alone tells them apart (lv3d.learn.model.Model._learn_arbiters)."""

from lv3d.facts import Fact, SceneFacts
from lv3d.learn import Model, Program


def _prism(name: str, end: str | None) -> SceneFacts:
    """A depth scene of a prism: two rectangular sides meeting at an obtuse angle and, where ``end`` names it
    (pentagon, hexagon), its end face; None: a view that hides the end."""
    o = f"{name}_o1"
    facts = [Fact("object", (o,), 1.0)]
    faces = [[("quadrilateral", 0.95), ("rectangle", 0.9)], [("quadrilateral", 0.95), ("rectangle", 0.9)]]
    if end:
        faces.append([(end, 0.95)])
    for j, props in enumerate(faces):
        f = f"{o}_f{j}"
        facts.append(Fact("face_of", (o, f), 0.99))
        facts += [Fact(p, (f,), c) for p, c in props]
    facts += [Fact("adjacent", (f"{o}_f0", f"{o}_f1"), 0.99), Fact("adjacent", (f"{o}_f1", f"{o}_f0"), 0.99),
              Fact("obtuse", (f"{o}_f0", f"{o}_f1"), 0.95), Fact("obtuse", (f"{o}_f1", f"{o}_f0"), 0.95)]
    return SceneFacts(name, "depth", facts, o)


def _box(name: str) -> SceneFacts:
    o = f"{name}_o1"
    facts = [Fact("object", (o,), 1.0)]
    for j in range(2):
        facts += [Fact("face_of", (o, f"{o}_f{j}"), 0.99), Fact("quadrilateral", (f"{o}_f{j}",), 0.95),
                  Fact("square", (f"{o}_f{j}",), 0.9)]
    facts += [Fact("perpendicular", (f"{o}_f0", f"{o}_f1"), 0.95), Fact("perpendicular", (f"{o}_f1", f"{o}_f0"), 0.95)]
    return SceneFacts(name, "depth", facts, o)


def _task() -> tuple[list[SceneFacts], list[str]]:
    """Four pentagonal and four hexagonal prisms, half of each seen without its end, and eight boxes: against
    every other class, "a rectangle with an obtuse neighbour" proves all four prisms of a class and the four of
    the other (J = 1 - 4/12), where "a pentagon face" proves two (J = 2/4), so both prism classes get the same
    program and the model cannot tell them apart."""
    scenes = [_prism(f"pent{i}", "pentagon" if i < 2 else None) for i in range(4)]
    scenes += [_prism(f"hex{i}", "hexagon" if i < 2 else None) for i in range(4)]
    scenes += [_box(f"box{i}") for i in range(8)]
    return scenes, ["pent"] * 4 + ["hex"] * 4 + ["box"] * 8


def test_rival_classes_get_arbiters_that_tell_them_apart():
    scenes, labels = _task()
    model = Model.fit(scenes, labels, settings={"disjunctions": 0}, seed=0)
    assert str(model.programs["pent"]).replace("pent(", "hex(") == str(model.programs["hex"])  # alike
    assert set(model.arbiters) == {("pent", "hex"), ("hex", "pent")}  # the boxes were never confused
    assert "pentagon(B)" in str(model.arbiters[("pent", "hex")])
    assert "hexagon(B)" in str(model.arbiters[("hex", "pent")])
    for name, end, label in (("t1", "pentagon", "pent"), ("t2", "hexagon", "hex")):
        scene = _prism(name, end)
        assert model.predict(scene)[0] == label and model.answer(scene)[2] == "arbiter"
        e = model.explain(scene)
        assert e.rival == ("hex" if label == "pent" else "pent")
        assert f"{end}({name}_o1_f2)" in [a for a, _ in e.rival_facts]
        assert "rather than a" in str(e) and f"{end}(B)" in str(e)


def test_without_the_end_the_arbiters_leave_the_ranking_alone():
    scenes, labels = _task()
    model = Model.fit(scenes, labels, settings={"disjunctions": 0}, seed=0)
    scene = _prism("t3", None)
    ranked = [p["label"] for p in model._proofs(scene)]
    assert set(ranked) == {"pent", "hex"} and model.predict(scene)[0] == ranked[0]
    assert model.explain(scene).rival is None


def test_a_model_without_rivals_has_no_arbiters():
    scenes = [_prism(f"pent{i}", "pentagon") for i in range(4)] + [_box(f"box{i}") for i in range(4)]
    model = Model.fit(scenes, ["pent"] * 4 + ["box"] * 4, settings={"disjunctions": 0}, seed=0)
    assert model.arbiters == {}
    one = Model.fit(*_task(), classes=["pent"], settings={"disjunctions": 0}, seed=0)  # a class task
    assert one.arbiters == {}


def test_arbiters_are_saved_and_loaded_with_the_model(tmp_path):
    scenes, labels = _task()
    model = Model.fit(scenes, labels, settings={"disjunctions": 0}, seed=0)
    model.save(tmp_path / "m")
    back = Model.load(tmp_path / "m")
    assert {k: str(p) for k, p in back.arbiters.items()} == {k: str(p) for k, p in model.arbiters.items()}
    assert back.arbiters[("pent", "hex")].score == model.arbiters[("pent", "hex")].score
    scene = _prism("t4", "hexagon")
    assert back.predict(scene) == model.predict(scene)


def test_only_one_arbiter_proving_reorders_the_first_two():
    a = Program("a_over_b", ("a_over_b(A) :- face_of(A, B), pentagon(B).",))
    b = Program("b_over_a", ("b_over_a(A) :- face_of(A, B), hexagon(B).",))
    model = Model({}, arbiters={("a", "b"): a, ("b", "a"): b})
    ranked = [{"label": "b", "conf": 0.9}, {"label": "a", "conf": 0.9}, {"label": "c", "conf": 0.5}]
    trace = [("clause", "1", 1.0), ("fact", "pentagon(f)", 0.9)]
    assert [p["label"] for p in model._arbitrate(ranked, {"a_over_b": trace})] == ["a", "b", "c"]
    assert model._arbitrate(ranked, {"a_over_b": trace})[0]["rival"] == "b"
    assert model._arbitrate(ranked, {}) == ranked  # neither proves
    assert model._arbitrate(ranked, {"a_over_b": trace, "b_over_a": trace}) == ranked  # both prove
    kept = model._arbitrate(ranked, {"b_over_a": trace})  # the first is confirmed, and says why
    assert [p["label"] for p in kept] == ["b", "a", "c"] and kept[0]["rival"] == "a"


def test_the_arbiters_setting_turns_them_off():
    scenes, labels = _task()
    model = Model.fit(scenes, labels, settings={"disjunctions": 0, "arbiters": False}, seed=0)
    assert model.arbiters == {} and model.settings["arbiters"] is False
    assert model.predict(_prism("t5", "pentagon"))[0] in ("pent", "hex")  # proved by both, as the ranking has it


def test_a_pairs_only_arbiter_decides_by_failing_too():
    # the other class's search found no arbiter: the one there is puts its class first when it proves the scene
    # and the other class first when it does not (it was learned on the two classes alone)
    a = Program("a_over_b", ("a_over_b(A) :- face_of(A, B), pentagon(B).",))
    model = Model({}, arbiters={("a", "b"): a})
    ranked = [{"label": "a", "conf": 0.9, "trace": []}, {"label": "b", "conf": 0.8, "trace": []},
              {"label": "c", "conf": 0.5, "trace": []}]
    trace = [("clause", "1", 1.0), ("fact", "pentagon(f)", 0.9)]
    kept = model._arbitrate(ranked, {"a_over_b": trace})
    assert [p["label"] for p in kept] == ["a", "b", "c"] and kept[0]["rival_trace"] == trace
    flipped = model._arbitrate(ranked, {})
    assert [p["label"] for p in flipped] == ["b", "a", "c"]
    assert flipped[0]["rival"] == "a" and flipped[0]["rival_trace"] is None
    assert model._arbitrate(ranked[1:], {}) == ranked[1:]  # b and c: no arbiter of theirs


def test_an_answer_a_failing_arbiter_decided_names_what_failed():
    scenes, labels = _task()
    model = Model.fit(scenes, labels, settings={"disjunctions": 0}, seed=0)
    del model.arbiters[("hex", "pent")]  # as where the search finds no hexagonal prism's arbiter
    scene = _prism("t6", "hexagon")  # proved by both prisms' programs, and by no pentagon arbiter
    assert model.answer(scene) == ("hex", model.answer(scene)[1], "arbiter")
    e = model.explain(scene)
    assert e.rival == "pent" and e.rival_fails and e.rival_facts == []
    text = str(e)
    assert "rather than a pent (whose program proves it too), because no clause of what tells a pent from a hex " \
           "proves it:" in text and "    pent_over_hex(A) :-\n        face_of(A, B),\n        pentagon(B)." in text
