"""Near answers by resemblance: a multi-class model names, for an object no program proves, the class of the
training object whose facts its own resemble most (lv3d.learn.resemblance, Model._decide)."""

import json

import pytest

from lv3d.facts import Fact, SceneFacts
from lv3d.learn import Model
from lv3d.learn.resemblance import (FACES, Reference, closeness, contrast, distance, nearest,
                                    profile, resemble)


def _scene(name: str, faces: list[list[tuple[str, float]]], pairs: list[tuple[str, int, int, float]] = ()
           ) -> SceneFacts:
    """A depth scene of one object with ``faces`` (each its properties and confidences) and ``pairs``
    (relation, face i, face j, confidence), each relation stated both ways."""
    o = f"{name}_o1"
    facts = [Fact("object", (o,), 1.0)]
    for j, props in enumerate(faces):
        facts.append(Fact("face_of", (o, f"{o}_f{j}"), 0.99))
        facts += [Fact(p, (f"{o}_f{j}",), c) for p, c in props]
    for rel, i, j, c in pairs:
        facts += [Fact(rel, (f"{o}_f{i}", f"{o}_f{j}"), c), Fact(rel, (f"{o}_f{j}", f"{o}_f{i}"), c)]
    return SceneFacts(name, "depth", facts, o)


def _tetra(name: str) -> SceneFacts:  # two triangles at an acute angle
    return _scene(name, [[("triangle", 0.95)], [("triangle", 0.9)]], [("adjacent", 0, 1, 0.99), ("acute", 0, 1, 0.9)])


def _can(name: str) -> SceneFacts:  # a cylindrical side and a circular cap
    return _scene(name, [[("cylindrical", 0.9)], [("circular", 0.9)]], [("adjacent", 0, 1, 0.99)])


def _prism(name: str) -> SceneFacts:  # a triangle end at a right angle to a rectangle side
    return _scene(name, [[("triangle", 0.9)], [("rectangle", 0.9)]], [("adjacent", 0, 1, 0.99),
                                                                     ("perpendicular", 0, 1, 0.95)])


def _box(name: str) -> SceneFacts:  # two rectangles at a right angle
    return _scene(name, [[("rectangle", 0.9)], [("rectangle", 0.9)]], [("adjacent", 0, 1, 0.99),
                                                                      ("perpendicular", 0, 1, 0.95)])


def test_profile_keeps_the_best_confidence_of_each_predicate_on_the_objects_own_faces():
    s = _scene("a", [[("triangle", 0.6), ("horizontal", 0.9)], [("triangle", 0.8)]], [("acute", 0, 1, 0.7)])
    s.facts.append(Fact("triangle", ("b_o1_f0",), 1.0))  # another object's face: not this one's
    p = profile(s)
    assert p == {"triangle": 0.8, "acute": 0.7, FACES: 0.5}  # no face_of, object, horizontal; 2 faces of 4
    many = _scene("m", [[("square", 0.9)]] * 6)
    assert profile(many)[FACES] == 1.0  # the count saturates at four faces
    assert profile(SceneFacts("none", "depth", [], None)) == {}


def test_distance_nearest_and_contrast():
    a, b = {"triangle": 0.9, FACES: 0.25}, {"triangle": 0.5, "acute": 0.8, FACES: 0.5}
    assert distance(a, b) == pytest.approx(0.4 + 0.8 + 0.25)
    assert distance(a, a) == 0.0
    refs = [Reference("x", "tetra", b), Reference("y", "can", {"cylindrical": 0.9, FACES: 0.25})]
    ref, d = nearest(a, refs)
    assert ref.object == "x" and d == pytest.approx(1.45)
    assert nearest(a, []) is None
    tie = [Reference("q", "b", {}), Reference("p", "a", {})]  # ties: by class, then object
    assert nearest({}, tie)[0].object == "p"
    shared, differ = contrast(a, refs[0])
    assert shared == [("triangle", 0.9, 0.5)] and differ == [("acute", 0.0, 0.8)]


def test_closeness_is_the_share_of_the_two_nearest_distances_held_by_the_other_class():
    refs = [Reference("x", "tetra", {"triangle": 0.9}), Reference("x2", "tetra", {"triangle": 0.1}),
            Reference("y", "can", {"cylindrical": 0.9})]
    prof = {"triangle": 0.7}
    # nearest tetra at 0.2 (x), nearest can at 0.7 + 0.9 = 1.6: 1.6 / (0.2 + 1.6)
    found = resemble(prof, refs)
    assert (found.ref.object, found.other.object) == ("x", "y")
    assert (found.distance, found.other_distance) == pytest.approx((0.2, 1.6))
    assert found.confidence == pytest.approx(1.6 / 1.8) == closeness(0.2, 1.6)
    assert closeness(1.6, 0.2) == pytest.approx(0.2 / 1.8)
    assert closeness(0.0, 0.0) == 0.5  # both at 0: a tie
    alone = resemble(prof, refs[:2])  # no other class to mistake it for
    assert alone.other is None and alone.other_distance is None and alone.confidence == 1.0 == closeness(0.2, None)
    assert resemble(prof, []) is None


