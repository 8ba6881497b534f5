"""The runner on a tiny synthetic study: outputs, resume, seeding."""

import json
import math

from lv3d.experiment.runner import run_study
from lv3d.facts import Fact, SceneFacts


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
    # a perfect learner is perfect on balanced accuracy too; the column sits between mean and multi
    assert summary["systems"]["lv3d-rgbd"]["balanced"] == {"mean": 1.0, "std": 0.0}
    assert "| mean | balanced | multi |" in md
    assert [t["a"] for t in summary["tests"]][:1] == ["lv3d-rgbd"]
    # the margin: the best-seeing lv3d system against the best CNN (the only one here)
    best = summary["against_best_cnn"]
    assert (best["a"], best["b"]) == ("lv3d-rgbd", "cnn-rgb") and "lv3d-rgbd against the best CNN here (cnn-rgb" in md
    # and in balanced accuracy, which an answer of "no" to everything does not inflate: the perfect learner's
    # cells are 1, the CNN's its own; the difference is theirs, over the cells both have
    bal = summary["against_best_cnn_balanced"]
    cnn = [float(r["balanced_accuracy"]) for r in _csv(out / "results.csv")
           if r["system"] == "cnn-rgb" and r["task"] != "multiclass" and r["balanced_accuracy"]]
    assert bal["b"] == "cnn-rgb" and bal["cells"] == len(cnn)
    assert math.isclose(bal["mean_diff"], 1.0 - sum(cnn) / len(cnn))
    assert "In balanced accuracy, lv3d-rgbd against the best CNN by it (cnn-rgb" in md


def test_a_condition_asking_more_examples_than_the_training_folds_hold_says_so(tmp_path, tiny_config, fake_world):
    # 6 images a class in 3 folds: the training folds hold 4 of each, so 6 positives draw 4 (a folder of a few
    # frames caps a learning curve the same way); the report names the tasks and what was drawn
    out = tmp_path / "short"
    run_study(tiny_config, out, ["systems=[lv3d-rgbd, tree-rgbd]", "sweep={param: train.positives, values: [4, 6]}"],
              progress=False)
    conds = json.loads((out / "results.json").read_text())["conditions"]
    assert "short" not in conds["positives=4"]
    assert conds["positives=6"]["short"] == {"cube": [4, 4, 6], "square_pyramid": [4, 4, 6],
                                             "triangular_prism": [4, 4, 6], "multiclass": [12, 12, 18]}
    md = (out / "results.md").read_text()
    section = md[md.index("## positives=6"):]
    assert md.count("Fewer training examples") == 1 and "Fewer training examples" in section
    assert "cube 4 positives of the 6 asked" in section and "multiclass 12 examples in all of the 18 asked" in section


def test_balanced_accuracy_of_a_fold_is_the_mean_over_its_class_tasks_that_have_one():
    from lv3d.experiment.report import _mean_balanced

    tasks = {"a": {"balanced_accuracy": 0.5}, "b": {"balanced_accuracy": 1.0}, "c": {"balanced_accuracy": float("nan")},
             "multiclass": {"accuracy": 0.2}}
    assert _mean_balanced(tasks, ["a", "b", "c", "d"]) == 0.75
    # a fold without a positive has none (NaN; a restored fold file holds an empty string): mean_std skips it
    assert math.isnan(_mean_balanced({"c": {"balanced_accuracy": ""}, "d": {}}, ["c", "d"]))


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
    # the tree's folds are reused, the same in both conditions: no test of it against the first
    assert all(t["system"] != "tree-rgbd" for t in json.loads((out / "results.json").read_text()).get(
        "against_first", []))


def test_named_conditions_are_each_tested_against_the_first(tmp_path, tiny_config, fake_world):
    out = tmp_path / "named"
    run_study(tiny_config, out, ["systems=[lv3d-rgbd, tree-rgbd]",
                                 "conditions={full: {}, one_positive: {train.positives: 1}}"], progress=False)
    tests = json.loads((out / "results.json").read_text())["against_first"]
    assert {(t["condition"], t["first"]) for t in tests} == {("one_positive", "full")}
    rows = _csv(out / "results.csv")
    for t in tests:
        cells = {(r["condition"], r["fold"], r["task"]): float(r["accuracy"]) for r in rows
                 if r["system"] == t["system"] and r["task"] != "multiclass"}
        diffs = [cells[("one_positive", f, k)] - cells[("full", f, k)] for c, f, k in cells if c == "full"]
        assert t["cells"] == len(diffs) and math.isclose(t["mean_diff"], sum(diffs) / len(diffs))
    assert "## Each condition against full" in (out / "results.md").read_text()


