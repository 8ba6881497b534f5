"""scripts/vote_perception_seeds.py: the answers of runs on several perception seeds, per seed and voted."""

import json

import pytest


@pytest.fixture(scope="module")
def vote(load_script):
    return load_script("vote_perception_seeds")


def _run(folder, box_answers, multi_answers):
    """A run folder with one fold file: objects a (box), b (box), c (cylinder); one draw of the box task and of
    the multi-class task, answered as given ({object: answer})."""
    d = folder / "folds" / "positives=1" / "lv3d-rgbd"
    d.mkdir(parents=True)
    rec = {"test_ids": ["a", "b", "c"], "test_classes": ["box", "box", "cylinder"],
           "predictions": {"box": [[[i, a, 0.9 if a != "unknown" else 0.0] for i, a in box_answers.items()]],
                           "multiclass": [[[i, a, 0.8] for i, a in multi_answers.items()]]}}
    (d / "fold0.json").write_text(json.dumps(rec))
    return folder


def test_the_vote_is_the_answer_most_seeds_give(tmp_path, vote, capsys):
    runs = [_run(tmp_path / "s0", {"a": "box", "b": "unknown", "c": "unknown"}, {"a": "box", "b": "cylinder", "c": "cylinder"}),
            _run(tmp_path / "s1", {"a": "box", "b": "box", "c": "box"}, {"a": "box", "b": "box", "c": "box"}),
            _run(tmp_path / "s2", {"a": "unknown", "b": "box", "c": "unknown"}, {"a": "cylinder", "b": "box", "c": "cylinder"})]
    assert vote.main([str(r) for r in runs] + ["--systems", "lv3d-rgbd"]) == 0
    out = capsys.readouterr().out
    # box task: 2/3, 2/3, 2/3 right; the vote says yes to a and b, no to c: 3/3. Multi-class: 2/3, 2/3, 2/3; vote 3/3
    assert "run 0: 66.7 / 66.7  run 1: 66.7 / 66.7  run 2: 66.7 / 66.7" in out
    assert "mean 66.7 / 66.7  vote 100.0 / 100.0  (vote - mean +33.3 / +33.3)" in out


def test_runs_that_tested_other_objects_are_refused(tmp_path, vote):
    a = _run(tmp_path / "a", {"a": "box", "b": "box", "c": "box"}, {"a": "box", "b": "box", "c": "box"})
    b = _run(tmp_path / "b", {"a": "box", "b": "box", "c": "box"}, {"a": "box", "b": "box", "c": "box"})
    c = _run(tmp_path / "c", {"a": "box", "b": "box", "c": "box"}, {"a": "box", "b": "box", "c": "box"})
    f = c / "folds" / "positives=1" / "lv3d-rgbd" / "fold0.json"
    rec = json.loads(f.read_text())
    rec["test_ids"] = ["x", "b", "c"]
    f.write_text(json.dumps(rec))
    with pytest.raises(SystemExit, match="tested different objects"):
        vote.main([str(a), str(b), str(c)])


def test_a_folder_without_folds_is_named(tmp_path, vote):
    with pytest.raises(SystemExit, match="no folds/"):
        vote.main([str(tmp_path)] * 3)
