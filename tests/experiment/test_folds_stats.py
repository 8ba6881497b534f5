"""Folds are stratified, seeded and disjoint; the paired tests give the textbook p-values."""

import math

import numpy as np
import pytest

from lv3d.experiment.folds import Item, class_task, multiclass_task, split, stratified_folds
from lv3d.experiment.stats import mean_diff_ci, mean_std, paired, sign_test, wilcoxon_test


def _items(per_class=10, classes=("a", "b", "c", "d")):
    return [Item(f"s{c}{i:03d}", c, f"s{c}{i:03d}") for c in classes for i in range(per_class)]


def test_folds_are_stratified_disjoint_and_cover():
    items = _items(10)
    folds = stratified_folds(items, 5, seed=7)
    assert sorted(it.id for f in folds for it in f) == sorted(it.id for it in items)
    for f in folds:
        assert {c: sum(it.cls == c for it in f) for c in "abcd"} == {c: 2 for c in "abcd"}
    for k in range(5):
        train, test = split(folds, k)
        assert not {it.id for it in train} & {it.id for it in test}
        assert len(train) == 32 and len(test) == 8


def test_same_seed_same_folds_other_seed_other_folds():
    items = _items(10)
    assert stratified_folds(items, 5, 1) == stratified_folds(items, 5, 1)
    assert stratified_folds(items, 5, 1) != stratified_folds(items, 5, 2)


def test_class_task_draws_the_protocol_sample_from_training_folds():
    items = _items(50)
    train, test = split(stratified_folds(items, 5, 0), 0)
    ex, pos = class_task(train, "a", 40, 1.5, seed=3)
    assert sum(pos) == 40 and len(pos) - sum(pos) == 60
    assert all(it.cls == "a" for it, p in zip(ex, pos) if p)
    assert {c: sum(it.cls == c for it in ex) for c in "bcd"} == {"b": 20, "c": 20, "d": 20}
    assert not {it.id for it in ex} & {it.id for it in test}
    assert class_task(train, "a", 40, 1.5, 3) == (ex, pos)
    small, spos = class_task(train, "a", 2, 1.5, 3)
    assert sum(spos) == 2 and len(spos) - sum(spos) == 3  # ceil(1.5 * 2 / 3) = 1 of each other class
    assert len(multiclass_task(train, 4, 3)) == 16


def test_sign_test_known_p():
    # 8 wins, 0 losses, 2 ties: p = 2 * 0.5**8
    r = sign_test([1.0] * 8 + [0.5, 0.5], [0.5] * 8 + [0.5, 0.5])
    assert (r["wins"], r["losses"], r["ties"]) == (8, 0, 2)
    assert r["p"] == pytest.approx(2 * 0.5 ** 8)


def test_wilcoxon_known_p():
    # five positive differences of distinct size: exact p = 2 / 2**5
    r = wilcoxon_test([0.9, 0.8, 0.7, 0.95, 0.85], [0.8, 0.6, 0.4, 0.55, 0.35])
    assert r["n"] == 5 and r["p"] == pytest.approx(0.0625)
    assert wilcoxon_test([0.5, 0.5], [0.5, 0.5])["p"] == 1.0


def test_tests_see_equal_differences_as_equal():
    # accuracies on a 40-image fold: 0.975 - 0.95 and 1.0 - 0.975 differ in the last bits, which would make
    # scipy rank them apart (and take its exact, tie-free distribution); on whole answers they tie
    a = [0.975, 1.0, 0.95, 0.925, 0.9, 0.8, 1.0, 0.975, 0.6]
    b = [0.95, 0.975, 0.975, 0.95, 0.875, 1.0, 0.95, 0.925, 0.6]
    whole = wilcoxon_test([40 * x for x in a], [40 * x for x in b])
    assert wilcoxon_test(a, b)["p"] == pytest.approx(whole["p"])
    assert (sign_test(a, b)["wins"], sign_test(a, b)["losses"], sign_test(a, b)["ties"]) == (5, 3, 1)


def test_mean_diff_ci_is_seeded_and_holds_the_mean():
    rng = np.random.default_rng(3)
    a, b = rng.uniform(0.6, 1.0, 20), rng.uniform(0.4, 0.8, 20)
    lo, hi = mean_diff_ci(a, b)
    assert lo < float(np.mean(a - b)) < hi and hi - lo < 0.3
    assert mean_diff_ci(a, b) == (lo, hi)                      # the same seed, the same interval
    assert mean_diff_ci(a, b, level=0.5)[0] > lo               # a lower level, a narrower interval
    assert mean_diff_ci([0.9, 0.8], [0.8, 0.7]) == pytest.approx((0.1, 0.1))  # every cell differs alike
    assert all(math.isnan(x) for x in mean_diff_ci([0.9], [0.8]))


def test_paired_and_mean_std():
    r = paired([1.0, 0.9], [0.8, 0.9])
    assert r["mean_diff"] == pytest.approx(0.1) and r["sign"]["ties"] == 1
    assert mean_std([0.5, 1.0]) == pytest.approx((0.75, 0.3535533905932738))
    assert mean_std([0.4]) == (0.4, 0.0)
