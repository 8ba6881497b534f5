"""scripts/real_errors.py: the wrong answers of a real-objects study, split by whether the facts contradict."""

import json

import pytest


@pytest.fixture(scope="module")
def real_errors(load_script):
    return load_script("real_errors")


def _facts(cache, version, frame, facts, under):
    folder = cache / "facts" / "real-abc" / version / "depth-refine1"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{frame}.json").write_text(json.dumps(
        {"frame": frame, "modality": "depth", "facts": {"facts": facts}, "under": under}))


def _fold(run, answers, ids, classes):
    folder = run / "folds" / "positives=1" / "lv3d-depth"
    folder.mkdir(parents=True)
    (folder / "fold0.json").write_text(json.dumps(
        {"condition": "positives=1", "system": "lv3d-depth", "test_ids": ids, "test_classes": classes,
         "predictions": {"cylinder": [answers]}}))


def test_wrong_answers_split_by_contradicting_facts(tmp_path, real_errors, capsys):
    run, cache = tmp_path / "run", tmp_path / "cache"
    face = lambda o, f: {"pred": "face_of", "args": [o, f], "conf": 0.99}  # noqa: E731
    _facts(cache, "v1", "a", [face("a_o1", "a_o1_f1"), {"pred": "cylindrical", "args": ["a_o1_f1"], "conf": 0.9},
                              face("a_o2", "a_o2_f1"), {"pred": "cylindrical", "args": ["a_o2_f1"], "conf": 0.3},
                              face("a_o3", "a_o3_f1"), {"pred": "cylindrical", "args": ["a_o3_f1"], "conf": 0.8}],
           {"1": "a_o1", "2": "a_o2", "3": "a_o3", "4": None})
    # x1 a can read cylindrical, answered right; x2 a can not read so (contradicts), answered wrong; x3 a box with a
    # cylindrical face (contradicts), answered wrong; x4 a can perception did not find (contradicts), answered wrong
    _fold(run, [["a_x1", "cylinder", 0.9], ["a_x2", "unknown", 0.0], ["a_x3", "cylinder", 0.8],
                ["a_x4", "unknown", 0.0]], ["a_x1", "a_x2", "a_x3", "a_x4"], ["cylinder", "cylinder", "box", "cylinder"])
    assert real_errors.main([str(run), str(cache), "--evidence", "cylinder=cylindrical"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("positives=1"))
    assert line.split()[3:] == ["4", "3", "(75.0", "%)", "3", "3", "(75.0", "%)"]


def test_several_versions_of_the_facts_must_be_chosen(tmp_path, real_errors):
    run, cache = tmp_path / "run", tmp_path / "cache"
    _facts(cache, "v1", "a", [], {"1": None})
    _facts(cache, "v2", "a", [], {"1": None})
    _fold(run, [["a_x1", "unknown", 0.0]], ["a_x1"], ["cylinder"])
    with pytest.raises(SystemExit, match="several versions .*v1, v2.*--facts-version"):
        real_errors.main([str(run), str(cache), "--evidence", "cylinder=cylindrical"])
    assert real_errors.main([str(run), str(cache), "--evidence", "cylinder=cylindrical", "--facts-version", "v2"]) == 0


def test_a_run_without_lv3d_folds_and_a_bad_evidence_are_named(tmp_path, real_errors):
    with pytest.raises(SystemExit, match="no lv3d fold files"):
        real_errors.main([str(tmp_path), str(tmp_path), "--evidence", "cylinder=cylindrical"])
    with pytest.raises(SystemExit):  # argparse: CLASS=PREDICATE
        real_errors.main([str(tmp_path), str(tmp_path), "--evidence", "cylinder"])
