"""The systems a study compares, behind one small interface.

``make_system(name, cfg, inputs)`` binds a system to what it sees of every image (``inputs``: id ->
SceneFacts for lv3d-*, id -> (4, S, S) pixel tensor for the baselines). ``fit(ids, labels, seed)``
returns a fitted system whose ``predict(ids)`` gives (label, confidence) per image (an lv3d one's
``answer(ids)`` adds how each answer was reached, which the runner keeps for multi-class answers), whose
``save(folder)`` writes what it learned that a person can read (the lv3d programs; nothing for
the baselines) and whose ``failures`` says, per class it could learn no program for, why. Labels are strings: class names, or ``not_<class>`` for the negatives of a class task.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol

import numpy as np

from .config import LOGIC_SYSTEMS, BaselineConfig, StudyConfig


class Fitted(Protocol):
    failures: dict[str, str]

    def predict(self, ids: list[str]) -> list[tuple[str, float]]: ...

    def save(self, folder: Path) -> None: ...


def negative_label(cls: str) -> str:
    return f"not_{cls}"


def modality_of(system: str) -> str:
    """'lv3d-rgbd' -> 'rgbd', 'cnn-rgbd-2s' -> 'rgbd', 'tree-depth' -> 'depth'."""
    return system.split("-")[1]


class LogicSystem:
    """The lv3d learner over the facts of one modality, with the study's learner settings (a dict of
    mil options, see lv3d.learn)."""

    def __init__(self, name: str, facts: dict, settings: dict):
        self.name, self.facts, self.settings = name, facts, dict(settings or {})

    def fit(self, ids: list[str], labels: list[str], seed: int, positive: str | None = None) -> "FittedLogic":
        """``positive``: the class of a binary class task (one program, for it; every other label is a
        negative); None: a program per label. Scenes where perception found no object cannot be
        examples (they have no target to speak of) and are left out of training."""
        from ..learn import Model

        keep = [(self.facts[i], y) for i, y in zip(ids, labels) if self.facts[i].target is not None]
        present = {y for _, y in keep}
        classes = [c for c in ([positive] if positive else sorted(present)) if c in present]
        wanted = [positive] if positive else sorted(set(labels))
        missing = {c: "perception found no object in any of its training images" for c in wanted if c not in present}
        if not classes:  # perception found no object in any positive: nothing to learn from
            return FittedLogic(Model({}, self.settings), self.facts, missing)
        model = Model.fit([f for f, _ in keep], [y for _, y in keep], settings=self.settings or None, seed=seed,
                          classes=classes)
        return FittedLogic(model, self.facts, missing)


class FittedLogic:
    def __init__(self, model, facts: dict, missing: dict[str, str] | None = None):
        self.model, self.facts = model, facts
        # class -> why no program was learned for it (the learner's reasons, and classes without examples)
        self.failures = {**dict(missing or {}), **dict(getattr(model, "failures", None) or {})}

    def predict(self, ids: list[str]) -> list[tuple[str, float]]:
        """(label, confidence of the best proof); "unknown" where no program proves the target (or
        perception found no object)."""
        return [(label, conf) for label, conf, _ in self.answer(ids)]

    def answer(self, ids: list[str]) -> list[tuple[str, float, str]]:
        """:meth:`predict`'s answers with how each was reached (lv3d.learn.model.Model.answer: "proof",
        "arbiter", "near" or "unknown"; "unknown" too where perception found no object)."""
        out = []
        for i in ids:
            scene = self.facts[i]
            out.append(("unknown", 0.0, "unknown") if scene.target is None else tuple(self.model.answer(scene)))
        return out

    def explain(self, scene_id: str):
        return self.model.explain(self.facts[scene_id])

    def save(self, folder: Path) -> None:
        Path(folder).mkdir(parents=True, exist_ok=True)
        self.model.save(Path(folder))


class PixelSystem:
    """A CNN, a decision tree or pretrained features with a linear classifier (effnet-*) over the pixel
    tensors of one modality."""

    def __init__(self, name: str, pixels: dict[str, np.ndarray], baselines: BaselineConfig):
        self.name, self.pixels, self.b = name, pixels, baselines
        self.modality = modality_of(name)
        self.channels = {"rgb": slice(0, 3), "depth": slice(3, 4), "rgbd": slice(0, 4)}[self.modality]
        self.tuned: dict | None = None  # the CNN setting tune() chose: width, epochs, augment, image_size

    def _x(self, ids: list[str]) -> np.ndarray:
        x = np.stack([self.pixels[i][self.channels] for i in ids])
        if self.tuned is not None:
            from ..baselines.tuning import area_downsample

            x = area_downsample(x, self.tuned["image_size"])
        return x

    def cnn_settings(self):
        """The CNN's training settings (lv3d.baselines.CNNSettings): the study's, with the width, epochs and
        augmentation tune() chose when it ran."""
        from ..baselines import CNNSettings

        b, t = self.b, self.tuned or {}
        return CNNSettings(epochs=t.get("epochs", b.epochs), batch_size=b.batch_size, lr=b.lr,
                           weight_decay=b.weight_decay, augment=t.get("augment", b.augment),
                           width=t.get("width", b.width), threads=b.threads, patience=b.patience,
                           val_fraction=b.val_fraction)

    def tune(self, items: list, seed: int) -> dict | None:
        """With ``baselines.tune``, a CNN's width, epochs, augmentation and input size chosen by grouped inner
        cross-validation of the multi-class task on ``items`` (one outer fold's training examples: the runner
        never passes its test fold) and used by every later fit and predict; returns the search's record
        (lv3d.baselines.tuning.tune). None, changing nothing, for the trees or without ``baselines.tune``."""
        if not self.b.tune or not self.name.startswith("cnn-"):
            return None
        from ..baselines.tuning import grid, tune

        b, arch = self.b, "twostream" if self.name.endswith("-2s") else "early"
        self.tuned = None
        settings = grid(b.tune_width, b.tune_epochs, b.tune_augment, b.tune_image_size, self.modality, arch)
        out = tune(self._x([it.id for it in items]), [it.cls for it in items], [it.group_key for it in items],
                   self.modality, arch, self.cnn_settings(), settings, b.tune_folds, seed)
        self.tuned = dict(out["setting"])
        return out

    def fit(self, ids: list[str], labels: list[str], seed: int, positive: str | None = None) -> "FittedPixels":
        """Train on the labels as given (a binary task's negatives share one label per task)."""
        from ..baselines import CNNClassifier, PixelTree

        b = self.b
        if self.name.startswith("tree-"):
            model = PixelTree(cells=b.tree_cells, min_samples_leaf=b.tree_min_samples_leaf)
        elif self.name.startswith("effnet-"):
            model = self._pretrained()
        else:
            model = CNNClassifier(self.modality, "twostream" if self.name.endswith("-2s") else "early",
                                  self.cnn_settings())
        model.fit(self._x(ids), labels, seed=seed)
        return FittedPixels(model, self)

    def _pretrained(self):
        """The effnet-* classifier (lv3d.baselines.pretrained). On first use, the network's features of every
        image this system sees, computed in batched passes of at most PRETRAINED_CHUNK images and cached in
        the process, so that the many fits of a study run the network once per image."""
        from ..baselines.pretrained import PretrainedClassifier, PretrainedSettings, features

        b = self.b
        settings = PretrainedSettings(C=b.effnet_c, input_size=b.effnet_input_size, threads=b.threads)
        if not getattr(self, "_features_ready", False):
            ids = list(self.pixels)
            for start in range(0, len(ids), PRETRAINED_CHUNK):
                features(self._x(ids[start:start + PRETRAINED_CHUNK]), self.modality, settings)
            self._features_ready = True
        return PretrainedClassifier(self.modality, settings)


PRETRAINED_CHUNK = 1024  # images stacked at once for the features: 1024 rgbd tensors of 64x64 are 64 MB


class FittedPixels:
    failures: dict[str, str] = {}

    def __init__(self, model, system: PixelSystem):
        self.model, self.system = model, system

    def predict(self, ids: list[str]) -> list[tuple[str, float]]:
        return self.model.predict(self.system._x(ids))

    def save(self, folder: Path) -> None:
        """Nothing a person can read: the baselines' weights are not kept."""


def make_system(name: str, cfg: StudyConfig, inputs: dict):
    if name in LOGIC_SYSTEMS:
        return LogicSystem(name, inputs, cfg.lv3d.settings)
    return PixelSystem(name, inputs, cfg.baselines)
