"""scripts/pooled_replicates.py: paired differences pooled over replicate runs of one study."""

import pytest


@pytest.fixture(scope="module")
def pooled(load_script):
    return load_script("pooled_replicates")


def test_cells_of_every_run_are_pooled_per_condition(tmp_path, pooled, capsys, write_results):
    def _results(folder, rows):
        folder.mkdir()
        write_results(folder / "results.csv", rows)
        return folder

    one = _results(tmp_path / "one", [("c", "lv3d-rgbd", 0, "cube", 1.0), ("c", "lv3d-depth", 0, "cube", 0.975),
                                      ("c", "lv3d-rgbd", 0, "multiclass", 0.1), ("c", "lv3d-depth", 0, "multiclass", 0.9)])
    two = _results(tmp_path / "two", [("c", "lv3d-rgbd", 0, "cube", 0.95), ("c", "lv3d-depth", 0, "cube", 0.925),
                                      ("c", "lv3d-rgbd", 1, "cube", 0.9), ("c", "lv3d-depth", 1, "cube", 0.95)])
    assert pooled.main([str(one), str(two)]) == 0
    out = capsys.readouterr().out
    # three class-task cells (multi-class left out): +2.5, +2.5, -5.0 points
    assert "over 3 cells of 2 runs: +0.00 points" in out and "2 wins, 1 losses, 0 ties" in out
    # multi-class rows apart: each system's mean over its (run, fold) cells
    assert "c: lv3d-rgbd multi-class over 1 cells of 2 runs: 10.0 %" in out
    assert "c: lv3d-depth multi-class over 1 cells of 2 runs: 90.0 %" in out


def test_multi_class_cells_are_pooled_with_an_interval(tmp_path, pooled, capsys, write_results):
    runs = []
    for k, accs in enumerate(([0.8, 0.9], [1.0, 0.9])):
        folder = tmp_path / f"run{k}"
        folder.mkdir()
        rows = [("c", s, f, "cube", 1.0) for s in ("lv3d-rgbd", "lv3d-depth") for f in (0, 1)]
        rows += [("c", "lv3d-rgbd", f, "multiclass", a) for f, a in enumerate(accs)]
        rows += [("c", "lv3d-depth", f, "multiclass", 0.5) for f in (0, 1)]
        write_results(folder / "results.csv", rows)
        runs.append(str(folder))
    assert pooled.main(runs) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("c: lv3d-rgbd multi-class"))
    assert "over 4 cells of 2 runs: 90.0 %" in line
    lo, hi = (float(v) for v in line.split("interval ")[1].rstrip(")").split(" to "))
    assert 80.0 <= lo < 90.0 < hi <= 100.0
    # every depth cell alike: the interval is the value itself
    assert "c: lv3d-depth multi-class over 4 cells of 2 runs: 50.0 % (95% interval 50.0 to 50.0)" in out


def test_a_run_without_results_is_named(tmp_path, pooled):
    with pytest.raises(SystemExit, match="no results.csv"):
        pooled.main([str(tmp_path)])
