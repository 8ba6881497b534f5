"""A small CNN trained from scratch on the CPU: the statistical baseline the learner is compared with.

Two ways to see RGB-D: *early fusion* (one tower over the 4-channel rgbd tensor) and *two-stream*
(a colour tower and a depth tower, features concatenated before the classifier). Inputs are the
(C, S, S) tensors of :mod:`lv3d.baselines.pixels`. Training is seeded (``torch.manual_seed``; kornia
draws its augmentation from the same generator) and uses ``threads`` CPU threads.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch
from torch import nn

ARCHS = ("early", "twostream")


@dataclass(frozen=True)
class CNNSettings:
    """``epochs`` over the training set in mini-batches of ``batch_size``; Adam with ``lr`` and
    ``weight_decay``; ``augment``: random horizontal flip and affine on all channels, colour jitter
    on the colour channels; ``width``: channels of the first conv layer (doubled per block)."""

    epochs: int = 40
    batch_size: int = 16
    lr: float = 3e-3
    weight_decay: float = 1e-4
    augment: bool = True
    width: int = 16
    threads: int = 1

    def to_dict(self) -> dict:
        return asdict(self)


def _tower(in_ch: int, width: int) -> nn.Sequential:
    """Three conv blocks (conv 3x3, batch norm, ReLU, 2x2 max pool), then global average pooling."""
    layers, c = [], in_ch
    for k in range(3):
        out = width * 2 ** k
        layers += [nn.Conv2d(c, out, 3, padding=1), nn.BatchNorm2d(out), nn.ReLU(), nn.MaxPool2d(2)]
        c = out
    layers += [nn.AdaptiveAvgPool2d(1), nn.Flatten()]
    return nn.Sequential(*layers)


class EarlyFusionCNN(nn.Module):
    """One tower over all input channels."""

    def __init__(self, in_ch: int, n_classes: int, width: int = 16):
        super().__init__()
        self.tower = _tower(in_ch, width)
        self.head = nn.Linear(width * 4, n_classes)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(self.tower(x))


class TwoStreamCNN(nn.Module):
    """A colour tower over channels 0-2 and a depth tower over channel 3, fused late."""

    def __init__(self, n_classes: int, width: int = 16):
        super().__init__()
        self.rgb = _tower(3, width)
        self.depth = _tower(1, width)
        self.head = nn.Linear(width * 8, n_classes)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(torch.cat([self.rgb(x[:, :3]), self.depth(x[:, 3:4])], dim=1))


def _augmenter(n_channels: int):
    """Geometric augmentation on every channel; colour jitter on the first three when they are colour."""
    import kornia.augmentation as K

    geometric = nn.Sequential(K.RandomHorizontalFlip(p=0.5),
                              K.RandomAffine(degrees=10.0, translate=(0.08, 0.08), scale=(0.9, 1.1), p=0.8))
    jitter = K.ColorJitter(0.2, 0.2, 0.2, 0.02, p=0.8) if n_channels in (3, 4) else None

    def augment(x: torch.Tensor) -> torch.Tensor:
        x = geometric(x)
        if jitter is not None:
            # ColorJitter works on [0, 1] colour: undo the pixel normalisation, jitter, redo it
            rgb = jitter((x[:, :3] * 0.25 + 0.5).clamp(0, 1)) * 4.0 - 2.0
            x = torch.cat([rgb, x[:, 3:]], dim=1)
        return x

    return augment


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

    def _make_net(self, in_ch: int, n_classes: int) -> nn.Module:
        w = self.settings.width
        return TwoStreamCNN(n_classes, w) if self.arch == "twostream" else EarlyFusionCNN(in_ch, n_classes, w)

    def fit(self, x: np.ndarray, labels: list[str], seed: int = 0) -> "CNNClassifier":
        s = self.settings
        self.classes = sorted(set(labels))
        y = torch.tensor([self.classes.index(l) for l in labels])
        xt = torch.from_numpy(np.ascontiguousarray(x, dtype=np.float32))
        old_threads = torch.get_num_threads()
        torch.set_num_threads(max(1, s.threads))
        try:
            torch.manual_seed(seed)
            self.net = self._make_net(xt.shape[1], len(self.classes))
            opt = torch.optim.Adam(self.net.parameters(), lr=s.lr, weight_decay=s.weight_decay)
            augment = _augmenter(xt.shape[1]) if s.augment else (lambda t: t)
            order_gen = torch.Generator().manual_seed(seed)
            self.net.train()
            for _ in range(s.epochs):
                order = torch.randperm(len(xt), generator=order_gen)
                for start in range(0, len(xt), s.batch_size):
                    idx = order[start:start + s.batch_size]
                    if len(idx) < 2:  # batch norm needs two samples
                        continue
                    with torch.no_grad():
                        xb = augment(xt[idx])
                    loss = nn.functional.cross_entropy(self.net(xb), y[idx])
                    opt.zero_grad()
                    loss.backward()
                    opt.step()
        finally:
            torch.set_num_threads(old_threads)
        return self

    def predict_proba(self, x: np.ndarray) -> np.ndarray:
        """(N, n_classes) class probabilities, columns in ``self.classes`` order."""
        if self.net is None:
            raise RuntimeError("fit the classifier first")
        self.net.eval()
        with torch.no_grad():
            logits = self.net(torch.from_numpy(np.ascontiguousarray(x, dtype=np.float32)))
        return torch.softmax(logits, dim=1).numpy()

    def predict(self, x: np.ndarray) -> list[tuple[str, float]]:
        """(label, probability of that label) per row."""
        p = self.predict_proba(x)
        return [(self.classes[int(k)], float(p[i, k])) for i, k in enumerate(p.argmax(axis=1))]
