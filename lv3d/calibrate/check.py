"""Per-type ECE of the calibrated fact confidences on rendered rows (lv3d.calibrate.rows): each set of rows alone
and all of them pooled, beside the target (ECE <= 0.05 per fact type on rendered realsense scenes).

    lv3d calibrate rows --fresh --seed 7000 --per-class 900 --modalities rgbd --out out/calib/held7000.pkl
    lv3d calibrate rows --fresh --seed 500000 --per-class 900 --modalities rgbd --out out/calib/held500000.pkl
    lv3d calibrate check out/calib/held7000.pkl out/calib/held500000.pkl

The rows hold raw probabilities; they are calibrated here with the maps lv3d ships (lv3d/data/calibration.json,
lv3d.calibration), and facts are grouped by predicate (the kinds filed apart, e.g. ``acute_touch``, count as their
predicate), as benchmarks/bench_grounding.py groups them: on the same scenes both print the same figures. Why
pool: a type with few facts, in clusters per scene (parallel: a face split in two gives a pair, in both orders),
shows an ECE that varies widely from one set of scenes to the next. The rows must come from the code the maps were
fitted on: a line says which sources changed since the fit (lv3d.calibration.stale_sources).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputError
from . import rows as rendered_rows
from .fit import MIN_CONF, row_key, scene_of
from .measures import ECE_TARGET, chance_ece, ece, ece_verdict, log_loss, scene_interval


def score(rows: list[dict], modality: str) -> tuple[np.ndarray, dict]:
    """(every candidate's (confidence, truth) (n, 2), {predicate: (confidence, truth, scene) (m, 3) of the facts
    emitted, confidence >= MIN_CONF}) of ``modality``'s rows with a non-zero raw probability."""
    from ..calibration import calibrate

    cands, facts = [], {}
    for r in rows:
        if r["modality"] != modality or not r["p"] > 0:
            continue
        c = calibrate(modality, row_key(r), r["p"], r)
        cands.append((c, float(r["y"])))
        if c >= MIN_CONF:
            facts.setdefault(r["pred"], []).append((c, float(r["y"]), scene_of(r)))
    return np.array(cands, float).reshape(-1, 2), {k: np.array(v, object) for k, v in facts.items()}


def report(name: str, rows: list[dict], modality: str, draws: int) -> None:
    cands, facts = score(rows, modality)
    if not len(cands):
        print(f"== {name}: no {modality} rows")
        return
    emitted = cands[cands[:, 0] >= MIN_CONF]
    scenes = len({scene_of(r) for r in rows if r["modality"] == modality and r["p"] > 0})
    print(f"== {name}: {scenes} scenes, {modality}; ECE over all {len(emitted)} facts {ece(*emitted.T):.3f}, "
          f"log loss over all {len(cands)} candidates {log_loss(*cands.T):.4f}")
    met = 0
    for pred in sorted(facts):
        f = facts[pred]
        c, y = f[:, 0].astype(float), f[:, 1].astype(float)
        e = ece(c, y)
        met += e <= ECE_TARGET
        lo, hi = scene_interval(c, y, f[:, 2].astype(str), draws=draws)
        print(f"  ECE {pred:14s} {e:.3f}  n={len(f):6d}  chance {chance_ece(c):.3f}  scenes 95% {lo:.3f}-{hi:.3f}"
              f"  {ece_verdict(e)}")
    print(f"  {met} of {len(facts)} types within {ECE_TARGET}")


def run(paths: list[Path], modality: str = "rgbd", draws: int = 300) -> None:
    """:func:`report` of each pickle of rows (lv3d.calibrate.rows) and, with several, of all of them pooled,
    after a line naming the sources changed since the shipped maps were fitted."""
    from ..calibration import stale_sources

    if modality not in ("rgbd", "depth"):
        raise InputError("--modality", f"choose among rgbd, depth, not {modality!r}")
    if draws < 1:
        raise InputError("--draws", f"must be at least 1, not {draws}")
    sets = {Path(p).name: rendered_rows.read(p)["rows"] for p in paths}
    stale = stale_sources()
    if stale:
        print(f"note: {', '.join(stale)} changed since the shipped maps were fitted (refit: lv3d calibrate fit)")
    for name, rows in sets.items():
        report(name, rows, modality, draws)
    if len(sets) > 1:
        report("all pooled", [r for rows in sets.values() for r in rows], modality, draws)
