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


def test_a_run_without_results_is_named(tmp_path, pooled):
    with pytest.raises(SystemExit, match="no results.csv"):
        pooled.main([str(tmp_path)])
