"""The ``lv3d mil`` and ``lv3d learn`` commands."""

import pytest

import prolog
from lv3d.cli import main


def test_mil_prints_program(capsys):
    assert main(["mil", str(prolog.source("tasks/ancestor.pl"))]) == 0
    out = capsys.readouterr().out
    assert out.splitlines() == ["ancestor(A,B):-parent(A,B).", "ancestor(A,B):-parent(A,C),ancestor(C,B)."]


def test_mil_bad_file_is_one_line_and_exit_2(tmp_path, capsys):
    f = tmp_path / "t.pl"
    f.write_text("pos(p(a)\n")
    assert main(["mil", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"lv3d: error: {f}: syntax error") and "\n" not in err


def test_mil_time_limit_is_one_line_and_exit_2(tmp_path, capsys):
    f = tmp_path / "t.pl"
    f.write_text("body_pred(e/2).\nmetarules([ident, inverse, chain, precon, postcon]).\n"
                 "setting(max_clauses(8)).\nsetting(max_literals(16)).\nsetting(max_inventions(4)).\n"
                 + "".join(f"e(n{i}, n{(i * 5 + 2) % 11}).\n" for i in range(11))
                 + "pos(t(n1, n2)).\npos(t(n3, n4)).\nneg(t(n2, n1)).\n")
    assert main(["mil", str(f), "--time-limit", "0.3"]) == 2
    assert "time limit of 0.3 s" in capsys.readouterr().err


@pytest.mark.slow
def test_learn_fit_then_predict_on_a_rendered_data_set(tmp_path, capsys):
    from lv3d.render.dataset import make_dataset

    data = make_dataset(tmp_path / "data", ["cube", "square_pyramid", "pentagonal_prism"], 2, "clean", 7,
                        workers=1, width=320, height=240, progress=False)
    assert main(["learn", "fit", "--data", str(data), "--out", str(tmp_path / "m")]) == 0
    assert (tmp_path / "m" / "cube.pl").is_file()
    assert main(["learn", "predict", "--data", str(data), "--model", str(tmp_path / "m")]) == 0
    assert "accuracy 6/6" in capsys.readouterr().out


def test_the_examples_of_a_rendered_data_set_follow_the_depth_settings(tmp_path, monkeypatch):
    import lv3d.pipeline as pipeline
    from lv3d.errors import InputError
    from lv3d.examples import read_examples
    from lv3d.render.dataset import make_dataset

    data = make_dataset(tmp_path / "data", ["cube", "square_pyramid"], 1, "clean", 3, workers=1, width=320,
                        height=240, progress=False)
    seen, real = [], pipeline.scene_facts
    monkeypatch.setattr(pipeline, "scene_facts", lambda *a, **k: seen.append(k.get("depth")) or real(*a, **k))
    ex = read_examples(data, "depth", depth={"sensor": {"base_m": 0.005}})  # nested or dotted, as a study takes them
    assert seen == [{"sensor.base_m": 0.005}] * 2 and all(s.target for s in ex.scenes)
    with pytest.raises(InputError, match="depth settings do not apply"):
        read_examples(data, "depth", facts="truth", depth={"sensor.base_m": 0.005})
    with pytest.raises(InputError, match="sensor.nope: unknown setting 'nope'"):
        read_examples(data, "depth", depth={"sensor.nope": 1})


def test_mil_noisy_and_a_goal_without_program(capsys):
    assert main(["mil", str(prolog.source("tasks/noisy_grandparent.pl"))]) == 1
    assert capsys.readouterr().out.strip() == "% unable to learn a solution"
    assert main(["mil", "--noisy", "--set", "max_clauses=3", str(prolog.source("tasks/noisy_grandparent.pl"))]) == 0
    assert capsys.readouterr().out.splitlines()[0] == "grandparent(A,B):-grandparent_1(A,C),grandparent_1(C,B)."


def test_mil_bad_set_is_one_line(capsys):
    assert main(["mil", "--set", "max_clauses=0", str(prolog.source("tasks/ancestor.pl"))]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("lv3d: error: --set: max_clauses") and "\n" not in err
