"""The runner on a tiny synthetic study: outputs, resume, seeding."""

import json

from lv3d.experiment.runner import run_study


def _accuracies(out):
    return {(r["system"], r["fold"], r["task"]): r["accuracy"]
            for r in _csv(out / "results.csv")}


def _csv(path):
    import csv

    with open(path) as f:
        return list(csv.DictReader(f))


def test_run_writes_folds_report_and_programs(tmp_path, tiny_config, fake_world):
    out = tmp_path / "run"
    res = run_study(tiny_config, out, progress=False)
    assert res["ran"] == 4 * 3 and res["skipped"] == 0
    for f in ("results.csv", "results.json", "results.md", "accuracy.png", "config.yaml"):
        assert (out / f).is_file(), f
    rec = json.loads((out / "folds" / "base" / "lv3d-rgbd" / "fold0.json").read_text())
    assert set(rec["tasks"]) == {"cube", "square_pyramid", "triangular_prism", "multiclass"}
    # the fake learner sees the side count, so it is perfect; the facts cache holds one file per image
    assert rec["tasks"]["cube"]["accuracy"] == 1.0 and rec["tasks"]["multiclass"]["accuracy"] == 1.0
    assert len(list((out / "facts").rglob("*.json"))) == 2 * 18
    assert (out / "programs" / "base" / "lv3d-rgbd" / "fold2" / "cube" / "program.pl").is_file()
    md = (out / "results.md").read_text()
    assert "| lv3d-rgbd | 100.0 ± 0.0" in md and "tree-rgbd" in md and "sign p" in md
    summary = json.loads((out / "results.json").read_text())["conditions"]["base"]
    assert [t["a"] for t in summary["tests"]][:1] == ["lv3d-rgbd"]


def test_rerun_skips_finished_folds(tmp_path, tiny_config, fake_world):
    out = tmp_path / "run"
    run_study(tiny_config, out, ["systems=[lv3d-rgbd]"], progress=False)
    fits = fake_world.fits
    assert fits == 3 * 4  # 3 folds x (3 class tasks + multi-class)
    mtime = (out / "folds" / "base" / "lv3d-rgbd" / "fold1.json").stat().st_mtime_ns
    (out / "folds" / "base" / "lv3d-rgbd" / "fold1.json").unlink()
    (out / "folds" / "base" / "lv3d-rgbd" / "fold2.json").write_text("{truncated")
    res = run_study(tiny_config, out, ["systems=[lv3d-rgbd]"], progress=False)
    assert res == {**res, "ran": 2, "skipped": 1} and fake_world.fits == fits + 2 * 4
    assert (out / "folds" / "base" / "lv3d-rgbd" / "fold0.json").is_file()
    res = run_study(tiny_config, out, ["systems=[lv3d-rgbd]"], progress=False)
    assert res["ran"] == 0 and fake_world.fits == fits + 2 * 4
    # a changed setting invalidates the finished results instead of silently reusing them
    res = run_study(tiny_config, out, ["systems=[lv3d-rgbd]", "train.positives=2"], progress=False)
    assert res["ran"] == 3
    assert (out / "folds" / "base" / "lv3d-rgbd" / "fold1.json").stat().st_mtime_ns != mtime


def test_same_seed_same_results(tmp_path, tiny_config, fake_world):
    a, b = tmp_path / "a", tmp_path / "b"
    sets = ["systems=[tree-rgbd, cnn-rgb, lv3d-rgb]"]
    run_study(tiny_config, a, sets, progress=False)
    run_study(tiny_config, b, sets, progress=False)
    assert _accuracies(a) == _accuracies(b)
    pa = json.loads((a / "folds" / "base" / "cnn-rgb" / "fold1.json").read_text())["predictions"]
    pb = json.loads((b / "folds" / "base" / "cnn-rgb" / "fold1.json").read_text())["predictions"]
    assert pa == pb


def test_sweep_writes_a_condition_per_value(tmp_path, tiny_config, fake_world):
    out = tmp_path / "curve"
    run_study(tiny_config, out, ["systems=[lv3d-rgbd, tree-rgbd]", "sweep={param: train.positives, values: [1, 4]}"],
              progress=False)
    assert (out / "sweep.png").is_file()
    assert {r["condition"] for r in _csv(out / "results.csv")} == {"positives=1", "positives=4"}
    # both conditions share one data set and one facts cache
    assert len(list((out / "data").iterdir())) == 1


def test_baselines_are_trained_once_across_ablation_conditions(tmp_path, tiny_config, fake_world):
    out = tmp_path / "abl"
    res = run_study(tiny_config, out, ["systems=[lv3d-rgbd, tree-rgbd]",
                                       "conditions={full: {}, no_confidences: {lv3d.confidences: false}}"],
                    progress=False)
    assert res["ran"] == 3 + 3 + 3  # lv3d twice, the tree once
    rec = json.loads((out / "folds" / "no_confidences" / "tree-rgbd" / "fold0.json").read_text())
    assert rec["condition"] == "no_confidences" and rec["reused_from"].startswith("folds/full/")


def test_learner_settings_reach_the_learner(tmp_path, tiny_config, fake_world):
    run_study(tiny_config, tmp_path / "s", ["systems=[lv3d-rgb]", "folds=2", "lv3d.settings.sample_pos=99"],
              progress=False)
    assert fake_world.last_settings == {"sample_pos": 99}