def test_against_first_leaves_out_a_system_the_same_in_both():
    from lv3d.experiment.report import against_first, against_first_markdown

    rows = [{"condition": c, "system": s, "fold": f, "task": t, "accuracy": a}
            for c, shift in (("full", 0.0), ("off", -0.1)) for s in ("lv3d-rgbd", "tree-rgbd") for f in (0, 1)
            for t, a in (("box", 0.9), ("can", 0.8), ("multiclass", 0.7))
            for a in [a + (shift if s == "lv3d-rgbd" else 0.0)]]
    tests = against_first(rows, ["full", "off"], ["lv3d-rgbd", "tree-rgbd"])
    assert [t["system"] for t in tests] == ["lv3d-rgbd"]
    assert tests[0]["cells"] == 4 and math.isclose(tests[0]["mean_diff"], -0.1)
    assert math.isclose(tests[0]["multiclass_diff"], -0.1) and tests[0]["sign"]["losses"] == 4
    text = "\n".join(against_first_markdown(tests))
    assert text.startswith("## Each condition against full") and "| lv3d-rgbd | off | 4 | -10.0 |" in text
    assert against_first_markdown([]) == []


def test_a_sweep_is_not_tested_condition_against_condition(tmp_path, tiny_config, fake_world):
    out = tmp_path / "curve"
    run_study(tiny_config, out, ["systems=[tree-rgbd]", "sweep={param: train.positives, values: [1, 4]}"],
              progress=False)
    assert "against_first" not in json.loads((out / "results.json").read_text())
    assert "Each condition against" not in (out / "results.md").read_text()


def test_learner_settings_reach_the_learner(tmp_path, tiny_config, fake_world):
    run_study(tiny_config, tmp_path / "s", ["systems=[lv3d-rgb]", "folds=2", "lv3d.settings.sample_pos=99"],
              progress=False)
    assert fake_world.last_settings == {"sample_pos": 99}


def test_draws_average_independent_samples_and_one_draw_keeps_the_old_keys(tmp_path, tiny_config, fake_world):
    from lv3d.experiment.config import load_study
    from lv3d.experiment.runner import result_key

    one, three = tmp_path / "one", tmp_path / "three"
    sets = ["systems=[tree-rgbd]", "train.positives=1"]
    run_study(tiny_config, one, sets, progress=False)
    run_study(tiny_config, three, sets + ["train.draws=3"], progress=False)
    r1 = json.loads((one / "folds" / "base" / "tree-rgbd" / "fold0.json").read_text())
    r3 = json.loads((three / "folds" / "base" / "tree-rgbd" / "fold0.json").read_text())
    for task, sc in r3["tasks"].items():
        # draw 0 is the one-draw sample; the score is the mean of the draws'
        assert len(sc["per_draw"]) == 3 and sc["per_draw"][0] == r1["tasks"][task]["accuracy"]
        assert abs(sc["accuracy"] - sum(sc["per_draw"]) / 3) < 1e-12
        assert len(r3["predictions"][task]) == 3 and r3["predictions"][task][0] == r1["predictions"][task]
    positives = lambda sc: sc["tp"] + sc["fn"]  # noqa: E731
    assert positives(r3["tasks"]["cube"]) == 3 * positives(r1["tasks"]["cube"])
    # a study written before draws existed (no train.draws) has the key a one-draw study has now
    ccfg = load_study(tiny_config, sets).conditions["base"].to_dict()
    before = {**ccfg, "train": {k: v for k, v in ccfg["train"].items() if k != "draws"}}
    assert result_key(ccfg, "tree-rgbd", 0) == result_key(before, "tree-rgbd", 0)
    three_draws = {**ccfg, "train": {**ccfg["train"], "draws": 3}}
    assert result_key(three_draws, "tree-rgbd", 0) != result_key(ccfg, "tree-rgbd", 0)


def test_draws_must_be_a_positive_integer(tmp_path, tiny_config):
    import pytest

    from lv3d.errors import InputError
    from lv3d.experiment.config import load_study

    for bad in ("0", "1.5", "true"):
        with pytest.raises(InputError, match="train.draws"):
            load_study(tiny_config, [f"train.draws={bad}"])


