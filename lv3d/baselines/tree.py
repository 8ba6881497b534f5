"""CART (scikit-learn's decision tree) on downsampled pixels: the simplest statistical baseline.

Input: the (N, C, S, S) tensors of :mod:`lv3d.baselines.pixels`, further area-averaged to
``cells`` x ``cells`` per channel and flattened (so a 64x64 rgbd frame gives 4 * 16 * 16 features).
"""

from __future__ import annotations

import numpy as np
from sklearn.tree import DecisionTreeClassifier


def pool(x: np.ndarray, cells: int) -> np.ndarray:
    """(N, C, S, S) -> (N, C * cells * cells) by averaging S/cells x S/cells blocks (S divisible by cells)."""
    n, c, s, _ = x.shape
    if s % cells:
        raise ValueError(f"image size {s} is not a multiple of {cells} cells")
    b = s // cells
    return x.reshape(n, c, cells, b, cells, b).mean(axis=(3, 5)).reshape(n, -1)


class PixelTree:
    """A decision tree over pooled pixels; ``min_samples_leaf`` keeps it from memorising single images."""

    def __init__(self, cells: int = 16, max_depth: int | None = None, min_samples_leaf: int = 2):
        self.cells, self.max_depth, self.min_samples_leaf = cells, max_depth, min_samples_leaf
        self.tree: DecisionTreeClassifier | None = None

    def fit(self, x: np.ndarray, labels: list[str], seed: int = 0) -> "PixelTree":
        self.tree = DecisionTreeClassifier(max_depth=self.max_depth, min_samples_leaf=self.min_samples_leaf,
                                           random_state=seed)
        self.tree.fit(pool(x, self.cells), np.asarray(labels))
        return self

    def predict(self, x: np.ndarray) -> list[tuple[str, float]]:
        """(label, fraction of the leaf's training samples with that label) per row."""
        if self.tree is None:
            raise RuntimeError("fit the tree first")
        p = self.tree.predict_proba(pool(x, self.cells))
        k = p.argmax(axis=1)
        return [(str(self.tree.classes_[j]), float(p[i, j])) for i, j in enumerate(k)]
