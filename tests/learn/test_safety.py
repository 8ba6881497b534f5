"""Tasks and programs are data: what a task file's Prolog may call is checked before any of it runs,
and every search and classification ends within its time and memory limits with one line."""

import os
import stat
import time

import pytest

from lv3d.errors import InputError
from lv3d.facts import Fact, SceneFacts
from lv3d.learn import LearnError, Model, Program
from lv3d.learn import task as tasks
from lv3d.learn.task import learn_task, run_task

HEAD = "body_pred(p/1).\nmetarule([P,Q], [P,A], [[Q,A]]).\n"
GOAL = "a :- learn([t(a)], []).\n"


@pytest.mark.parametrize("body, line, problem", [
    ("p(X) :- shell('touch PWNED'), X = a.\n", 3, "clause p/1 calls shell/1, which a task may not call"),
    ("p(a).\nuser:message_hook(_, _, _) :- shell(ls).\n", 4, "module-qualified (user)"),
    ("p(X) :- catch(loop(X), _, p(X)).\nloop(X) :- loop(X).\n", 3, "calls catch/3"),
    ("p(_) :- halt.\n", 3, "calls halt/0"),
    ("p(X) :- assertz(q(X)).\n", 3, "calls assertz/1"),
    ("p(X) :- open(X, read, _).\n", 3, "calls open/3"),
    ("p(X) :- writeln(X).\n", 3, "calls writeln/1 outside a learning goal"),
    ("'$mil_own'(shell, 1).\np(_) :- shell(ls).\n", 3, "names starting with $ are reserved"),
    ("bk_rule(p(X), [q(X)]) :- shell(ls).\nq(a).\n", 3, "calls shell/1"),
    ("p(X) :- lists:append(X, [], X).\n", 3, "module-qualified goal"),
    ("p(X) :- maplist(shell, [X]).\n", 3, "calls shell/1"),
])
def test_unsafe_task_code_is_refused_before_it_runs(tmp_path, body, line, problem):
    f = tmp_path / "t.pl"
    f.write_text(HEAD + body + GOAL)
    with pytest.raises(InputError) as e:
        learn_task(f)
    msg = str(e.value)
    assert e.value.where == str(f) and msg.count("\n") == 0
    assert f"line {line}:" in msg and problem in msg, msg
    assert not (tmp_path / "PWNED").exists()


def test_a_goal_built_at_run_time_is_checked_when_called(tmp_path):
    f = tmp_path / "t.pl"
    f.write_text(HEAD + "p(_) :- G = halt, call(G).\n" + GOAL)
    run = run_task(f, time_limit=5)
    assert run.goals[0].error and "a goal built at run time calls halt/0" in run.goals[0].error


def test_safe_meta_calls_run(tmp_path):
    f = tmp_path / "t.pl"
    f.write_text(HEAD + "p(X) :- C = q, call(C, X), maplist(q, [X]), findall(Y, q(Y), [_|_]).\nq(a).\n" + GOAL)
    assert learn_task(f) == ["t(A):-p(A)."]


def test_a_missing_body_predicate_is_a_warning(tmp_path):
    f = tmp_path / "t.pl"
    f.write_text("body_pred(nope/1).\n" + HEAD + "p(a).\n" + GOAL)
    run = run_task(f)
    assert any("body_pred nope/1" in w for w in run.warnings)
    assert run.goals[0].clauses == ("t(A):-p(A).",)


def test_an_endless_background_stops_at_the_time_limit(tmp_path):
    f = tmp_path / "t.pl"
    f.write_text(HEAD + "p(X) :- between(1, inf, _), X == b.\n" + GOAL)
    t0 = time.monotonic()
    with pytest.raises(LearnError, match="time limit of 1"):
        learn_task(f, time_limit=1)
    assert time.monotonic() - t0 < 15


def test_a_background_that_fills_memory_is_stopped(tmp_path):
    f = tmp_path / "t.pl"
    f.write_text(HEAD + "p(X) :- numlist(1, 500000000, L), length(L, X).\n" + GOAL)
    run = run_task(f, time_limit=30, memory_mb=128)
    assert run.goals[0].kind == "memory", run.goals[0]


@pytest.mark.parametrize("text", ["p(" + "[" * 300000 + "]" * 300000 + ").\n", "p(" + "1+" * 300000 + "1).\n"])
def test_deeply_nested_terms_are_an_error_not_a_crash(tmp_path, text):
    f = tmp_path / "t.pl"
    f.write_text(HEAD + text + GOAL)
    with pytest.raises((InputError, LearnError)) as e:
        run_task(f, memory_mb=256)
    assert "nested" in str(e.value) or "memory" in str(e.value)