def test_the_perception_seed_reaches_perception_and_keys_its_facts(tmp_path, tiny_config, perceived_with):
    from lv3d.experiment.config import load_study
    from lv3d.experiment.data import facts_variant
    from lv3d.experiment.runner import result_key

    sets = ["systems=[lv3d-depth]", "folds=2"]
    run_study(tiny_config, tmp_path / "s", sets + ["lv3d.perception_seed=7"], progress=False)
    seeds = [seed for seed, _ in perceived_with]
    assert seeds and set(seeds) == {7}
    facts = tmp_path / "s" / "facts"
    assert {p.name for p in facts.glob("*/*/*")} == {facts_variant("depth", True, 7)} == {"depth-refine1-seed7"}
    assert facts_variant("depth", True, 0) == "depth-refine1"  # the default's folders keep their names
    # the default seed keeps the keys results made before the option existed; another seed is another result
    ccfg = load_study(tiny_config, sets).conditions["base"].to_dict()
    before = {**ccfg, "lv3d": {k: v for k, v in ccfg["lv3d"].items() if k != "perception_seed"}}
    assert ccfg["lv3d"]["perception_seed"] == 0
    assert result_key(ccfg, "lv3d-depth", 0, "f") == result_key(before, "lv3d-depth", 0, "f")
    other = {**ccfg, "lv3d": {**ccfg["lv3d"], "perception_seed": 7}}
    assert result_key(other, "lv3d-depth", 0, "f") != result_key(ccfg, "lv3d-depth", 0, "f")
    # rendered images do not depend on perception: the baselines' keys stay
    assert result_key(other, "tree-rgbd", 0) == result_key(ccfg, "tree-rgbd", 0)


def test_depth_settings_reach_perception_and_key_their_facts(tmp_path, tiny_config, perceived_with):
    import re

    import pytest

    from lv3d.errors import InputError
    from lv3d.experiment.config import load_study
    from lv3d.experiment.data import depth_suffix, facts_variant
    from lv3d.experiment.runner import result_key

    sets = ["systems=[lv3d-depth]", "folds=2"]
    # a dotted key, a nested mapping: one flat mapping of dotted keys
    deeper = load_study(tiny_config, sets + ["lv3d.depth={sensor: {per_m2: 0.01}}", "lv3d.depth.sensor.base_m=0.006"])
    depth = deeper.conditions["base"].lv3d.depth
    assert depth == {"sensor.base_m": 0.006, "sensor.per_m2": 0.01}
    swept = load_study(tiny_config, sets + ["sweep={param: lv3d.depth.sensor.base_m, values: [0.004, 0.006]}"])
    assert {n: c.lv3d.depth for n, c in swept.conditions.items()} == {
        "base_m=0.004": {"sensor.base_m": 0.004}, "base_m=0.006": {"sensor.base_m": 0.006}}
    run_study(tiny_config, tmp_path / "s", sets + ["lv3d.depth.sensor.base_m=0.006", "lv3d.depth.sensor.per_m2=0.01"],
              progress=False)
    given = [d for _, d in perceived_with]
    assert given and all(d == depth for d in given)
    facts = tmp_path / "s" / "facts"
    assert {p.name for p in facts.glob("*/*/*")} == {facts_variant("depth", True, 0, depth)}
    assert facts_variant("depth", True, 0, depth) == "depth-refine1" + depth_suffix(depth) != "depth-refine1"
    assert facts_variant("depth", True, 0, {}) == "depth-refine1"  # the default's folders keep their names
    # at the default the keys are those of results made before the option existed
    ccfg = load_study(tiny_config, sets).conditions["base"].to_dict()
    before = {**ccfg, "lv3d": {k: v for k, v in ccfg["lv3d"].items() if k != "depth"}}
    assert result_key(ccfg, "lv3d-depth", 0, "f") == result_key(before, "lv3d-depth", 0, "f")
    other = {**ccfg, "lv3d": {**ccfg["lv3d"], "depth": depth}}
    assert result_key(other, "lv3d-depth", 0, "f") != result_key(ccfg, "lv3d-depth", 0, "f")
    for bad, says in (("lv3d.depth.sensor.nope=1", "lv3d.depth.sensor.nope: unknown setting 'nope'"),
                      ("lv3d.depth.stride=0.5", "lv3d.depth.stride: must be of type int"),
                      ("lv3d.depth.sensor.min_m=0.5", "lv3d.depth.sensor.min_m: min_m (0.5) must not exceed")):
        with pytest.raises(InputError, match=re.escape(says)):
            load_study(tiny_config, sets + [bad])


