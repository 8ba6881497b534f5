"""scripts/restore_baselines.py: a study rerun after a change to lv3d's code retrains only the lv3d systems."""

import json

import pytest

from lv3d.errors import InputError
from lv3d.experiment.runner import run_study

@pytest.fixture(scope="module")
def restore_mod(load_script):
    return load_script("restore_baselines")


def test_restored_baselines_are_skipped_and_report_the_same(tmp_path, tiny_config, fake_world, restore_mod):
    first = tmp_path / "first"
    run_study(tiny_config, first, progress=False)
    rerun = tmp_path / "rerun"
    n = restore_mod.restore(tiny_config, first / "results.csv", rerun)
    baselines = [p for p in (first / "folds" / "base").iterdir() if not p.name.startswith("lv3d-")]
    assert n == 3 * len(baselines) > 0  # 3 folds of each baseline
    res = run_study(tiny_config, rerun, progress=False)
    assert res["skipped"] == n and res["ran"] == 3 * 2  # only the two lv3d systems' folds ran
    strip = lambda p: [r.rsplit(",", 1)[0] for r in p.read_text().splitlines()]  # all but the seconds column
    assert strip(rerun / "results.csv") == strip(first / "results.csv")
    rec = json.loads(next((rerun / "folds" / "base" / baselines[0].name).glob("fold0.json")).read_text())
    assert rec["restored_from"].endswith("results.csv")


def test_results_without_a_system_name_both_files(tmp_path, tiny_config, fake_world, restore_mod):
    first = tmp_path / "first"
    run_study(tiny_config, first, ["systems=[lv3d-rgbd]"], progress=False)
    with pytest.raises(InputError, match="no rows for condition 'base', system 'tree-rgbd', fold 0"):
        restore_mod.restore(tiny_config, first / "results.csv", tmp_path / "rerun")
    with pytest.raises(InputError, match="results file not found"):
        restore_mod.restore(tiny_config, tmp_path / "missing.csv", tmp_path / "rerun")
