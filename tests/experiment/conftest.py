"""Tiny studies on a synthetic data set and a fake learner, so that the runner is tested on its own."""

import csv
import json
import sys
import types
from pathlib import Path

import cv2
import numpy as np
import pytest

from lv3d.facts import Fact, SceneFacts

SHAPES = {"cube": 4, "square_pyramid": 3, "triangular_prism": 5}


def write_dataset(out: Path, classes, per_class: int, seed: int) -> Path:
    """An lv3d.dataset/1 folder of 64x48 frames: a bright polygon (4 corners for a cube, 3 for a
    pyramid, ...) nearer than a flat table, at a seeded random place."""
    rng = np.random.default_rng(seed)
    out.mkdir(parents=True, exist_ok=True)
    items = []
    for cls in classes:
        for _ in range(per_class):
            sid = f"s{len(items):06d}"
            d = out / sid
            d.mkdir()
            cx, cy, r = int(rng.integers(20, 44)), int(rng.integers(16, 32)), int(rng.integers(7, 11))
            ang = np.linspace(0, 2 * np.pi, SHAPES[cls], endpoint=False) + rng.uniform(0, 0.3)
            poly = np.stack([cx + r * np.cos(ang), cy + r * np.sin(ang)], 1).astype(np.int32)
            color = np.full((48, 64, 3), 40, np.uint8)
            cv2.fillPoly(color, [poly], (200, 180, 160))
            depth = np.full((48, 64), 800, np.uint16)
            mask = np.zeros((48, 64), np.uint8)
            cv2.fillPoly(mask, [poly], 1)
            depth[mask > 0] = 720
            cv2.imwrite(str(d / "color.png"), color[:, :, ::-1])
            cv2.imwrite(str(d / "depth.png"), depth)
            meta = {"schema": "lv3d.scene/1", "id": sid, "depth_scale_m": 0.001, "seed": seed,
                    "intrinsics": {"fx": 60, "fy": 60, "cx": 31.5, "cy": 23.5, "width": 64, "height": 48},
                    "truth": {"class": cls, "sides": SHAPES[cls]}}
            (d / "meta.json").write_text(json.dumps(meta))
            items.append({"id": sid, "class": cls, "dir": sid})
    (out / "manifest.json").write_text(json.dumps({"schema": "lv3d.dataset/1", "classes": list(classes),
                                                   "per_class": per_class, "items": items}))
    return out


def fake_scene_facts(frame, scene_id, modality, refine=True, confidences=True, seed=0, depth=None):
    """Facts read off the synthetic meta: one object with one face of the drawn side count."""
    sides = frame.meta["truth"]["sides"]
    pred = {3: "triangle", 4: "quadrilateral", 5: "pentagon"}[sides]
    o, f = f"{scene_id}_o1", f"{scene_id}_o1_f0"
    facts = [Fact("object", (o,), 1.0), Fact("face_of", (o, f), 1.0), Fact(pred, (f,), 0.9)]
    return SceneFacts(scene_id, modality, facts, o)


class FakeModel:
    """Learns, per label, which face predicates its scenes show; predicts the best-matching label."""

    fits = 0

    def __init__(self, table):
        self.table = table

    @staticmethod
    def _sig(scene):
        return frozenset(f.pred for f in scene.facts if f.pred not in ("object", "face_of"))

    @classmethod
    def fit(cls, scenes, labels, settings=None, seed=0, classes=None):
        FakeModel.fits += 1
        FakeModel.last_settings = settings
        table = {}
        for s, label in zip(scenes, labels):
            table.setdefault(cls._sig(s), {}).setdefault(label, 0)
            table[cls._sig(s)][label] += 1
        return cls(table)

    def predict(self, scene):
        votes = self.table.get(self._sig(scene))
        if not votes:
            return "none", 0.5
        label = max(sorted(votes), key=votes.get)
        return label, votes[label] / sum(votes.values())

    def answer(self, scene):
        label, conf = self.predict(scene)
        return label, conf, "unknown" if label == "none" else "proof"

    def explain(self, scene):
        return f"{self.predict(scene)[0]} because {sorted(self._sig(scene))}"

    def save(self, folder):
        (Path(folder) / "program.pl").write_text("% fake program\n")


def _synthetic_data_and_facts(monkeypatch):
    """Route the runner's data set and pipeline to the synthetic stand-ins above."""
    from lv3d.experiment import data as data_mod

    def ensure_dataset(cfg, out):
        target = data_mod.dataset_dir(cfg, out)
        if not (target / "manifest.json").is_file():
            write_dataset(target, cfg.data.classes, cfg.data.per_class, cfg.seed)
        return target

    monkeypatch.setattr(data_mod, "ensure_dataset", ensure_dataset)
    monkeypatch.setattr("lv3d.pipeline.scene_facts", fake_scene_facts)


@pytest.fixture
def fake_world(monkeypatch):
    """Route the runner's data set, pipeline and learner to the synthetic stand-ins above."""
    _synthetic_data_and_facts(monkeypatch)
    import lv3d.learn.settings  # noqa: F401  (the settings check stays the real one)

    learn = types.ModuleType("lv3d.learn")
    learn.Model = FakeModel
    monkeypatch.setitem(sys.modules, "lv3d.learn", learn)
    FakeModel.fits = 0
    return FakeModel


@pytest.fixture
def perceived_with(fake_world, monkeypatch):
    """The perception seed and depth settings of each call of lv3d.pipeline.scene_facts, as (seed, depth), the
    facts those of :func:`fake_scene_facts`."""
    calls = []

    def recording(frame, scene_id, modality, refine=True, confidences=True, seed=0, depth=None):
        calls.append((seed, depth))
        return fake_scene_facts(frame, scene_id, modality, refine, confidences, seed)

    monkeypatch.setattr("lv3d.pipeline.scene_facts", recording)
    return calls


TINY = """\
name: tiny
seed: 3
folds: 3
data: {classes: [cube, square_pyramid, triangular_prism], per_class: 6, noise: clean}
train: {positives: 4, negatives_per_positive: 1.0}
systems: [lv3d-rgbd, lv3d-depth, tree-rgbd, cnn-rgb]
baselines: {image_size: 16, tree_cells: 4, epochs: 2, width: 4, threads: 1, batch_size: 8}
"""


@pytest.fixture
def tiny_config(tmp_path):
    p = tmp_path / "tiny.yaml"
    p.write_text(TINY)
    return p


@pytest.fixture
def synthetic_facts(monkeypatch):
    """The synthetic data set and facts of ``fake_world``, but the real learner."""
    _synthetic_data_and_facts(monkeypatch)


@pytest.fixture(scope="session")
def write_results():
    """Writes a study's results.csv at a path from (condition, system, fold, task, accuracy) rows: the columns the
    scripts reading reports need."""

    def write(path: Path, rows) -> Path:
        with path.open("w", newline="") as f:
            w = csv.DictWriter(f, ["condition", "system", "fold", "task", "accuracy"])
            w.writeheader()
            for cond, system, fold, task, acc in rows:
                w.writerow({"condition": cond, "system": system, "fold": fold, "task": task, "accuracy": acc})
        return path

    return write
