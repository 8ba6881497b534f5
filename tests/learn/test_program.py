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
