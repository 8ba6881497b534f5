"""Per-type ECE of the calibrated fact confidences on rows from benchmarks/calibration_data.py: each set of rows alone
and all of them pooled, beside the target (ECE <= 0.05 per fact type on rendered realsense scenes).

    .venv/bin/python -m benchmarks.calibration_data --fresh --seed 7000 --per-class 900 --modalities rgbd --out out/calib/held7000.pkl
    .venv/bin/python -m benchmarks.calibration_data --fresh --seed 500000 --per-class 900 --modalities rgbd --out out/calib/held500000.pkl
    .venv/bin/python -m benchmarks.calibration_check out/calib/held7000.pkl out/calib/held500000.pkl

The rows hold raw probabilities; they are calibrated here with the maps lv3d ships (lv3d/data/calibration.json,
lv3d.calibration), and facts are grouped by predicate (the kinds filed apart, e.g. ``acute_touch``, count as their
predicate), as bench_grounding.py groups them: on the same scenes both print the same figures. Why pool: a type
with few facts, in clusters per scene (parallel: a face split in two gives a pair, in both orders), shows an ECE
that varies widely from one set of scenes to the next. The rows must come from the code the maps were fitted on:
a line says which sources changed since the fit (lv3d.calibration.stale_sources).
"""

from __future__ import annotations

import argparse
import pickle
import sys
from pathlib import Path

import numpy as np

from benchmarks.calibration_error import ECE_TARGET, chance_ece, ece, ece_verdict, log_loss, scene_interval
from benchmarks.fit_calibration import MIN_CONF, row_key, scene_of


def score(rows: list[dict], modality: str) -> tuple[np.ndarray, dict]:
    """(every candidate's (confidence, truth) (n, 2), {predicate: (confidence, truth, scene) (m, 3) of the facts
    emitted, confidence >= MIN_CONF}) of ``modality``'s rows with a non-zero raw probability."""
    from lv3d.calibration import calibrate

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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rows", type=Path, nargs="+", help="pickles from benchmarks/calibration_data.py")
    ap.add_argument("--modality", default="rgbd", choices=("rgbd", "depth"))
    ap.add_argument("--draws", type=int, default=300, help="scene-bootstrap draws for each interval")
    a = ap.parse_args(argv)
    sets = {}
    for path in a.rows:
        if not path.is_file():
            ap.error(f"{path}: no such file (make it with benchmarks/calibration_data.py)")
        try:
            sets[path.name] = pickle.loads(path.read_bytes())["rows"]
        except (pickle.UnpicklingError, KeyError, EOFError) as e:
            ap.error(f"{path}: not a calibration_data.py pickle ({e!r})")
    from lv3d.calibration import stale_sources

    stale = stale_sources()
    if stale:
        print(f"note: {', '.join(stale)} changed since the shipped maps were fitted (refit: benchmarks/fit_calibration.py)")
    for name, rows in sets.items():
        report(name, rows, a.modality, a.draws)
    if len(sets) > 1:
        report("all pooled", [r for rows in sets.values() for r in rows], a.modality, a.draws)
    return 0


if __name__ == "__main__":
    sys.exit(main())
