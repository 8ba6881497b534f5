"""scripts/restore_baselines.py: a study rerun after a change to lv3d's code retrains only the lv3d systems."""

import csv
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
    assert _without_seconds(rerun / "results.csv") == _without_seconds(first / "results.csv")
    rec = json.loads(next((rerun / "folds" / "base" / baselines[0].name).glob("fold0.json")).read_text())
    assert rec["restored_from"].endswith("results.csv")


def _without_seconds(path):
    with path.open(newline="") as f:
        return [{k: v for k, v in row.items() if k != "seconds"} for row in csv.DictReader(f)]


def test_a_tuned_baselines_setting_rides_on_its_rows_and_survives_the_restore(tmp_path, tiny_config, fake_world,
                                                                              restore_mod):
    first = tmp_path / "first"
    run_study(tiny_config, first, progress=False)
    with (first / "results.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert all(r["tuned"] == "" for r in rows)  # nothing here was tuned
    base = next(r["system"] for r in rows if not r["system"].startswith("lv3d-"))
    chosen = {"setting": {"width": 8, "epochs": 20, "augment": False, "image_size": 32}, "inner_accuracy": 0.8}
    for r in rows:
        if r["system"] == base and r["fold"] == "0":
            r["tuned"] = json.dumps(chosen)
    tuned_csv = tmp_path / "tuned.csv"
    with tuned_csv.open("w", newline="") as f:
        w = csv.DictWriter(f, list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    rerun = tmp_path / "rerun"
    restore_mod.restore(tiny_config, tuned_csv, rerun)
    assert json.loads((rerun / "folds" / "base" / base / "fold0.json").read_text())["tuned"] == chosen
    assert "tuned" not in json.loads((rerun / "folds" / "base" / base / "fold1.json").read_text())
    run_study(tiny_config, rerun, progress=False)
    assert f"| {base} | 0 | 8 | 20 | off | 32 | 80.0 |" in (rerun / "results.md").read_text()
    with (rerun / "results.csv").open(newline="") as f:
        again = [r for r in csv.DictReader(f) if r["system"] == base and r["fold"] == "0"]
    assert again and all(json.loads(r["tuned"]) == chosen for r in again)


def test_results_without_a_system_name_both_files(tmp_path, tiny_config, fake_world, restore_mod):
    first = tmp_path / "first"
    run_study(tiny_config, first, ["systems=[lv3d-rgbd]"], progress=False)
    with pytest.raises(InputError, match="no rows for condition 'base', system 'tree-rgbd', fold 0"):
        restore_mod.restore(tiny_config, first / "results.csv", tmp_path / "rerun")
    with pytest.raises(InputError, match="results file not found"):
        restore_mod.restore(tiny_config, tmp_path / "missing.csv", tmp_path / "rerun")