def test_a_learner_that_ignores_its_time_limit_is_stopped_from_outside(tmp_path, monkeypatch):
    fake = tmp_path / "swipl"
    fake.write_text("#!/bin/sh\ntrap '' INT TERM ALRM\necho 'goal\ta'\nwhile :; do sleep 1; done\n")
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("LV3D_SWIPL", str(fake))
    monkeypatch.setattr(tasks, "GRACE_S", 1.0)
    monkeypatch.setattr(tasks, "WALL_FACTOR", 1.0)  # it sleeps: blocked, it is stopped by the wall clock
    f = tmp_path / "t.pl"
    f.write_text(HEAD + "p(a).\n" + GOAL)
    t0 = time.monotonic()
    run = run_task(f, time_limit=0.5)
    assert time.monotonic() - t0 < 10
    assert run.goals[0].kind == "time_limit" and "was stopped" in run.goals[0].error


def _fake_swipl(tmp_path, monkeypatch, script):
    fake = tmp_path / "swipl"
    fake.write_text("#!/bin/sh\ntrap '' INT TERM ALRM\n" + script)
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("LV3D_SWIPL", str(fake))
    monkeypatch.setattr(tasks, "GRACE_S", 1.0)
    f = tmp_path / "t.pl"
    f.write_text(HEAD + "p(a).\n" + GOAL)
    return f


def test_a_learner_that_spins_past_its_time_limit_is_stopped_by_its_cpu_time(tmp_path, monkeypatch):
    f = _fake_swipl(tmp_path, monkeypatch, "printf 'goal\\ta\\n'\nwhile :; do :; done\n")
    monkeypatch.setattr(tasks, "WALL_FACTOR", 100.0)  # the wall clock's stop would come at 200 s
    t0 = time.monotonic()
    run = run_task(f, time_limit=0.5)
    assert time.monotonic() - t0 < 60  # two CPU seconds allowed
    assert run.goals[0].kind == "time_limit" and "was stopped" in run.goals[0].error


def test_a_learner_slowed_by_a_busy_machine_is_not_stopped_within_its_cpu_allowance(tmp_path, monkeypatch):
    # sleeping stands for a process that gets no CPU: 3 s of wall time past the 1.5 s of CPU it may use first
    f = _fake_swipl(tmp_path, monkeypatch, "sleep 3\nprintf 'goal\\ta\\nnone\\ntime\\t0.1\\t3.0\\n'\n")
    run = run_task(f, time_limit=0.5)
    assert run.goals == (tasks.GoalResult("a", None, None, None, 0.1, 3.0),) and not run.warnings


def test_the_cpu_allowance_of_a_process_that_has_ended_keeps_what_it_used():
    import subprocess
    import sys

    # 0.3 s of CPU, then 0.5 s asleep, in which the allowance reads all of it
    code = "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.3: pass\ntime.sleep(0.5)"
    proc = subprocess.Popen([sys.executable, "-c", code])
    allowance = tasks._Allowance(proc, 0.1)
    seen = 0.0
    while proc.poll() is None:
        seen = allowance._cpu()
        time.sleep(0.02)
    proc.wait()
    assert seen >= 0.3
    assert allowance._cpu() >= seen and allowance.spent()  # ended and reaped: its last reading stays, never 0


def test_a_learner_that_hangs_after_its_goals_keeps_their_results(tmp_path, monkeypatch):
    monkeypatch.setattr(tasks, "WALL_FACTOR", 1.0)
    f = _fake_swipl(tmp_path, monkeypatch, "printf 'goal\\ta\\nclause\\tt(A):-p(A).\\ntime\\t0.1\\t0.1\\n'\n"
                                           "while :; do sleep 1; done\n")
    run = run_task(f, time_limit=0.5)
    assert run.goals[0].clauses == ("t(A):-p(A).",)
    assert len(run.warnings) == 1 and "stopped after 1 goals" in run.warnings[0]


def test_a_deep_program_file_is_refused_without_crashing(tmp_path):
    f = tmp_path / "cube.pl"
    f.write_text("cube(A) :- face_of(A, B), square(" + "[" * 50000 + "]" * 50000 + ").\n")
    with pytest.raises(InputError, match="nested"):
        Program.load(f)


def test_classifying_with_a_loose_program_stops_at_the_time_limit():
    # twelve faces, each adjacent to every other; a program of twelve face_of/adjacent pairs has
    # 12^12 proofs to compare
    faces = [f"f{i}" for i in range(12)]
    facts = [Fact("object", ("o1",), 1.0)] + [Fact("face_of", ("o1", f), 0.9) for f in faces]
    facts += [Fact("adjacent", (a, b), 0.9) for a in faces for b in faces if a != b]
    scene = SceneFacts("s1", "rgb", facts, "o1")
    body = ", ".join(f"face_of(A, F{i}), adjacent(F{i}, G{i})" for i in range(12))
    prog = Program("loose", (f"loose(A) :- {body}.",), {"threshold": 0.0}, "rgb")
    model = Model({"loose": prog}, settings={"time_limit": 1})
    t0 = time.monotonic()
    with pytest.raises(LearnError, match="time limit of 1"):
        model.predict(scene)
    assert time.monotonic() - t0 < 10


def test_swipl_is_found():
    assert os.access(tasks.swipl(), os.X_OK)
