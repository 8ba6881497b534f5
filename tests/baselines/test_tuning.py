"""Tuning the CNN by grouped inner cross-validation: folds, downsampling, the choice and its seed."""

import numpy as np
import pytest

from lv3d.baselines import tuning
from lv3d.baselines.pixels import frame_tensor
from lv3d.baselines.tuning import Setting, area_downsample, cost, grid, inner_folds, tune
from lv3d.camera import Intrinsics
from lv3d.errors import InputError
from lv3d.rgbd import RGBD


def _grouped(n_groups: int = 12, per_group: int = 3, classes=("a", "b", "c")):
    """Labels and groups: each group holds ``per_group`` examples of mixed classes (the objects of one frame)."""
    labels, groups = [], []
    for g in range(n_groups):
        for j in range(per_group):
            labels.append(classes[(g + j) % len(classes)])
            groups.append(f"frame{g}")
    return labels, groups


@pytest.mark.parametrize("seed", [0, 7, 123])
def test_inner_folds_never_split_a_group_and_cover_every_example(seed):
    labels, groups = _grouped()
    splits = inner_folds(labels, groups, 3, seed)
    assert len(splits) == 3
    held_out = np.concatenate([te for _, te in splits])
    assert sorted(held_out.tolist()) == list(range(len(labels)))  # each example held out exactly once
    for tr, te in splits:
        assert not {groups[i] for i in tr} & {groups[i] for i in te}
        assert sorted(tr.tolist() + te.tolist()) == list(range(len(labels)))
    again = inner_folds(labels, groups, 3, seed)
    assert all(np.array_equal(a[1], b[1]) for a, b in zip(splits, again))


def test_inner_folds_need_a_group_per_fold():
    labels, groups = _grouped(n_groups=2)
    with pytest.raises(InputError, match="at least 3 groups"):
        inner_folds(labels, groups, 3, 0)


def test_area_downsample_is_the_tensor_of_the_frame_at_that_size():
    rng = np.random.default_rng(0)
    color = rng.integers(0, 256, (96, 128, 3), dtype=np.uint8)
    depth = (1.0 + 0.2 * rng.random((96, 128))).astype(np.float32)
    depth[rng.random((96, 128)) < 0.05] = 0.0  # missing readings
    frame = RGBD(color, depth, Intrinsics(100, 100, 64, 48, 128, 96))
    small = area_downsample(frame_tensor(frame, "rgbd", 32)[None], 16)[0]
    direct = frame_tensor(frame, "rgbd", 16)
    assert small.shape == direct.shape == (4, 16, 16) and small.dtype == np.float32
    assert np.allclose(small[3], direct[3], atol=1e-5)  # depth: the same numbers
    assert np.abs(small[:3] - direct[:3]).max() <= 1.0 / 255 / 0.25 + 1e-6  # colour: within one 8-bit level
    x = np.ones((2, 1, 8, 8), np.float32)
    assert area_downsample(x, 8) is x
    with pytest.raises(InputError, match="must divide"):
        area_downsample(x, 3)


def test_grid_is_every_combination_cheapest_first():
    g = grid([16, 8], [40, 20], [True, False], [64, 32])
    assert len(g) == 16 and len(set(g)) == 16
    assert g[0] == Setting(8, 20, False, 32) and g[-1] == Setting(16, 40, True, 64)
    costs = [cost(s, "rgbd", "early") for s in g]
    assert costs == sorted(costs)
    with pytest.raises(InputError, match="widths"):
        grid([], [20], [False], [64])


class _Fake:
    """A stand-in for CNNClassifier whose held-out accuracy is set by its width: predicts the true class of an
    example when the width is ``good`` and "wrong" otherwise. Records what each fit sees."""

    good = 8
    fits: list = []

    def __init__(self, modality, arch, settings):
        self.settings = settings

    def fit(self, x, labels, seed=0):
        _Fake.fits.append((len(x), x.shape[-1], seed, self.settings.width))
        return self

    def predict(self, x):
        ok = self.settings.width == _Fake.good
        return [(str(int(v)) if ok else "wrong", 1.0) for v in x[:, 0, 0, 0]]


