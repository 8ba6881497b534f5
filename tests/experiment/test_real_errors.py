"""scripts/real_errors.py: the wrong answers of a real-objects study, split by whether the facts contradict.

The examples' facts are read by lv3d.experiment.real_data (tested with the study); here they are given."""

import json

import pytest


@pytest.fixture(scope="module")
def real_errors(load_script):
    return load_script("real_errors")


def _run(run, answers, ids, classes):
    folder = run / "folds" / "positives=1" / "lv3d-depth"
    folder.mkdir(parents=True)
    (run / "config.yaml").write_text("name: real_objects\n")
    (folder / "fold0.json").write_text(json.dumps(
        {"condition": "positives=1", "system": "lv3d-depth", "test_ids": ids, "test_classes": classes,
         "predictions": {"cylinder": [answers]}}))
    return run


def test_wrong_answers_split_by_contradicting_facts(tmp_path, real_errors, capsys, monkeypatch):
    # x1 a can read cylindrical, answered right; x2 a can not read so (contradicts), answered wrong; x3 a box with a
    # cylindrical face (contradicts), answered wrong; x4 a can perception did not find (contradicts), answered wrong
    asked = []

    def evidence(run, modality, preds):
        asked.append((modality, preds))
        return {"a_x1": {"cylindrical"}, "a_x2": set(), "a_x3": {"cylindrical"}}

    monkeypatch.setattr(real_errors, "example_evidence", evidence)
    run = _run(tmp_path, [["a_x1", "cylinder", 0.9], ["a_x2", "unknown", 0.0], ["a_x3", "cylinder", 0.8],
                          ["a_x4", "unknown", 0.0]], ["a_x1", "a_x2", "a_x3", "a_x4"],
               ["cylinder", "cylinder", "box", "cylinder"])
    assert real_errors.main([str(run), "--evidence", "cylinder=cylindrical"]) == 0
    assert asked == [("depth", {"cylindrical"})]  # the facts of the system's modality, read once
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("positives=1"))
    assert line.split()[3:] == ["4", "3", "(75.0", "%)", "3", "3", "(75.0", "%)"]


def test_a_folder_that_is_not_a_study_run_and_a_bad_evidence_are_named(tmp_path, real_errors):
    with pytest.raises(SystemExit, match="not a study's --out folder"):
        real_errors.main([str(tmp_path), "--evidence", "cylinder=cylindrical"])
    with pytest.raises(SystemExit):  # argparse: CLASS=PREDICATE
        real_errors.main([str(tmp_path), "--evidence", "cylinder"])
