"""Fit the per-(modality, predicate) confidence calibration maps and write grounding/_calibration_table.py.

    .venv/bin/python benchmarks/calibration_data.py --seed 30000 --per-class 25 --out out/calib/dev30000.pkl
    .venv/bin/python benchmarks/fit_calibration.py out/calib/dev30000.pkl            # fit, print, write
    .venv/bin/python benchmarks/fit_calibration.py out/calib/dev30000.pkl --check out/calib/dev40000.pkl

For each (modality, predicate) three maps compete by 5-fold cross-validated log loss on the dev rows:
the raw probability unchanged, Platt scaling (bias + slope on logit p), and Platt plus a few face
measurements (``FEATURES``). The winner is refitted on all rows (L2-regularised logistic regression,
measurements standardised, the standardisation folded into the coefficients). A map whose slope on
logit p comes out negative is not used (confidence must grow with the measured probability).
``--check`` prints per-type ECE before and after on another dev set (rows with confidence >= 0.05,
as facts are emitted). Rows come from dev seeds only, never the study's data.
"""

from __future__ import annotations

import argparse
import pickle
import pprint
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.calibration_error import chance_ece, ece  # noqa: E402
from grounding._calibration import design  # noqa: E402

MODALITIES = ("rgbd", "depth")  # rgb is left raw: see docs/grounding.md (its labels need a look first)
FEATURES = ["support", "log_area_px", "min_turn_z", "min_side_px"]
MIN_ROWS = 12        # fewer rows (or one class of label only): keep the raw probability
C_REG = 0.5          # inverse L2 strength of the logistic fits (standardised inputs)
MIN_CONF = 0.05
SUPPORT_PREDS = ("face_of", "adjacent", "object")


def _logloss(p, y):
    p = np.clip(p, 1e-6, 1 - 1e-6)
    return float(-np.mean(y * np.log(p) + (1 - y) * np.log(1 - p)))


def _fit(x: np.ndarray, y: np.ndarray):
    """Logistic regression on standardised x with one pseudo-observation of each label (weight 1/2 each,
    at the mean inputs: Laplace smoothing, so a type that was always true on dev gets (n + 1/2) / (n + 1),
    not 1); returns (bias, coef) in the original units."""
    from sklearn.linear_model import LogisticRegression

    mu, sd = x.mean(0), x.std(0) + 1e-9
    xs = np.concatenate([(x - mu) / sd, np.zeros((2, x.shape[1]))])
    ys = np.concatenate([y, [0.0, 1.0]])
    w = np.concatenate([np.ones(len(y)), [0.5, 0.5]])
    m = LogisticRegression(C=C_REG, max_iter=1000).fit(xs, ys, sample_weight=w)
    coef = m.coef_[0] / sd
    return float(m.intercept_[0] - coef @ mu), coef


def _predict(bias, coef, x):
    return 1.0 / (1.0 + np.exp(-np.clip(bias + x @ coef, -50, 50)))


def _fit_shift(rows: list[dict]):
    """(bias, coef, features) of ``sigmoid(logit p + bias)``: the raw probability moved in logit space by
    one smoothed constant (types whose dev candidates were all true or all false keep p's order)."""
    from scipy.optimize import minimize_scalar

    z = np.array([design(r["p"], r, ["logit_p"])[0] for r in rows])
    y = np.array([r["y"] for r in rows], float)

    def loss(b):  # log loss plus the two half pseudo-observations at logit 0
        return len(y) * _logloss(_predict(b, np.ones(1), z[:, None]), y) + 0.5 * (np.logaddexp(0, -b) + np.logaddexp(0, b))

    return float(minimize_scalar(loss, bounds=(-15, 15), method="bounded").x), np.ones(1), ["logit_p"]


def _fit_monotone(rows: list[dict], feats: list[str] | None):
    if feats is None:
        return _fit_shift(rows)
    """(bias, coef, features) of a logistic map; refitted without logit p when its slope comes out
    negative (where p carries no information, e.g. always 1, the map must not turn it upside down)."""
    y = np.array([r["y"] for r in rows], float)
    if not feats:  # a constant: the smoothed rate
        return float(np.log((y.sum() + .5) / ((1 - y).sum() + .5))), np.zeros(0), []
    x = np.array([design(r["p"], r, feats) for r in rows])
    b, c = _fit(x, y)
    if feats and feats[0] == "logit_p" and c[0] < 0:
        return _fit_monotone(rows, feats[1:])
    return b, c, feats


