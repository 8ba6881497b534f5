"""A small CNN trained from scratch on the CPU: the statistical baseline the learner is compared with.

Two ways to see RGB-D: *early fusion* (one tower over the 4-channel rgbd tensor) and *two-stream*
(a colour tower and a depth tower, features concatenated before the classifier). Inputs are the
(C, S, S) tensors of :mod:`lv3d.baselines.pixels`. Training is seeded (``torch.manual_seed`` for the
weights, one ``torch.Generator`` for batch order, validation split and augmentation), runs with
deterministic algorithms on ``threads`` CPU threads, and can stop early on a held-out validation split.

Speed (issue 6): one training on ~100-160 images of 64x64 must take seconds on two cores, so the
tower starts with a stride-2 convolution (no full-resolution feature maps), augmentation (when on)
is one call per batch (:mod:`lv3d.baselines.augment`), training runs one thread and 20 epochs.
"""

from __future__ import annotations

import copy
from dataclasses import asdict, dataclass

import numpy as np
import torch
from torch import nn

from .augment import augment as augment_batch

ARCHS = ("early", "twostream")


@dataclass(frozen=True)
class CNNSettings:
    """At most ``epochs`` over the training set in mini-batches of ``batch_size``; Adam with ``lr``
    and ``weight_decay``; ``augment``: see :mod:`lv3d.baselines.augment`; ``width``: channels of the
    first conv layer (doubled per block); ``threads``: CPU threads for torch.

    Defaults chosen on a dev data set (seed 1234, not the seed protocol's), see
    benchmarks/bench_baselines.py: one thread (two threads on two shared cores ran ~1.7x slower:
    OpenMP threads wait on each other), 20 epochs, no augmentation and no early stopping (on ~24
    validation images it stopped at chance; augmentation did not raise dev accuracy at this size).

    Early stopping: when every class has at least ``MIN_PER_CLASS_FOR_VAL`` examples, a seeded,
    stratified ``val_fraction`` of them is held out; training stops after ``patience`` epochs without
    a lower validation loss and keeps the weights of the best epoch. Otherwise (tiny training sets,
    e.g. the demo) it trains all ``epochs`` on everything. ``patience`` 0 turns early stopping off."""

    epochs: int = 20
    batch_size: int = 16
    lr: float = 3e-3
    weight_decay: float = 1e-4
    augment: bool = False
    width: int = 16
    threads: int = 1
    patience: int = 0
    val_fraction: float = 0.15

    def to_dict(self) -> dict:
        return asdict(self)


POOL_CELLS = 2  # last map pooled to 2x2 cells, not 1: the head keeps coarse layout (better than 1 or 3 on dev)
MIN_PER_CLASS_FOR_VAL = 10  # below this a validation split costs more training data than it is worth


def _tower(in_ch: int, width: int) -> nn.Sequential:
    """A stride-2 5x5 stem (S -> S/2), then two blocks (conv 3x3, batch norm, ReLU, 2x2 max pool),
    then global average pooling: (N, in_ch, S, S) -> (N, 4 * width)."""
    layers = [nn.Conv2d(in_ch, width, 5, stride=2, padding=2), nn.BatchNorm2d(width), nn.ReLU()]
    c = width
    for k in (1, 2):
        out = width * 2 ** k
        layers += [nn.Conv2d(c, out, 3, padding=1), nn.BatchNorm2d(out), nn.ReLU(), nn.MaxPool2d(2)]
        c = out
    layers += [nn.AdaptiveAvgPool2d(POOL_CELLS), nn.Flatten()]
    return nn.Sequential(*layers)


class EarlyFusionCNN(nn.Module):
    """One tower over all input channels."""

    def __init__(self, in_ch: int, n_classes: int, width: int = 16):
        super().__init__()
        self.tower = _tower(in_ch, width)
        self.head = nn.Linear(width * 4 * POOL_CELLS ** 2, n_classes)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(self.tower(x))


class TwoStreamCNN(nn.Module):
    """A colour tower over channels 0-2 and a depth tower over channel 3, fused late."""

    def __init__(self, n_classes: int, width: int = 16):
        super().__init__()
        self.rgb = _tower(3, width)
        self.depth = _tower(1, width)
        self.head = nn.Linear(width * 8 * POOL_CELLS ** 2, n_classes)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(torch.cat([self.rgb(x[:, :3]), self.depth(x[:, 3:4])], dim=1))


def validation_split(y: torch.Tensor, n_classes: int, fraction: float, gen: torch.Generator
                     ) -> tuple[torch.Tensor, torch.Tensor | None]:
    """(training indices, validation indices or None): a seeded stratified split of the labels ``y``
    (N,), or everything for training when some class has fewer than MIN_PER_CLASS_FOR_VAL examples."""
    counts = torch.bincount(y, minlength=n_classes)
    if fraction <= 0 or int(counts.min()) < MIN_PER_CLASS_FOR_VAL:
        return torch.arange(len(y)), None
    train, val = [], []
    for c in range(n_classes):
        members = torch.nonzero(y == c).flatten()
        members = members[torch.randperm(len(members), generator=gen)]
        k = max(2, round(fraction * len(members)))
        val.append(members[:k])
        train.append(members[k:])
    return torch.sort(torch.cat(train)).values, torch.sort(torch.cat(val)).values


