"""The report's confusions of the multi-class answers, counted from fold records made by hand."""

import pytest

from lv3d.experiment.report import answer_confusion, confusion_matrix, markdown


def _record(truth, *draws):
    return {"test_classes": truth, "predictions": {"multiclass": [[[f"s{i}", a, 0.5] for i, a in enumerate(d)]
                                                                 for d in draws]}}


def test_confusions_are_counted_over_folds_and_draws_most_frequent_first():
    recs = [_record(["cube", "cuboid", "cuboid"], ["cube", "cube", "cuboid"], ["cube", "cube", "unknown"]),
            _record(["cuboid", "cone"], ["cube", "cone"])]
    c = answer_confusion(recs)
    assert c["answers"] == {"cone": 1, "cube": 2, "cuboid": 5}
    assert c["pairs"] == [["cuboid", "cube", 3], ["cuboid", "unknown", 1]]
    cols, rows = confusion_matrix(c, ["cube", "cuboid", "cone", "sphere"])
    assert cols == ["cube", "cuboid", "cone", "sphere", "unknown"]
    assert rows[0] == [1.0, 0.0, 0.0, 0.0, 0.0]
    assert rows[1] == pytest.approx([0.6, 0.2, 0.0, 0.0, 0.2])
    assert rows[3] == [0.0] * 5  # a class without answers


def test_a_record_of_one_draw_and_records_without_answers():
    one = {"test_classes": ["cube", "cone"], "predictions": {"multiclass": [["s0", "cone", 0.9], ["s1", "cone", 0.8]]}}
    assert answer_confusion([one])["pairs"] == [["cube", "cone", 1]]
    assert answer_confusion([{"test_classes": ["cube"], "predictions": {}}]) is None


def test_the_report_names_the_most_frequent_confusions_per_system():
    conf = answer_confusion([_record(["cube", "cuboid"], ["cube", "cube"])])
    per = {"classes": {c: {"mean": 1.0, "std": 0.0} for c in ("cube", "cuboid", "multiclass")},
           "mean": {"mean": 1.0, "std": 0.0}, "balanced": {"mean": 1.0, "std": 0.0}, "folds_done": 1, "errors": 0,
           "confusion": conf}
    md = markdown("t", {"base": {"systems": {"lv3d-rgbd": per}, "tests": []}}, ["cube", "cuboid"])
    assert "| lv3d-rgbd | 1 of 2 | cuboid → cube 1 of 1 |" in md