def fit_one(rows: list[dict], seed: int = 0):
    """The best map for one (modality, predicate) by 5-fold CV log loss: None (raw) or a table entry."""
    y = np.array([r["y"] for r in rows], float)
    p = np.array([r["p"] for r in rows])
    if len(rows) < MIN_ROWS:
        return None, {}
    folds = np.random.default_rng(seed).permutation(len(rows)) % 5
    cands = {"raw": "raw", "shift": None, "platt": ["logit_p"], "platt+measures": ["logit_p"] + FEATURES}
    if rows[0]["pred"] in SUPPORT_PREDS:  # p is edge support, not a geometric probability: may be ignored
        cands["const"] = []
    losses = {}
    for name, feats in cands.items():
        pred = np.empty(len(rows))
        for k in range(5):
            tr, te = folds != k, folds == k
            if feats == "raw":
                pred[te] = np.clip(p[te], 0, 1)
                continue
            trows = [r for r, t in zip(rows, tr) if t]
            b, c, f = _fit_monotone(trows, feats)
            x = np.array([design(r["p"], r, f) for r, t in zip(rows, te) if t]).reshape(int(te.sum()), len(f))
            pred[te] = _predict(b, c, x)
        losses[name] = _logloss(pred, y)
    name = min(losses, key=losses.get)
    if cands[name] == "raw":
        return None, losses
    b, c, f = _fit_monotone(rows, cands[name])
    return {"features": f, "bias": round(b, 5), "coef": [round(float(v), 5) for v in c], "n": len(rows),
            "map": name, "cv_logloss": round(losses[name], 4)}, losses


def report(rows: list[dict], table: dict, title: str) -> None:
    from grounding._calibration import calibrate_with

    print(f"== {title}: per-type ECE of emitted facts (conf >= {MIN_CONF}), raw -> calibrated")
    by = defaultdict(list)
    for r in rows:
        by[(r["modality"], r["pred"])].append(r)
    for key in sorted(by):
        rs = by[key]
        raw = np.array([(min(r["p"], 1.0), r["y"]) for r in rs if r["p"] >= MIN_CONF], float).reshape(-1, 2)
        cal = np.array([(c, r["y"]) for r in rs if (c := calibrate_with(table, *key, r["p"], r)) >= MIN_CONF],
                       float).reshape(-1, 2)
        print(f"  {key[0]:5s} {key[1]:14s} raw {ece(*raw.T):.3f} (n={len(raw):4d})  calibrated {ece(*cal.T):.3f} "
              f"(n={len(cal):4d}, chance {chance_ece(cal[:, 0]):.3f})  mean conf {cal[:, 0].mean() if len(cal) else float('nan'):.2f} "
              f"true {cal[:, 1].mean() if len(cal) else float('nan'):.2f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("data", type=Path, nargs="+", help="pickles from benchmarks/calibration_data.py")
    ap.add_argument("--check", type=Path, help="another dev set to report ECE on")
    ap.add_argument("--out", type=Path, default=ROOT / "grounding" / "_calibration_table.py")
    ap.add_argument("--dry-run", action="store_true")
    a = ap.parse_args(argv)
    rows = [r for path in a.data for r in pickle.loads(path.read_bytes())["rows"]]
    by = defaultdict(list)
    for r in rows:
        if r["modality"] in MODALITIES and r["p"] > 0:
            by[(r["modality"], r["pred"])].append(r)
    table: dict = {}
    for key in sorted(by):
        entry, losses = fit_one(by[key])
        print(f"  {key[0]:5s} {key[1]:14s} n={len(by[key]):5d}  cv log loss "
              + "  ".join(f"{k} {v:.4f}" for k, v in losses.items()) + f"  -> {'raw' if entry is None else entry['map'] + ' ' + ','.join(entry['features'])}")
        if entry is not None:
            table.setdefault(key[0], {})[key[1]] = entry
    report(rows, table, f"fit rows ({', '.join(map(str, a.data))})")
    if a.check:
        report(pickle.loads(a.check.read_bytes())["rows"], table, f"check rows ({a.check})")
    if not a.dry_run:
        a.out.write_text('"""Calibration maps (see _calibration.py), written by benchmarks/fit_calibration.py from\n'
                         f'{", ".join(p.name for p in a.data)} (perceived realsense dev scenes). Do not edit by hand."""\n\n'
                         f"TABLE: dict = {pprint.pformat(table, width=110, sort_dicts=True)}\n")
        print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
