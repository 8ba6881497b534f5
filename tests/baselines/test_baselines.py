"""The baselines learn a trivially separable synthetic task, deterministically from a seed."""

import cv2
import numpy as np
import pytest

from lv3d.baselines import CNNClassifier, CNNSettings, PixelTree, frame_tensor
from lv3d.baselines.tree import pool
from lv3d.camera import Intrinsics
from lv3d.rgbd import RGBD


def _shapes(n_per_class: int, seed: int, size: int = 32):
    """Bright squares vs bright triangles at random places on a dark background, as (N, 4, S, S)."""
    rng = np.random.default_rng(seed)
    xs, ys = [], []
    for label in ("square", "triangle"):
        for _ in range(n_per_class):
            img = np.zeros((size, size), np.uint8)
            cx, cy = rng.integers(10, size - 10, 2)
            r = int(rng.integers(6, 9))
            if label == "square":
                cv2.rectangle(img, (int(cx - r), int(cy - r)), (int(cx + r), int(cy + r)), 255, -1)
            else:
                pts = np.array([[cx, cy - r], [cx - r, cy + r], [cx + r, cy + r]], np.int32)
                cv2.fillPoly(img, [pts], 255)
            x = np.repeat(img[None].astype(np.float32) / 64.0, 4, axis=0)
            xs.append(x + rng.normal(0, 0.05, x.shape).astype(np.float32))
            ys.append(label)
    return np.stack(xs), ys


def test_frame_tensor_layout_and_relative_depth():
    color = np.full((48, 64, 3), 255, np.uint8)
    depth = np.full((48, 64), 1.0, np.float32)
    depth[:, :8] = 0.0  # outside the central square: must not matter
    depth[20:28, 28:36] = 0.9  # an object 10 cm nearer than the table
    frame = RGBD(color, depth, Intrinsics(60, 60, 32, 24, 64, 48))
    t = frame_tensor(frame, "rgbd", size=16)
    assert t.shape == (4, 16, 16) and t.dtype == np.float32
    assert np.allclose(t[:3], 2.0)  # white: (1 - 0.5) / 0.25
    assert t[3].min() < -0.5 and np.isclose(np.median(t[3]), 0.0)
    assert frame_tensor(frame, "depth", size=16).shape == (1, 16, 16)


def test_pool_averages_blocks():
    x = np.arange(16, dtype=np.float32).reshape(1, 1, 4, 4)
    assert np.allclose(pool(x, 2), [[2.5, 4.5, 10.5, 12.5]])


def test_tree_learns_and_is_deterministic():
    x, y = _shapes(12, seed=1)
    xt, yt = _shapes(6, seed=2)
    a = PixelTree(cells=8).fit(x, y, seed=3).predict(xt)
    b = PixelTree(cells=8).fit(x, y, seed=3).predict(xt)
    assert a == b
    assert all(label in ("square", "triangle") and 0 < conf <= 1 for label, conf in a)


@pytest.mark.parametrize("modality,arch", [("rgb", "early"), ("rgbd", "twostream")])
def test_cnn_learns_separable_shapes_deterministically(modality, arch):
    x, y = _shapes(16, seed=1)
    xt, yt = _shapes(8, seed=2)
    ch = slice(0, 3) if modality == "rgb" else slice(0, 4)
    settings = CNNSettings(epochs=12, batch_size=8, width=8, threads=1)
    p1 = CNNClassifier(modality, arch, settings).fit(x[:, ch], y, seed=5).predict(xt[:, ch])
    p2 = CNNClassifier(modality, arch, settings).fit(x[:, ch], y, seed=5).predict(xt[:, ch])
    assert p1 == p2
    acc = np.mean([label == truth for (label, _), truth in zip(p1, yt)])
    assert acc >= 0.75


def test_two_stream_needs_rgbd():
    with pytest.raises(ValueError, match="rgbd"):
        CNNClassifier("rgb", "twostream")


def test_augment_is_seeded_and_keeps_shape_and_channel_alignment():
    import torch

    from lv3d.baselines.augment import augment, geometric

    x = torch.from_numpy(_shapes(4, seed=3)[0])
    a = augment(x, torch.Generator().manual_seed(1), color=True)
    b = augment(x, torch.Generator().manual_seed(1), color=True)
    c = augment(x, torch.Generator().manual_seed(2), color=True)
    assert a.shape == x.shape and torch.equal(a, b) and not torch.equal(a, c)
    # geometric warps move every channel alike: identical channels stay identical
    same = x[:, :1].repeat(1, 4, 1, 1)
    g = geometric(same, torch.Generator().manual_seed(1))
    assert torch.allclose(g[:, 0], g[:, 3]) and not torch.allclose(g, same)


def test_validation_split_is_stratified_or_absent():
    import torch

    from lv3d.baselines.cnn import MIN_PER_CLASS_FOR_VAL, validation_split

    y = torch.tensor([0] * 40 + [1] * 60)
    tr, val = validation_split(y, 2, 0.15, torch.Generator().manual_seed(0))
    assert sorted(tr.tolist() + val.tolist()) == list(range(100))
    assert torch.bincount(y[val]).tolist() == [6, 9]
    small = torch.tensor([0] * (MIN_PER_CLASS_FOR_VAL - 1) + [1] * 30)
    tr, val = validation_split(small, 2, 0.15, torch.Generator().manual_seed(0))
    assert val is None and len(tr) == len(small)


def test_cnn_with_augmentation_and_early_stopping_learns():
    x, y = _shapes(20, seed=4)
    xt, yt = _shapes(8, seed=5)
    settings = CNNSettings(epochs=15, batch_size=8, width=8, augment=True, patience=4)
    m = CNNClassifier("rgbd", "early", settings).fit(x, y, seed=1)
    assert 1 <= m.epochs_run <= 15
    acc = np.mean([label == truth for (label, _), truth in zip(m.predict(xt), yt)])
    assert acc >= 0.75
