"""baselines.tune in a study: tuned on the training folds only, recorded per fold, seeded; off, keys unchanged."""

import json

import numpy as np
import pytest

from lv3d.baselines import tuning
from lv3d.errors import InputError
from lv3d.experiment.config import TUNE_KEYS, from_dict, load_study
from lv3d.experiment.folds import Item
from lv3d.experiment.runner import result_key, run_study
from lv3d.experiment.systems import PixelSystem

TINY_GRID = ["baselines.tune=true", "baselines.tune_width=[2, 4]", "baselines.tune_epochs=[1]",
             "baselines.tune_augment=[false]", "baselines.tune_image_size=[8, 16]", "baselines.tune_folds=2"]


def _fold(out, system, k):
    return json.loads((out / "folds" / "base" / system / f"fold{k}.json").read_text())


def _strip(rec: dict) -> dict:
    """A fold record without its timings."""
    rec = {k: v for k, v in rec.items() if k != "seconds"}
    if "tuned" in rec:
        rec["tuned"] = {k: v for k, v in rec["tuned"].items() if k != "seconds"}
    rec["tasks"] = {t: {k: v for k, v in s.items() if k != "seconds"} for t, s in rec["tasks"].items()}
    return rec


def test_tuning_sees_only_the_training_folds_and_is_recorded(tmp_path, tiny_config, fake_world, monkeypatch):
    seen: list[tuple[str, list[str]]] = []
    original = PixelSystem.tune

    def spy(self, items, seed):
        seen.append((self.name, [it.id for it in items]))
        return original(self, items, seed)

    monkeypatch.setattr(PixelSystem, "tune", spy)
    monkeypatch.setattr(tuning, "_CACHE", {})
    out = tmp_path / "run"
    run_study(tiny_config, out, ["systems=[cnn-rgb, tree-rgbd]", *TINY_GRID], progress=False)
    assert [name for name, _ in seen] == ["cnn-rgb"] * 3 + ["tree-rgbd"] * 3  # asked once per cell
    every = {i for _, ids in seen for i in ids} | set(_fold(out, "cnn-rgb", 0)["test_ids"])
    for k in range(3):
        rec = _fold(out, "cnn-rgb", k)
        test = set(rec["test_ids"])
        assert not test & set(seen[k][1]) and set(seen[k][1]) == every - test  # all of the training folds, no test item
        t = rec["tuned"]
        assert t["setting"]["width"] in (2, 4) and t["setting"]["image_size"] in (8, 16)
        row = next(r for r in t["grid"] if all(r[key] == v for key, v in t["setting"].items()))
        assert row["accuracy"] == t["inner_accuracy"] == max(r["accuracy"] for r in t["grid"])
        assert t["n_examples"] == len(every - test) and t["inner_folds"] == 2 and len(t["grid"]) == 4
        assert "tuned" not in _fold(out, "tree-rgbd", k)  # the trees are not tuned
    md = (out / "results.md").read_text()
    assert "CNN settings chosen per fold" in md and "| cnn-rgb | 2 |" in md
    assert len(json.loads((out / "results.json").read_text())["conditions"]["base"]["systems"]["cnn-rgb"]["tuned"]) == 3


def test_tuned_settings_are_used_and_the_run_is_seeded(tmp_path, tiny_config, fake_world, monkeypatch):
    from lv3d.baselines import cnn

    used = []
    original = cnn.CNNClassifier.fit

    def spy(self, x, labels, seed=0):
        used.append((self.settings.width, self.settings.epochs, x.shape[-1]))
        return original(self, x, labels, seed)

    monkeypatch.setattr(cnn.CNNClassifier, "fit", spy)
    runs = []
    for name in ("a", "b"):
        monkeypatch.setattr(tuning, "_CACHE", {})  # the second run searches again, not from the cache
        used.clear()
        run_study(tiny_config, tmp_path / name, ["systems=[cnn-rgb]", *TINY_GRID], progress=False)
        runs.append([_strip(_fold(tmp_path / name, "cnn-rgb", k)) for k in range(3)])
        # per fold: 4 settings x 2 inner folds in the search, then the fold's 4 tasks with the setting it chose
        assert len(used) == 3 * (4 * 2 + 4)
        for k, rec in enumerate(runs[-1]):
            chosen = (rec["tuned"]["setting"]["width"], 1, rec["tuned"]["setting"]["image_size"])
            search, tasks = used[12 * k:12 * k + 8], used[12 * k + 8:12 * k + 12]
            assert set(search) == {(w, 1, s) for w in (2, 4) for s in (8, 16)} and set(tasks) == {chosen}
    assert runs[0] == runs[1]


