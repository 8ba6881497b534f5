"""Classic MIL tasks from prolog/tasks/, the plunit suite, and bad task files."""

import shutil
import subprocess
import time

import pytest

import prolog
from lv3d.errors import InputError
from lv3d.learn import LearnError, learn_task


def task(name):
    return prolog.source(f"tasks/{name}.pl")


def test_grandparent_invents_parent():
    clauses = learn_task(task("grandparent"))
    assert clauses == ["grandparent(A,B):-grandparent_1(A,C),grandparent_1(C,B).",
                       "grandparent_1(A,B):-mother(A,B).", "grandparent_1(A,B):-father(A,B)."]


def test_ancestor_is_recursive():
    assert learn_task(task("ancestor")) == ["ancestor(A,B):-parent(A,B).", "ancestor(A,B):-parent(A,C),ancestor(C,B)."]


def test_even_and_odd_learned_together_by_mutual_recursion():
    clauses = learn_task(task("even_odd"))
    assert set(clauses) == {"even(A):-zero(A).", "even(A):-prev(A,B),odd(B).", "odd(A):-prev(A,B),even(B)."}


def test_plunit_suite_passes():
    swipl = shutil.which("swipl")
    if swipl is None:
        pytest.skip("swipl not on PATH")
    r = subprocess.run([swipl, "-g", "run_tests", "-t", "halt", str(prolog.source("test_mil.pl"))],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr


@pytest.mark.parametrize("text, problem", [
    ("body_pred(mother/2).\npos(gp(a, b)", "syntax error at line"),
    (":- shell('ls').\n", "a task file is data"),
    ("p(a).\nbody_pred(p/1).\nmetarules([base]).\n", "no positive examples"),
    ("p(a).\nbody_pred(p/1).\nmetarules([sideways]).\npos(q(a)).\n", "unknown metarule"),
    ("p(a).\nbody_pred(p/1).\nmetarules([base]).\nsetting(speed(9)).\npos(q(a)).\n", "unknown setting"),
])
def test_malformed_task_file_names_file_and_problem(tmp_path, text, problem):
    f = tmp_path / "bad.pl"
    f.write_text(text)
    with pytest.raises(InputError) as e:
        learn_task(f)
    assert e.value.where == str(f) and problem in e.value.problem


def test_missing_task_file(tmp_path):
    with pytest.raises(InputError, match="no such task file"):
        learn_task(tmp_path / "none.pl")


def test_search_that_reaches_its_time_limit_is_an_error(tmp_path):
    # many metarules and inventions over a background where no program separates the examples
    f = tmp_path / "hard.pl"
    f.write_text("body_pred(e/2).\nmetarules([ident, inverse, chain, precon, postcon]).\n"
                 "setting(max_clauses(8)).\nsetting(max_literals(16)).\nsetting(max_inventions(4)).\n"
                 + "".join(f"e(n{i}, n{(i * 7 + 3) % 13}).\n" for i in range(13))
                 + "pos(t(n1, n2)).\npos(t(n3, n5)).\npos(t(n8, n0)).\nneg(t(n2, n1)).\nneg(t(n5, n3)).\n")
    t0 = time.monotonic()
    with pytest.raises(LearnError, match="time limit of 0.5 s"):
        learn_task(f, time_limit=0.5)
    assert time.monotonic() - t0 < 10


GRANDPARENT = ["grandparent(A,B):-grandparent_1(A,C),grandparent_1(C,B).",
               "grandparent_1(A,B):-mother(A,B).", "grandparent_1(A,B):-father(A,B)."]


def test_noisy_search_learns_through_a_wrong_label_and_a_doubtful_fact():
    with pytest.raises(LearnError, match="no program"):
        learn_task(task("noisy_grandparent"))
    assert learn_task(task("noisy_grandparent"), mode="noisy") == GRANDPARENT


@pytest.mark.parametrize("settings, mode, problem", [
    ({"samples": 4}, "exact", "setting samples is read only by the noise-tolerant search"),
    ({"miss": 0.1}, "noisy", "setting miss is not read when learning"),
])
def test_a_setting_the_search_does_not_read_is_refused(settings, mode, problem):
    with pytest.raises(InputError, match=problem):
        learn_task(task("grandparent"), settings=settings, mode=mode)


def test_a_fact_with_a_confidence_below_the_threshold_is_not_used(tmp_path):
    f = tmp_path / "t.pl"
    f.write_text("body_pred(p/1).\nmetarules([base]).\n0.4::p(a).\np(b).\npos(t(b)).\n")
    assert learn_task(f) == ["t(A):-p(A)."]
    f.write_text("body_pred(p/1).\nmetarules([base]).\n0.4::p(a).\np(b).\npos(t(a)).\n")
    with pytest.raises(LearnError, match="no program"):
        learn_task(f)
    assert learn_task(f, settings={"threshold": 0.3}) == ["t(A):-p(A)."]


def test_p_and_p_with_one_more_argument_do_not_collide(tmp_path):
    # trains: load/3 is a body predicate and load/2 a plain one; neither is a fact with a confidence
    f = tmp_path / "t.pl"
    f.write_text("body_pred(load/2).\nmetarules([base, part]).\nload(c1, tri).\nload(c1, tri, 2).\n"
                 "tri(tri).\nbody_pred(tri/1).\npos(t(c1)).\nneg(t(c2)).\n")
    assert learn_task(f) == ["t(A):-load(A,B),tri(B)."]