def _model() -> Model:
    """Tetrahedra, triangular prisms, cans and boxes: a triangle face alone tells no class from the others (the
    prisms show one too), so the tetrahedron's and the prism's programs rest on a neighbour."""
    scenes = [make(f"{k}{i}") for k, make in (("t", _tetra), ("p", _prism), ("c", _can), ("b", _box)) for i in range(3)]
    return Model.fit(scenes, [c for c in ("tetra", "prism", "can", "box") for _ in range(3)],
                     settings={"disjunctions": 0}, seed=0)


def test_an_object_no_program_proves_gets_the_class_of_the_training_object_it_resembles():
    model = _model()
    assert len(model.references) == 12
    # one triangle face seen head-on: no tetrahedron program (it needs a neighbour) nor any other proves it
    one = _scene("one", [[("triangle", 0.95)]])
    assert model._proofs(one) == []
    label, conf, how = model.answer(one)
    assert (label, how) == ("tetra", "near")
    assert conf == pytest.approx(resemble(profile(one), model.references).confidence) and 0.5 < conf < 1
    e = model.explain(one)
    # the tetrahedron's program needs a neighbour face, which a near proof cannot make up: it shows none
    assert e.confidence == conf and e.clauses == [] and e.near_confidence == 0.0
    r = e.resembles
    assert r.ref.object.startswith("t") and r.ref.label == "tetra"
    assert ("triangle", 0.95, 0.95) in e.shared
    text = str(e)
    assert "no program proves it" in text and f"resembles {r.ref.object}, a tetra" in text
    assert "both show triangle" in text and "which it misses" not in text
    # the nearest training object of another class, whose distance the confidence weighs against
    assert r.other.label != "tetra" and r.other_distance == pytest.approx(r.distance * conf / (1 - conf))
    assert f"of another class, {r.other.object}, a {r.other.label}, at {r.other_distance:.2f}" in text
    # a round cap beside a rectangle: the can's program (a cylindrical face) misses it by one fact, which its
    # explanation shows with the near proof's confidence beside the resemblance's
    cap = _scene("cap", [[("circular", 0.9)], [("rectangle", 0.9)]], [("adjacent", 0, 1, 0.99)])
    label, conf, how = model.answer(cap)
    assert (label, how) == ("can", "near") and conf == pytest.approx(resemble(profile(cap), model.references).confidence)
    e = model.explain(cap)
    assert e.missing and 0 < e.near_confidence < 0.5
    assert f"the can's program, which it misses (near proof {e.near_confidence:.3f}):" in str(e)
    # a proved object is answered by its proof, as before
    assert model.answer(_can("c9"))[::2] == ("can", "proof")


def test_references_are_saved_and_loaded_and_a_class_task_keeps_none(tmp_path):
    model = _model()
    model.save(tmp_path / "m")
    again = Model.load(tmp_path / "m")
    assert again.references == model.references
    one = _scene("one", [[("triangle", 0.95)]])
    assert again.answer(one) == model.answer(one)
    task = Model.fit([_tetra("t0"), _tetra("t1"), _prism("p0"), _prism("p1")], ["tetra", "tetra", "prism", "prism"],
                     classes=["tetra"], settings={"disjunctions": 0}, seed=0)
    assert task.references == [] and task.answer(one)[0] == "unknown"


def test_a_malformed_reference_names_the_model_file(tmp_path):
    model = _model()
    model.save(tmp_path / "m")
    meta = json.loads((tmp_path / "m" / "model.json").read_text())
    meta["references"] = [{"object": "t0_o1", "class": "tetra"}]  # no profile
    (tmp_path / "m" / "model.json").write_text(json.dumps(meta))
    with pytest.raises(Exception, match="model.json.*malformed reference"):
        Model.load(tmp_path / "m")


def test_a_class_whose_search_found_no_program_is_still_named_by_resemblance():
    model = _model()
    lone = Model({"can": model.programs["can"]}, references=model.references)  # the others' searches found none
    label, conf, how = lone.answer(_box("b9"))
    assert (label, conf, how) == ("box", 1.0, "near")  # it equals the training boxes, no other class's object
    e = lone.explain(_box("b9"))
    assert e.clauses == [] and e.resembles.ref.label == "box" and "program, which it misses" not in str(e)
    assert Model({"can": model.programs["can"]}).answer(_box("b9"))[0] == "unknown"  # no references: a class task