def test_tuning_off_leaves_result_keys_as_they_were(tiny_config):
    cfg = load_study(tiny_config).base
    d = cfg.to_dict()
    before = {**d, "baselines": {k: v for k, v in d["baselines"].items() if k not in TUNE_KEYS}}
    for system in ("cnn-rgb", "cnn-rgbd-2s", "tree-rgbd", "lv3d-rgbd"):
        facts = "f" if system.startswith("lv3d-") else None  # an lv3d result's key holds its facts' digest
        assert result_key(cfg, system, 1, facts) == result_key(before, system, 1, facts)
    on = load_study(tiny_config, TINY_GRID).base
    assert result_key(on, "cnn-rgb", 1) != result_key(cfg, "cnn-rgb", 1)
    assert result_key(on, "tree-rgbd", 1) == result_key(cfg, "tree-rgbd", 1)  # the trees are not tuned: reused
    wider = load_study(tiny_config, [*TINY_GRID, "baselines.tune_width=[2, 8]"]).base
    assert result_key(wider, "cnn-rgb", 1) != result_key(on, "cnn-rgb", 1)


@pytest.mark.parametrize("key,value,problem", [
    ("tune_image_size", [24], "must divide baselines.image_size"),
    ("tune_image_size", [4], "whole number from 8"),
    ("tune_width", [], "non-empty list"),
    ("tune_width", [8, 8], "twice"),
    ("tune_width", 8, "non-empty list"),
    ("tune_epochs", [0], "whole number from 1"),
    ("tune_augment", ["yes"], "true or false"),
    ("tune_folds", 1, "from 2"),
])
def test_bad_tuning_settings_name_the_key(key, value, problem):
    with pytest.raises(InputError, match=problem) as e:
        from_dict({"baselines": {"tune": True, key: value}}, "study.yaml")
    assert f"baselines.{key}" in str(e.value)


def test_tuning_passes_groups_and_never_splits_one(monkeypatch):
    """Examples of one real frame share a group: the inner folds keep each group on one side."""
    splits_seen = []
    original = tuning.inner_folds

    def spy(labels, groups, k, seed):
        splits = original(labels, groups, k, seed)
        splits_seen.append((groups, splits))
        return splits

    monkeypatch.setattr(tuning, "inner_folds", spy)
    monkeypatch.setattr(tuning, "_CACHE", {})
    rng = np.random.default_rng(1)
    items = [Item(f"f{g}_o{j}", ("cube", "square_pyramid")[(g + j) % 2], f"f{g}", group=f"frame{g}")
             for g in range(8) for j in range(2)]
    pixels = {it.id: rng.normal(size=(4, 16, 16)).astype(np.float32) for it in items}
    cfg = from_dict({"baselines": {"image_size": 16, "tree_cells": 4, "batch_size": 4, "tune": True,
                                   "tune_width": [2], "tune_epochs": [1], "tune_augment": [False],
                                   "tune_image_size": [8], "tune_folds": 2}}, "test")
    system = PixelSystem("cnn-depth", pixels, cfg.baselines)
    out = system.tune(items, seed=3)
    (groups, splits), = splits_seen
    assert groups == [it.group for it in items] and out["n_groups"] == 8
    for tr, te in splits:
        assert not {groups[i] for i in tr} & {groups[i] for i in te}
    assert system.tuned == out["setting"] and system._x([items[0].id]).shape == (1, 1, 8, 8)
