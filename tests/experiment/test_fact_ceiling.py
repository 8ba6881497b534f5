"""scripts/fact_ceiling.py: the best program on a study's facts, known with hindsight.

The examples' facts are read by lv3d.experiment.real_data (tested with the study); here they are given."""

import re
from pathlib import Path

import pytest

from lv3d.facts import Fact


@pytest.fixture(scope="module")
def fact_ceiling(load_script):
    return load_script("fact_ceiling")


def _fact(pred, *args, conf=1.0):
    return Fact(pred, tuple(args), conf)


def test_a_face_carries_its_facts_and_the_derived_predicates_times_its_face_of(fact_ceiling):
    facts = [_fact("object", "o"), _fact("face_of", "o", "f1", conf=0.9), _fact("face_of", "o", "f2"),
             _fact("quadrilateral", "f1", conf=0.8), _fact("square", "f2", conf=0.6),
             _fact("adjacent", "f1", "f2", conf=0.5), _fact("adjacent", "f2", "f1", conf=0.5),
             _fact("perpendicular", "f1", "f2", conf=0.4), _fact("perpendicular", "f2", "f1", conf=0.4),
             _fact("obtuse", "f2", "f1", conf=0.7),
             _fact("face_of", "p", "g1"), _fact("cylindrical", "g1")]  # another object's face: not o's
    props = fact_ceiling.face_properties(facts, "o")
    assert set(props) == {"f1", "f2"}
    assert props["f1"]["quadrilateral"] == pytest.approx(0.9 * 0.8)
    assert props["f1"]["perpendicular_neighbour"] == pytest.approx(0.9 * 0.5 * 0.4)  # adjacent x perpendicular
    assert props["f1"]["square_neighbour"] == pytest.approx(0.9 * 0.5 * 0.6)         # adjacent x the other's fact
    assert props["f2"]["quadrilateral_neighbour"] == pytest.approx(1.0 * 0.5 * 0.8)
    assert props["f2"]["obtuse_neighbour"] == pytest.approx(0.7)
    assert "obtuse_neighbour" not in props["f1"]
    assert fact_ceiling.face_properties(facts, None) == {}  # no object under the labelled pixel: no face


def test_the_derived_predicates_are_those_of_shape_bk(fact_ceiling):
    bk = (Path(__file__).resolve().parents[2] / "prolog" / "shape_bk.pl").read_text()
    face_level = set(re.findall(r"^bk_rule\((\w+)\(F\)", bk, flags=re.M))
    assert face_level == set(fact_ceiling.DERIVED)
    assert set(re.findall(r"^bk_rule\((\w+)\(O\)", bk, flags=re.M)) == {"right_corner"}  # face_of + the above


def _face(**props):
    return {"f": props}


def test_the_best_program_first_a_disjunction_where_no_clause_covers_every_positive(fact_ceiling):
    examples = [("box", _face(perpendicular_neighbour=0.9, rectangle=0.9)),
                ("box", _face(perpendicular_neighbour=0.9)),
                ("cylinder", _face(rectangle=0.9, cylindrical=0.8)),
                ("cylinder", {})]                                     # perceived nowhere: covered by none
    best = fact_ceiling.ceilings(examples, "box", literals=2, threshold=0.5)
    assert best[0][:4] == (1.0, "face_of(A, B), perpendicular_neighbour(B)", 2, 0)
    acc = {text: a for a, text, *_ in best}
    assert acc["face_of(A, B), rectangle(B)"] == 0.5                   # one box and one cylinder
    assert acc["face_of(A, B), perpendicular_neighbour(B), rectangle(B)"] == 0.75
    examples = [("cylinder", _face(cylindrical=0.9)), ("cylinder", _face(conical=0.9)), ("box", _face(square=1.0))]
    best = fact_ceiling.ceilings(examples, "cylinder", literals=1, threshold=0.5)
    assert best[0][:4] == (1.0, "face_of(A, B), conical(B) ; face_of(A, B), cylindrical(B)", 2, 0)


