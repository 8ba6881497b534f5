"""Stratified, seeded folds and the training sets of each task drawn from them.

Folds: within each class the items are shuffled with the seed and dealt round-robin to the k
folds, so every fold holds per_class / k items of each class (up to one more or less), and the
same seed always gives the same folds. A *class task* for class c trains on ``positives`` items of
c and ``negatives_per_positive * positives`` items of the other classes (spread evenly over them),
all drawn from the training folds; it is tested on every item of the held-out fold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class Item:
    """One example of a study: its id, class and where its pixels are (a rendered image's folder relative to
    the data set; a labelled real object's frame). ``group``: examples that must stay in one fold (the
    objects of one real frame); empty means the example is its own group."""

    id: str
    cls: str
    dir: str
    group: str = ""

    @property
    def group_key(self) -> str:
        return self.group or self.id


def fold_path(out: Path, condition: str, system: str, fold: int) -> Path:
    """Where a study in ``out`` keeps the result of one (condition, system, held-out fold)."""
    return Path(out) / "folds" / condition / system / f"fold{fold}.json"


def stratified_folds(items: list[Item], k: int, seed: int) -> list[list[Item]]:
    """k disjoint folds covering ``items``, each with an even share of every class."""
    rng = np.random.default_rng(seed)
    folds: list[list[Item]] = [[] for _ in range(k)]
    offset = 0
    for cls in sorted({it.cls for it in items}):
        members = sorted((it for it in items if it.cls == cls), key=lambda it: it.id)
        for j, idx in enumerate(rng.permutation(len(members))):
            # continue dealing where the last class stopped, so small classes do not all land in fold 0
            folds[(offset + j) % k].append(members[idx])
        offset += len(members)
    return [sorted(f, key=lambda it: it.id) for f in folds]


def split(folds: list[list[Item]], test_fold: int) -> tuple[list[Item], list[Item]]:
    """(training items, test items) for one held-out fold."""
    train = [it for j, f in enumerate(folds) if j != test_fold for it in f]
    return train, list(folds[test_fold])


def class_task(train: list[Item], cls: str, positives: int, negatives_per_positive: float,
               seed: int) -> tuple[list[Item], list[bool]]:
    """Training examples of the binary task for ``cls``: (items, is_positive), seeded sample.

    Takes min(positives, available) positives and ceil(negatives_per_positive * that / n_other)
    negatives of each other class (at least one, at most what the training folds hold)."""
    rng = np.random.default_rng(seed)
    pos_pool = sorted((it for it in train if it.cls == cls), key=lambda it: it.id)
    pos = [pos_pool[i] for i in sorted(rng.permutation(len(pos_pool))[:positives])]
    others = sorted({it.cls for it in train} - {cls})
    per_other = max(1, math.ceil(negatives_per_positive * len(pos) / max(1, len(others))))
    neg = []
    for o in others:
        pool = sorted((it for it in train if it.cls == o), key=lambda it: it.id)
        neg += [pool[i] for i in sorted(rng.permutation(len(pool))[:per_other])]
    return pos + neg, [True] * len(pos) + [False] * len(neg)


def multiclass_task(train: list[Item], per_class: int, seed: int) -> list[Item]:
    """``per_class`` training items of every class (all of them if fewer), seeded sample."""
    rng = np.random.default_rng(seed)
    out = []
    for cls in sorted({it.cls for it in train}):
        pool = sorted((it for it in train if it.cls == cls), key=lambda it: it.id)
        out += [pool[i] for i in sorted(rng.permutation(len(pool))[:per_class])]
    return out


def grouped_folds(items: list[Item], k: int, seed: int) -> list[list[Item]]:
    """k disjoint folds covering ``items`` that never split a group (the labelled objects of one real frame)
    and keep each class's share as even as the groups allow (sklearn's StratifiedGroupKFold, shuffled with
    the seed)."""
    from sklearn.model_selection import StratifiedGroupKFold

    ordered = sorted(items, key=lambda it: it.id)
    splitter = StratifiedGroupKFold(n_splits=k, shuffle=True, random_state=seed % (2 ** 32))
    folds = [sorted((ordered[i] for i in test), key=lambda it: it.id)
             for _, test in splitter.split(np.zeros(len(ordered)), [it.cls for it in ordered],
                                           [it.group_key for it in ordered])]
    return folds
