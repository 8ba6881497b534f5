"""scripts/compare_reports.py: which cells of a study's report moved between two runs."""

import pytest


@pytest.fixture(scope="module")
def compare(load_script):
    return load_script("compare_reports")


def test_moved_cells_and_each_systems_mean_change(tmp_path, compare, capsys, write_results):
    old = write_results(tmp_path / "old.csv", [
        ("c", "lv3d-rgbd", 0, "cube", 1.0), ("c", "lv3d-rgbd", 1, "cube", 0.9), ("c", "lv3d-rgbd", 0, "prism", 0.8),
        ("c", "tree-rgbd", 0, "cube", 0.5)])
    new = write_results(tmp_path / "new.csv", [
        ("c", "lv3d-rgbd", 0, "cube", 0.9), ("c", "lv3d-rgbd", 1, "cube", 0.9), ("c", "lv3d-rgbd", 0, "prism", 0.8),
        ("c", "cnn-rgbd", 0, "cube", 0.6)])
    assert compare.main([str(old), str(new)]) == 0
    out = capsys.readouterr().out
    # cube: mean over folds 95.0 -> 90.0; prism unchanged and so not listed
    assert "95.0   90.0   -5.00" in out and "prism" not in out.split("\n\n")[0]
    assert "lv3d-rgbd: 1 of 2 cells moved, mean change -2.50 points" in out
    assert "in one report only: cnn-rgbd, tree-rgbd" in out


def test_a_file_that_is_not_a_report_is_named(tmp_path, compare):
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n")
    with pytest.raises(SystemExit, match="bad.csv: not a study's results.csv"):
        compare.main([str(bad), str(bad)])


def test_a_non_numeric_accuracy_names_file_and_line(tmp_path, compare, write_results):
    bad = write_results(tmp_path / "r.csv", [("c", "lv3d-rgbd", 0, "cube", "x")])
    with pytest.raises(SystemExit, match=r"r.csv:2: accuracy 'x' is not a number"):
        compare.main([str(bad), str(bad)])