def test_a_clause_covers_where_the_product_of_its_confidences_reaches_the_threshold(fact_ceiling):
    examples = [("box", _face(quadrilateral=0.8, vertical=0.7)), ("cylinder", _face(vertical=0.9))]
    acc = {text: a for a, text, *_ in fact_ceiling.ceilings(examples, "box", literals=2, threshold=0.5)}
    assert acc["face_of(A, B), quadrilateral(B), vertical(B)"] == 1.0  # 0.56 >= 0.5: the box; not the cylinder
    acc = {text: a for a, text, *_ in fact_ceiling.ceilings(examples, "box", literals=2, threshold=0.6)}
    assert "face_of(A, B), quadrilateral(B), vertical(B)" not in acc  # 0.56 < 0.6: it covers nothing, as "false"
    assert acc["false"] == 0.5
    assert acc["face_of(A, B), quadrilateral(B)"] == 1.0


def test_bad_arguments_are_one_line(tmp_path, fact_ceiling):
    with pytest.raises(SystemExit, match="not a study's --out folder"):
        fact_ceiling.main([str(tmp_path)])
    (tmp_path / "config.yaml").write_text("name: real_objects\n")
    with pytest.raises(SystemExit, match="--modalities: unknown"):
        fact_ceiling.main([str(tmp_path), "--modalities", "lidar"])
    with pytest.raises(SystemExit, match="--threshold"):
        fact_ceiling.main([str(tmp_path), "--threshold", "0"])


def test_a_class_the_study_does_not_learn_is_named(tmp_path, fact_ceiling):
    (tmp_path / "config.yaml").write_text("name: ten\ndata: {classes: [cube, cylinder], per_class: 5}\n")
    with pytest.raises(SystemExit, match=r"--classes: \['bowl'\] not among the study's classes"):
        fact_ceiling.main([str(tmp_path), "--classes", "cube,bowl"])


def test_without_faces_answering_no_is_all_there_is(fact_ceiling):
    assert fact_ceiling.ceilings([("box", {}), ("cylinder", {})], "box", 2, 0.5) == [(0.5, "false", 0, 0)]


def test_answering_no_is_the_ceiling_where_no_clause_tells_the_class_apart(fact_ceiling):
    # a cuboid's faces are rectangles, and so are a cube's: no clause of these facts covers cuboids alone
    examples = [("cuboid", _face(rectangle=0.9)), ("cube", _face(rectangle=0.9, square=0.9)),
                ("cube", _face(rectangle=0.9, square=0.9)), ("prism", _face(triangle=0.9))]
    best = fact_ceiling.ceilings(examples, "cuboid", literals=2, threshold=0.5)
    assert best[0][:4] == (0.75, "false", 0, 0)
    assert all(tp > 0 for _, text, tp, _ in best if text != "false")  # no other program covering no positive


def test_each_group_of_conditions_with_its_own_examples_is_measured_once_beside_the_studys_figures(
        tmp_path, fact_ceiling, capsys, monkeypatch):
    (tmp_path / "config.yaml").write_text(
        "name: ten\ndata: {classes: [cube, cylinder], per_class: 5}\n"
        "sweep: {param: data.noise, values: [clean, realsense]}\nsystems: [lv3d-depth]\n")
    (tmp_path / "results.json").write_text(
        '{"conditions": {"noise=clean": {"systems": {"lv3d-depth": {"classes": {"cylinder": {"mean": 0.75}}}}}}}')
    asked = []

    def examples(cfg, run, modality):
        asked.append((cfg.data.noise, modality))
        read = 0.9 if cfg.data.noise == "clean" else 0.3  # the noisy preset's cylinders read weakly
        return [("cylinder", _face(cylindrical=read)), ("cylinder", _face(cylindrical=0.9)),
                ("cube", _face(square=0.9))]

    monkeypatch.setattr(fact_ceiling, "study_examples", examples)
    assert fact_ceiling.main([str(tmp_path), "--modalities", "depth", "--classes", "cylinder", "--top", "1"]) == 0
    assert asked == [("clean", "depth"), ("realsense", "depth")]
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "depth cylinder (noise=clean): 3 examples (2 cylinder); ceiling 100.0 %"
    assert out[1] == "  the study's lv3d-depth: noise=clean 75.0 %"
    assert out[2].split() == ["100.0", "%", "cylinder(A)", ":-", "face_of(A,", "B),", "cylindrical(B).", "covers",
                              "2/2", "cylinder,", "0/1", "others"]
    assert out[3] == "depth cylinder (noise=realsense): 3 examples (2 cylinder); ceiling 66.7 %"
