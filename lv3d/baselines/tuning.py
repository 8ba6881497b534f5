"""Choosing the CNN's settings by inner cross-validation on one outer fold's training examples.

What is tuned: the first layer's width, the number of epochs, augmentation (off, on) and the input size
(pixels a side). The grid is every combination of the values given (:func:`grid`); each setting is
trained on the inner training folds and scored on the inner held-out fold, on the multi-class task over
every example given, and the setting with the best mean inner accuracy is chosen; on a tie, the cheaper
one (:func:`cost`: multiply-adds of the convolutions per image times epochs, then augmentation off
before on). Every setting sees the same inner folds and the same training seeds, so settings are
compared on the same splits.

Inner folds (:func:`inner_folds`): stratified by class and grouped, so that the examples of one group
(the objects of one real frame) are never split between an inner training fold and its held-out fold.

Input size: a smaller input is the cached tensor area-downsampled by a whole factor (:func:`area_downsample`:
the mean of each f x f block). The tensors are made by area resampling of the frame's central square
(:mod:`lv3d.baselines.pixels`), and the mean of block means over equal blocks is the mean over their
union, so this is the tensor the frame itself would give at that size (to float rounding; the depth
channel's median is taken at full resolution either way). The network is the same at any input size
(its last map is pooled to a fixed grid), only its cost changes.

Results are cached in this process by a digest of everything they depend on (pixels, labels, groups,
settings, grid, folds, seed): a sweep whose conditions share the training folds (a learning curve)
tunes once per fold and process.
"""

from __future__ import annotations

import hashlib
import json
import time
import warnings
from dataclasses import asdict, dataclass, replace
from itertools import product

import numpy as np

from ..errors import InputError
from .cnn import CNNClassifier, CNNSettings


@dataclass(frozen=True)
class Setting:
    """One point of the grid: ``width`` channels of the first layer, ``epochs``, ``augment`` and
    ``image_size`` (input pixels a side)."""

    width: int
    epochs: int
    augment: bool
    image_size: int

    def to_dict(self) -> dict:
        return asdict(self)


def conv_macs(width: int, size: int, in_ch: int) -> int:
    """Multiply-adds of one tower's convolutions on one (in_ch, size, size) image (lv3d.baselines.cnn._tower:
    a stride-2 5x5 stem, then 3x3 convolutions at size/2 and, after a 2x2 pool, at size/4)."""
    half = (size + 1) // 2
    quarter = half // 2
    return in_ch * width * 25 * half ** 2 + width * 2 * width * 9 * half ** 2 + 2 * width * 4 * width * 9 * quarter ** 2


def cost(s: Setting, modality: str, arch: str) -> tuple:
    """The order in which ties are broken, cheapest first: conv multiply-adds per image x epochs, then
    augmentation off before on, then the setting itself (a total order)."""
    ins = (3, 1) if arch == "twostream" else ({"rgb": 3, "depth": 1, "rgbd": 4}[modality],)
    macs = sum(conv_macs(s.width, s.image_size, c) for c in ins)
    return macs * s.epochs, s.augment, s.width, s.epochs, s.image_size


def grid(widths, epochs, augment, sizes, modality: str = "rgbd", arch: str = "early") -> list[Setting]:
    """Every combination of the values, cheapest first (:func:`cost`)."""
    for name, values in (("widths", widths), ("epochs", epochs), ("augment", augment), ("sizes", sizes)):
        if not len(values):
            raise InputError("tuning grid", f"{name}: give at least one value")
    settings = {Setting(int(w), int(e), bool(a), int(s)) for w, e, a, s in product(widths, epochs, augment, sizes)}
    return sorted(settings, key=lambda s: cost(s, modality, arch))


def area_downsample(x: np.ndarray, size: int) -> np.ndarray:
    """(N, C, S, S) -> (N, C, size, size): the mean of each (S/size)^2 block; ``size`` must divide S."""
    s = x.shape[-1]
    if size == s:
        return x
    if size < 1 or size > s or s % size:
        raise InputError("tuning grid", f"an input size must divide the tensors' size ({s} px), got {size}")
    f = s // size
    n, c = x.shape[:2]
    return x.reshape(n, c, size, f, size, f).mean(axis=(3, 5), dtype=np.float32)


