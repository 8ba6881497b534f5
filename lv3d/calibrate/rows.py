"""Candidate facts of perceived dev scenes with their ground-truth labels and the measurements behind them:
the data the confidence calibration (grounding/_calibration.py) is fitted on and checked against.

    lv3d calibrate rows --fresh --seed 30000 --per-class 50 --modalities rgbd,depth --out out/calib/s6_a50.pkl

Scenes are ``render_scene(cls, seed + 1000 * class_index + i, preset)`` for the 7 classes of ``CLASSES``: dev
seeds only (never the study's seed-0 data set). Each row: modality, predicate, raw probability (before any
calibration), truth label (True/False; candidates the truth says nothing about are left out) and the
face measurements ``lv3d.describe.calibration_features`` gives (with the candidate's measured ``value``).
Rows are appended per scene, so an interrupted run resumes; ``fresh`` starts the file over (after
perception or grounding changed, old rows are stale).

The pickle: ``{"rows": [...], "scenes": [render seeds done], "made_by": the command line}``.
"""

from __future__ import annotations

import pickle
import time
from pathlib import Path

from ..errors import InputError, read_pickle
from ..output import write_atomic
from .truth import truth_labels

CLASSES = ["cube", "cuboid", "square_pyramid", "triangular_prism", "pentagonal_prism", "hexagonal_prism",
           "tetrahedron"]
MODALITIES = ("rgbd", "depth", "rgb")


def scene_rows(cls: str, seed: int, preset: str, modalities: list[str]) -> list[dict]:
    """The labelled candidate rows of one rendered scene, per modality."""
    from ..describe import calibration_features, ground
    from ..perception import perceive
    from ..render import render_scene

    frame, faces_mask = render_scene(cls, seed, preset)
    rows = []
    for mod in modalities:
        scene = perceive(frame, mod, scene_id=f"s{seed:06d}")
        cands, results = ground(scene, frame, refine=True, calibrate=False)
        labels = truth_labels(cands, results, faces_mask, frame.meta["truth"], frame.intrinsics)
        feats = calibration_features(cands, results)
        for (pred, args, p, value), y, f in zip(cands, labels, feats):
            if y is not None:
                rows.append({"modality": mod, "pred": pred, "p": float(p), "y": bool(y), "cls": cls, "seed": seed,
                             "source": f"render:{preset}", **f, "value": value})
    return rows


def read(path: Path) -> dict:
    """A pickle of :func:`make`, or a one-line InputError naming the file."""
    return read_pickle(path, "lv3d calibrate rows", ("rows", "scenes"))


def make(out: Path, seed: int = 30000, per_class: int = 20, preset: str = "realsense",
         modalities: tuple[str, ...] = MODALITIES, fresh: bool = False, command: str = "", log=print) -> dict:
    """Render ``per_class`` scenes of each class from ``seed`` and append their rows to the pickle ``out``, one
    complete file after each scene (resumes; ``fresh``: starts over). ``out`` must be absent or a pickle of
    this function. A scene that fails is reported and counted as done."""
    from ..render.noise import noise_config

    bad = [m for m in modalities if m not in MODALITIES]
    if bad or not modalities:
        raise InputError("--modalities", f"choose among {', '.join(MODALITIES)}, not {','.join(modalities)!r}")
    noise_config(preset)  # an unknown preset: one line, before any work
    out = Path(out)
    if out.is_dir():
        raise InputError(out, "is a folder; --out names a file")
    done = read(out) if out.exists() else None  # a file this command did not write is refused, never replaced
    if done is None or fresh:
        done = {"rows": [], "scenes": []}
    done["made_by"] = command
    out.parent.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    for s in range(per_class):
        for ci, cls in enumerate(CLASSES):
            scene_seed = seed + 1000 * ci + s
            if scene_seed in done["scenes"]:
                continue
            try:
                done["rows"] += scene_rows(cls, scene_seed, preset, list(modalities))
            except Exception as e:  # noqa: BLE001 - a failing scene is reported, not fatal
                log(f"  {cls} {scene_seed}: {e!r}"[:200])
            done["scenes"].append(scene_seed)
            write_atomic(out, pickle.dumps(done))
        log(f"{s + 1}/{per_class} per class, {len(done['rows'])} rows, {time.time() - t0:.0f} s")
    if not out.exists():
        write_atomic(out, pickle.dumps(done))
    return done