def _coded(n_groups: int = 8, size: int = 8):
    """Examples whose first pixel codes their class (0, 1), in groups of two."""
    labels = [str(i % 2) for i in range(2 * n_groups)]
    groups = [f"g{i // 2}" for i in range(2 * n_groups)]
    x = np.zeros((len(labels), 1, size, size), np.float32)
    x[:, 0] = np.array([float(v) for v in labels])[:, None, None]
    return x, labels, groups


def test_tune_chooses_the_best_inner_accuracy_and_the_cheaper_on_a_tie(monkeypatch):
    from lv3d.baselines import CNNSettings

    monkeypatch.setattr(tuning, "CNNClassifier", _Fake)
    monkeypatch.setattr(tuning, "_CACHE", {})
    x, labels, groups = _coded()
    settings = grid([4, 8, 16], [2], [False], [4, 8], "depth")
    _Fake.good, _Fake.fits = 8, []
    out = tune(x, labels, groups, "depth", "early", CNNSettings(), settings, 2, seed=5)
    assert out["setting"] == {"width": 8, "epochs": 2, "augment": False, "image_size": 4}  # 4 px: cheaper than 8
    assert out["inner_accuracy"] == 1.0 and out["inner_folds"] == 2 and out["n_groups"] == 8
    assert [(r["width"], r["image_size"]) for r in out["grid"]] == [(s.width, s.image_size) for s in settings]
    assert len(_Fake.fits) == len(settings) * 2
    assert {f[1] for f in _Fake.fits} == {4, 8}  # the smaller input made by downsampling
    assert len({f[2] for f in _Fake.fits}) == 2  # one seed per inner fold, the same for every setting
    _Fake.good = 0  # no setting right: all tie, the cheapest wins
    monkeypatch.setattr(tuning, "_CACHE", {})
    assert tune(x, labels, groups, "depth", "early", CNNSettings(), settings, 2, seed=5)["setting"] == \
        settings[0].to_dict()


def test_tune_takes_one_inner_fold_per_group_where_there_are_fewer_groups_than_folds(monkeypatch):
    from lv3d.baselines import CNNSettings

    monkeypatch.setattr(tuning, "CNNClassifier", _Fake)
    monkeypatch.setattr(tuning, "_CACHE", {})
    x, labels, groups = _coded(n_groups=2)  # the training folds of a small folder: two frames
    _Fake.good, _Fake.fits = 8, []
    out = tune(x, labels, groups, "depth", "early", CNNSettings(), grid([8], [2], [False], [8]), 3, seed=5)
    assert out["inner_folds"] == 2 and out["n_groups"] == 2 and len(_Fake.fits) == 2
    with pytest.raises(InputError, match="at least 2 groups"):  # one frame: no inner cross-validation
        tune(x[:2], labels[:2], groups[:2], "depth", "early", CNNSettings(), grid([8], [2], [False], [8]), 3, seed=5)


def test_tune_is_seeded_and_cached(monkeypatch):
    """The real CNN on a tiny grid: the same seed gives the same choice and scores; the cache answers a repeat."""
    from lv3d.baselines import CNNSettings

    monkeypatch.setattr(tuning, "_CACHE", {})
    rng = np.random.default_rng(0)
    x, labels, groups = _coded(n_groups=6, size=16)
    x = x + rng.normal(0, 0.3, x.shape).astype(np.float32)
    base = CNNSettings(batch_size=4)
    settings = grid([2, 4], [2], [False, True], [8, 16], "depth")
    a = tune(x, labels, groups, "depth", "early", base, settings, 2, seed=11)
    monkeypatch.setattr(tuning, "_CACHE", {})
    b = tune(x, labels, groups, "depth", "early", base, settings, 2, seed=11)
    strip = lambda r: {k: v for k, v in r.items() if k != "seconds"}  # noqa: E731
    assert strip(a) == strip(b)
    assert a["setting"] in [s.to_dict() for s in settings]
    fits = []
    monkeypatch.setattr(tuning.CNNClassifier, "fit", lambda *args, **kw: fits.append(1))
    assert tune(x, labels, groups, "depth", "early", base, settings, 2, seed=11) == b and not fits


def test_tune_rejects_mismatched_inputs():
    from lv3d.baselines import CNNSettings

    x, labels, groups = _coded()
    with pytest.raises(InputError, match="labels"):
        tune(x, labels[:-1], groups, "depth", "early", CNNSettings(), grid([4], [1], [False], [8]), 2, 0)