def test_lv3d_results_are_kept_while_their_facts_and_learning_code_are(tmp_path, tiny_config, fake_world,
                                                                      monkeypatch):
    import pytest

    from lv3d.experiment import runner
    from lv3d.experiment.config import load_study
    from tests.experiment.conftest import fake_scene_facts

    sets, out = ["systems=[lv3d-depth, tree-rgbd]", "folds=2"], tmp_path / "s"
    run_study(tiny_config, out, sets, progress=False)
    fits, fold = fake_world.fits, out / "folds" / "base" / "lv3d-depth" / "fold0.json"
    made_by = json.loads(fold.read_text())["code"]
    # perception's code changed and every fact stayed: the facts are computed anew, the results kept, and the
    # report says they hold for the new version
    monkeypatch.setattr("lv3d.experiment.data.facts_version", lambda: "refactored")
    monkeypatch.setattr(runner, "learner_version", lambda: "newversion00")
    assert run_study(tiny_config, out, sets, progress=False)["ran"] == 0 and fake_world.fits == fits
    assert list((out / "facts").glob("*/refactored/depth-refine1/*.json"))
    rec = json.loads(fold.read_text())
    assert rec["code"] == made_by and rec["holds_under"] == ["newversion00"]
    assert (f"made with lv3d code version `{made_by}` (a digest of its source: lv3d/experiment/code_version.py); "
            "they hold for version `newversion00` too") in (out / "results.md").read_text()
    run_study(tiny_config, out, sets, progress=False)
    assert json.loads(fold.read_text())["holds_under"] == ["newversion00"]  # said once
    # a fact changed: the lv3d results are computed again, the baseline's kept
    def other_facts(frame, scene_id, modality, refine=True, confidences=True, seed=0, depth=None):
        sf = fake_scene_facts(frame, scene_id, modality, refine, confidences, seed)
        return type(sf)(sf.scene, sf.modality, [*sf.facts[:-1], Fact(sf.facts[-1].pred, sf.facts[-1].args, 0.8)],
                        sf.target)

    monkeypatch.setattr("lv3d.pipeline.scene_facts", other_facts)
    monkeypatch.setattr("lv3d.experiment.data.facts_version", lambda: "changed")
    assert run_study(tiny_config, out, sets, progress=False)["ran"] == 2
    rec = json.loads(fold.read_text())
    assert rec["code"] == "newversion00" and "holds_under" not in rec
    # the learning code changed: computed again
    monkeypatch.setattr(runner, "learning_version", lambda: "other learner")
    assert run_study(tiny_config, out, sets, progress=False)["ran"] == 2
    # an lv3d result's key cannot be made without its facts
    with pytest.raises(ValueError, match="digest of its facts"):
        runner.result_key(load_study(tiny_config, sets).base, "lv3d-depth", 0)


def test_baselines_on_real_frames_are_keyed_by_where_their_crops_lie(tiny_config, monkeypatch):
    import pytest

    from lv3d.experiment import runner
    from lv3d.experiment.config import load_study
    from lv3d.experiment.real_data import crops_digest
    from lv3d.object_facts import FrameFacts

    monkeypatch.setattr(runner, "_real_key", lambda folders, classes: "frames")
    ccfg = load_study(tiny_config, []).conditions["base"].to_dict()
    real = {**ccfg, "data": {**ccfg["data"], "folders": ["somewhere"]}}
    with pytest.raises(ValueError, match="digest of its crops"):
        runner.result_key(real, "effnet-rgbd", 0)
    assert runner.result_key(real, "effnet-rgbd", 0, "a") != runner.result_key(real, "effnet-rgbd", 0, "b")
    assert runner.result_key(ccfg, "effnet-rgbd", 0) == runner.result_key(ccfg, "effnet-rgbd", 0, None)  # rendered

    def frames(box, conf):
        facts = SceneFacts("f0", "rgbd", [Fact("object", ("f0_o1",), conf)], "f0_o1")
        return {"f0": FrameFacts("f0", "rgbd", facts, {1: "f0_o1"}, {1: box})}

    # the crops follow the boxes perception found under the labelled pixels, not the facts' confidences
    assert crops_digest(frames([1, 2, 30, 40], 0.9)) == crops_digest(frames([1, 2, 30, 40], 0.5))
    assert crops_digest(frames([1, 2, 30, 40], 0.9)) != crops_digest(frames([1, 2, 30, 41], 0.9))
    assert crops_digest(frames(None, 0.9)) != crops_digest(frames([1, 2, 30, 40], 0.9))