def inner_folds(labels: list[str], groups: list[str], k: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """k (training indices, held-out indices) splits of the examples, stratified by label, each group
    wholly on one side; seeded (sklearn's StratifiedGroupKFold with shuffled groups)."""
    from sklearn.model_selection import StratifiedGroupKFold

    n_groups = len(set(groups))
    if k < 2 or n_groups < k:
        raise InputError("tuning", f"inner cross-validation needs at least {max(k, 2)} groups of examples "
                                   f"(one per inner fold), got {n_groups}")
    splitter = StratifiedGroupKFold(n_splits=k, shuffle=True, random_state=int(seed) % 2 ** 32)
    with warnings.catch_warnings():  # a class with fewer groups than folds: some inner folds lack it
        warnings.simplefilter("ignore", UserWarning)
        return [(np.asarray(tr), np.asarray(te)) for tr, te in splitter.split(np.zeros(len(labels)), labels, groups)]


_CACHE: dict[str, dict] = {}
_CACHE_SIZE = 64


def _digest(x: np.ndarray, labels, groups, modality, arch, base: CNNSettings, settings, k, seed) -> str:
    h = hashlib.sha256(np.ascontiguousarray(x, dtype=np.float32).tobytes())
    h.update(json.dumps([list(x.shape), list(labels), list(groups), modality, arch, base.to_dict(),
                         [s.to_dict() for s in settings], k, int(seed)]).encode())
    return h.hexdigest()


def tune(x: np.ndarray, labels: list[str], groups: list[str], modality: str, arch: str, base: CNNSettings,
         settings: list[Setting], k: int, seed: int) -> dict:
    """Choose among ``settings`` (cheapest first, as :func:`grid` orders them) by ``k``-fold inner
    cross-validation of the multi-class task on (N, C, S, S) pixels ``x`` with ``labels`` and ``groups``;
    ``base`` gives every other training setting. Where the examples hold fewer groups than ``k`` (a small
    folder's training folds: fewer frames), one inner fold per group. Returns ``{"setting": chosen
    (Setting.to_dict()), "inner_accuracy": its mean, "inner_folds": the folds used, "n_examples", "n_groups",
    "seed", "grid": [each setting with its mean "accuracy" and "per_fold" accuracies, in grid order], "seconds":
    wall time of the search}``. The same arguments give the same choice."""
    if len(labels) != len(x) or len(groups) != len(x):
        raise InputError("tuning", f"{len(x)} examples but {len(labels)} labels and {len(groups)} groups")
    if not settings:
        raise InputError("tuning", "an empty grid of settings")
    key = _digest(x, labels, groups, modality, arch, base, settings, k, seed)
    if key in _CACHE:
        return json.loads(json.dumps(_CACHE[key]))
    t0 = time.perf_counter()
    k = min(k, max(2, len(set(groups))))  # below two groups inner_folds says what is missing
    splits = inner_folds(labels, groups, k, seed)
    fold_seeds = [int(s) for s in np.random.SeedSequence([int(seed) % 2 ** 32]).generate_state(k)]
    y = np.asarray(labels)
    inputs = {size: area_downsample(x, size) for size in sorted({s.image_size for s in settings})}
    scores = []
    for s in settings:
        xs = inputs[s.image_size]
        model_settings = replace(base, width=s.width, epochs=s.epochs, augment=s.augment)
        per_fold = []
        for (tr, te), fseed in zip(splits, fold_seeds):
            model = CNNClassifier(modality, arch, model_settings).fit(xs[tr], list(y[tr]), seed=fseed)
            pred = [label for label, _ in model.predict(xs[te])]
            per_fold.append(float(np.mean([p == t for p, t in zip(pred, y[te])])))
        scores.append({**s.to_dict(), "accuracy": float(np.mean(per_fold)), "per_fold": per_fold})
    # the first of the best in grid order: the cheapest on a tie (rounded: equal means may differ in the last bit)
    best = max(range(len(scores)), key=lambda i: (round(scores[i]["accuracy"], 9), -i))
    out = {"setting": settings[best].to_dict(), "inner_accuracy": scores[best]["accuracy"], "inner_folds": k,
           "n_examples": len(labels), "n_groups": len(set(groups)), "seed": int(seed), "grid": scores,
           "seconds": round(time.perf_counter() - t0, 3)}
    if len(_CACHE) >= _CACHE_SIZE:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = json.loads(json.dumps(out))
    return out