class _TorchState:
    """Threads and determinism for one training, restored afterwards (other code shares the process)."""

    def __init__(self, threads: int):
        self.threads = max(1, threads)

    def __enter__(self):
        self.old = (torch.get_num_threads(), torch.are_deterministic_algorithms_enabled())
        torch.set_num_threads(self.threads)
        try:  # one inter-op thread: nothing here runs ops in parallel; only settable before first use
            torch.set_num_interop_threads(1)
        except RuntimeError:
            pass
        torch.use_deterministic_algorithms(True)
        torch.set_flush_denormal(True)  # tiny weights late in training must not fall to slow denormals
        return self

    def __exit__(self, *exc):
        torch.set_num_threads(self.old[0])
        torch.use_deterministic_algorithms(self.old[1])
        torch.set_flush_denormal(False)
        return False


class CNNClassifier:
    """Classifier over (N, C, S, S) float32 pixel tensors and string labels.

    ``modality`` says what the channels are ('rgb': 3, 'depth': 1, 'rgbd': 4); ``arch`` is 'early'
    or 'twostream' (rgbd only)."""

    def __init__(self, modality: str, arch: str = "early", settings: CNNSettings | None = None):
        if arch not in ARCHS:
            raise ValueError(f"unknown CNN architecture {arch!r}; choose one of {ARCHS}")
        if arch == "twostream" and modality != "rgbd":
            raise ValueError("the two-stream CNN needs rgbd input")
        self.modality, self.arch = modality, arch
        self.settings = settings or CNNSettings()
        self.classes: list[str] = []
        self.net: nn.Module | None = None
        self.epochs_run = 0  # epochs the last fit ran (fewer than settings.epochs when it stopped early)

    def _make_net(self, in_ch: int, n_classes: int) -> nn.Module:
        w = self.settings.width
        return TwoStreamCNN(n_classes, w) if self.arch == "twostream" else EarlyFusionCNN(in_ch, n_classes, w)

    def fit(self, x: np.ndarray, labels: list[str], seed: int = 0) -> "CNNClassifier":
        """Train on (N, C, S, S) pixels and N labels; the same seed gives the same weights."""
        s = self.settings
        self.classes = sorted(set(labels))
        self.epochs_run = 0
        y = torch.tensor([self.classes.index(l) for l in labels])
        xt = torch.from_numpy(np.ascontiguousarray(x, dtype=np.float32))  # converted once, reused every epoch
        color = self.modality in ("rgb", "rgbd")
        with _TorchState(s.threads), torch.random.fork_rng(devices=[]):
            torch.manual_seed(seed)
            gen = torch.Generator().manual_seed(seed)
            self.net = self._make_net(xt.shape[1], len(self.classes))
            opt = torch.optim.Adam(self.net.parameters(), lr=s.lr, weight_decay=s.weight_decay)
            tr, val = validation_split(y, len(self.classes), s.val_fraction if s.patience > 0 else 0.0, gen)
            x_tr, y_tr = xt[tr], y[tr]
            # inverse-frequency class weights: a class task's 40 positives vs 60 negatives must not
            # settle on "always negative"
            counts = torch.bincount(y_tr, minlength=len(self.classes)).float().clamp(min=1)
            weight = counts.sum() / (len(self.classes) * counts)
            best, best_state, stale = float("inf"), None, 0
            for epoch in range(s.epochs):
                self.net.train()
                order = torch.randperm(len(x_tr), generator=gen)
                for start in range(0, len(x_tr), s.batch_size):
                    idx = order[start:start + s.batch_size]
                    if len(idx) < 2:  # batch norm needs two samples
                        continue
                    xb = x_tr[idx]
                    if s.augment:
                        with torch.no_grad():
                            xb = augment_batch(xb, gen, color)
                    loss = nn.functional.cross_entropy(self.net(xb), y_tr[idx], weight=weight)
                    opt.zero_grad(set_to_none=True)
                    loss.backward()
                    opt.step()
                self.epochs_run = epoch + 1
                if val is None:
                    continue
                self.net.eval()
                with torch.no_grad():
                    v = float(nn.functional.cross_entropy(self.net(xt[val]), y[val]))
                if v < best - 1e-4:
                    best, best_state, stale = v, copy.deepcopy(self.net.state_dict()), 0
                else:
                    stale += 1
                    if stale >= s.patience:
                        break
            if best_state is not None:
                self.net.load_state_dict(best_state)
        return self

    def predict_proba(self, x: np.ndarray) -> np.ndarray:
        """(N, n_classes) class probabilities, columns in ``self.classes`` order."""
        if self.net is None:
            raise RuntimeError("fit the classifier first")
        self.net.eval()
        with _TorchState(self.settings.threads), torch.no_grad():
            logits = self.net(torch.from_numpy(np.ascontiguousarray(x, dtype=np.float32)))
        return torch.softmax(logits, dim=1).numpy()

    def predict(self, x: np.ndarray) -> list[tuple[str, float]]:
        """(label, probability of that label) per row."""
        p = self.predict_proba(x)
        return [(self.classes[int(k)], float(p[i, k])) for i, k in enumerate(p.argmax(axis=1))]
