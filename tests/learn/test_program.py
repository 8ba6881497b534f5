"""Programs saved as readable .pl files and loaded back as checked data."""

import pytest

from lv3d.errors import InputError
from lv3d.learn import Model, Program


def test_model_save_load_round_trip(tmp_path, shape_train):
    x, y = shape_train
    model = Model.fit(x, y, seed=0)
    model.save(tmp_path / "m")
    text = (tmp_path / "m" / "cube.pl").read_text()
    assert text.startswith("% lv3d program: target cube/1") and "cube(A) :-" in text
    back = Model.load(tmp_path / "m")
    assert {k: p.clauses for k, p in back.programs.items()} == {k: p.clauses for k, p in model.programs.items()}
    assert [back.predict(s)[0] for s in x] == [model.predict(s)[0] for s in x]


def test_invented_predicates_defined_in_file_are_known(tmp_path):
    f = tmp_path / "cube.pl"
    f.write_text("cube(A) :- face_of(A, B), cube_1(B).\ncube_1(A) :- square(A), square_neighbour(A).\n")
    assert Program.load(f).clauses[1].startswith("cube_1(A)")


@pytest.mark.parametrize("text, problem", [
    ("cube(A) :- face_of(A, B), shell(B).\n", "unknown predicate shell/1"),
    ("cube(A) :- face_of(A, B), square(B, B).\n", "unknown predicate square/2"),
    ("cube(A) :- face_of(A, B) square(B).\n", "syntax error at line 1"),
    (":- initialization(halt).\ncube(A) :- square(A).\n", "directives are not allowed"),
    ("pyramid(A) :- face_of(A, B), triangle(B).\n", "does not define cube/1"),
    ("", "no clauses"),
])
def test_bad_program_file_is_an_input_error(tmp_path, text, problem):
    f = tmp_path / "cube.pl"
    f.write_text(text)
    with pytest.raises(InputError) as e:
        Program.load(f)
    assert e.value.where == str(f) and problem in e.value.problem


def test_missing_model_dir(tmp_path):
    with pytest.raises(InputError, match="no model.json"):
        Model.load(tmp_path)


def test_a_class_named_like_a_fact_predicate_is_learned_under_another_name(tmp_path):
    from lv3d.facts import Fact, SceneFacts

    def scene(i, shape):
        o, f = f"o{i}", f"f{i}"
        return SceneFacts(f"s{i}", "rgb", [Fact("object", (o,), 1.0), Fact("face_of", (o, f), 1.0),
                                           Fact(shape, (f,), 0.9)], o)

    xs = [scene(0, "triangle"), scene(1, "triangle"), scene(2, "pentagon"), scene(3, "hexagon")]
    model = Model.fit(xs, ["triangle", "triangle", "other", "other"], classes=["triangle"])
    p = model.programs["triangle"]
    assert p.target == "is_triangle" and p.label == "triangle" and p.clauses[0].startswith("is_triangle(A) :-")
    assert model.predict(xs[0]) == ("triangle", 0.9) and model.predict(xs[2])[0] == "unknown"
    model.save(tmp_path / "m")
    assert "% label: triangle" in (tmp_path / "m" / "is_triangle.pl").read_text()
    assert Model.load(tmp_path / "m").predict(xs[1]) == ("triangle", 0.9)
