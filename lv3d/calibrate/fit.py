"""Fit the per-(modality, key) confidence calibration maps and write lv3d/data/calibration.json.

The fit reads candidate facts with their truth from two kinds of data:

- rendered dev scenes (lv3d.calibrate.rows, ``lv3d calibrate rows``): every fact type, truth from the renderer;
- labelled real frames (lv3d.calibrate.real, ``lv3d calibrate real``, ``--real``): ``perpendicular`` only, truth
  from the labelled shape (adjacent faces of a box are perpendicular, of a cylinder or bowl not;
  benchmarks/bench_real.py's definition). A real sensor's errors are larger than the renderer's, and real scenes
  hold curved solids the renderer has none of; the real rows teach the maps both.

The whole fit, from the repository root (each rendered set of 840 scenes about 4 min on one core for both
modalities, the two real folders 20 s each, the fit with its checks about 7 min; ``bash
scripts/refit_calibration.sh`` runs all of it, two sets side by side on two cores, and resumes where it
stopped)::

    for a in "30000 s30000 realsense 120" "40000 s40000 realsense 120" "60000 s60000 realsense 120" \
             "70000 c70000 clean 120" "80000 r80000 realistic 120" "100000 chk100000 realsense 40" \
             "110000 chk110000 clean 40"; do set -- $a
        OMP_NUM_THREADS=1 .venv/bin/lv3d calibrate rows --fresh --seed $1 --per-class $4 --preset $3 \
            --modalities rgbd,depth --out out/calib/$2.pkl
    done
    for f in osd-learn ycb-realsense; do
        OMP_NUM_THREADS=1 .venv/bin/lv3d calibrate real ../shared/data/real/$f --out out/calib/real_$f.pkl
    done
    OMP_NUM_THREADS=1 .venv/bin/lv3d calibrate fit out/calib/{s30000,s40000,s60000,c70000,r80000}.pkl \
        --real out/calib/real_osd-learn.pkl --real out/calib/real_ycb-realsense.pkl \
        --check out/calib/chk100000.pkl --check out/calib/chk110000.pkl --holdout

The shipped maps come from this recipe (their provenance has each command): rendered rows of all three noise
presets the studies use (clean, realistic, realsense), so that maps which read a face's plane RMS
(``plane_rms_mm``) do not extrapolate on noise-free depth, where it is ten times smaller than a sensor's.

Rows come from dev seeds only, never the study's data. After perception or grounding changed, all of it is rerun
(lv3d.calibration.stale_sources names what changed since the shipped fit; ``lv3d calibrate check`` prints it).

The maps. For each (modality, key) (``grounding.calibration_key``: the predicate, or a kind filed apart) several
maps compete by scene-grouped 5-fold cross-validated log loss (a scene's or real frame's facts share its view and
its perception errors): the raw probability unchanged, a shift in logit space, Platt scaling (bias + slope on
logit p), and Platt plus face measurements (``FEATURES``; for predicates with a tolerance also ``tol_frac``, the
measured value in tolerances), each with and without how well the faces fit a polygon and a plane
(``FIT_FEATURES``) and with those and a slope on logit p that depends on them (``GATE_FEATURES``: the measured
probability counts as far as the outlines are straight and the corners sharp), and Platt plus the fit measures
alone, with and without a slope that also depends on how flat the faces are (``PLANE_GATE``), none of the other
measurements (where those read differently on a sensor's frames than on rendered ones, as the edge support of
the colour + depth edge field does under rgbd); for facts about two faces
(``PAIR_PREDS``) also those plus the side the two share (``PAIR_FEATURES``), for parallel (``PLANE_GAP_PREDS``)
plus how far the faces are from one plane. The winner is refitted on all rows (L2-regularised logistic
regression, inputs standardised, the standardisation folded into the coefficients); a map whose slope on logit p
comes out negative on most rows is refitted without the terms on p (confidence must not fall as the measured
probability rises; grounding holds the slope at 0 where it would). Then the final maps: per modality one isotonic
map of every key's out-of-fold confidences pooled, one of the per-face keys (``FACE_PREDS``) pooled, and per key
the best by scene-grouped CV log loss of none, its group's pooled map and its own (:func:`fit_final`).

Weights. Where a key has rows of both kinds, the real rows carry ``REAL_SHARE`` of its total weight (each kind's
rows equal among themselves, weights averaging 1): a few hundred real candidates against thousands of rendered
ones would otherwise leave the maps as they were. The log prints, under each such key, every map's CV log loss over
its real rows and over its rendered rows alone (unweighted): which kind of frame chose the map.

Checks. ``--holdout`` first fits without each real pickle and prints bench_real's figures on the one left out
(a sensor the fit has not seen), then fits in ``HOLDOUT_FOLDS`` frame-grouped folds over all real frames and prints
the figures of each frame's out-of-fold confidences (new frames of the sensors it has seen), per folder and
pooled. ``--check`` prints per-key ECE on other rendered dev sets (facts with confidence >= 0.05, as they are
emitted) for the raw probabilities, the shipped maps and the new ones. The figures of the final fit on the real
frames are in-sample. The written file holds the maps, these figures (``checks``) and the provenance
(lv3d.calibration; its ``command`` is the ``lv3d calibrate fit`` command line).
"""

from __future__ import annotations

import datetime
import hashlib
import json
import subprocess
from collections import defaultdict
from pathlib import Path

import numpy as np

from grounding import (SHARED_SIDE_PREDS, TOL_FRAC_PREDS, calibrate_with, calibration_key, factors, inputs, is_slope,
                       logit)
from grounding import final_knots as grounding_final_knots

from ..describe import ANGLE_PREDS, SIDE_NAMES
from ..errors import InputError
from ..facts import PREDICATES
from ..output import write_atomic
from . import real as real_rows, rows as rendered_rows
from .measures import chance_ece, ece, log_loss

ROOT = Path(__file__).resolve().parents[2]  # the checkout, where there is one: the provenance's git commit

MODALITIES = ("rgbd", "depth")  # rgb is left raw: its facts' truth needs a look first (docs/grounding.md)
FEATURES = ["support", "log_area_px", "min_turn_z", "min_side_px"]
# how well the faces are a polygon and a plane (lv3d.describe._face_features): outlines off straight edges and
# surfaces off their plane are what a curved solid read as planar faces shows, and rendered scenes have none
FIT_FEATURES = ["edge_scale2", "plane_rms_mm"]
# the slope on logit p may grow or shrink with how straight the outlines are and how sharp the weakest corner:
# the measured probability is trusted as far as the faces look like faces of a polyhedron (grounding._calibration)
GATE_FEATURES = ["logit_p*edge_scale2", "logit_p*min_turn_z"]
# ... and with how flat the faces are: an angle between planes measured on faces that depart from their planes by
# a sensor's noise (or by a curved surface's sagitta) says less than one measured on flat faces
PLANE_GATE = ["logit_p*plane_rms_mm"]
MIN_ROWS = 12        # fewer rows (or one class of label only): keep the raw probability
C_REG = 0.5          # inverse L2 strength of the logistic fits (standardised inputs, weights averaging 1)
MIN_CONF = 0.05      # facts below this confidence are not emitted (lv3d.describe.MIN_CONF): ECE is over the rest
MIN_OWN_FINAL = 50   # fewer rows of either label: a type's own isotonic map would be steps of a few facts
FINAL_REPEATS = 5    # fold draws the final maps are chosen over (_choose_final): one draw's choice between
#                      near-equal maps is a coin toss
# the share of a key's total fit weight its real rows carry where it has rows of both kinds: the two kinds count
# alike (the maps must hold on both; neither is the other's special case)
REAL_SHARE = 0.5
# modalities whose facts about the angle between two planes (lv3d.describe.ANGLE_PREDS; their keys are the
# predicate or the predicate with a suffix, e.g. perpendicular_touch) are read as another modality reads them:
# rgbd's are depth's reading (the faces' uncertainty and measurements against depth's edge field), so they take
# depth's maps and fit none of their own
READ_AS = {"rgbd": "depth"}
HOLDOUT_FOLDS = 5    # --holdout: frame-grouped folds over the real frames (each fold ~12 of 59 dev frames)
SUPPORT_PREDS = ("face_of", "adjacent", "object")  # p is edge support, not a geometric probability: may be ignored
# facts about two faces whose map may also read the side the faces share (0: none, e.g. pyramid laterals
# touching at the apex); parallel is offered it beside the plane gap (PLANE_GAP_PREDS)
PAIR_PREDS = SHARED_SIDE_PREDS
PAIR_FEATURES = ["shared_side_px"]
# facts about two planes whose map may also read how far the two faces are from one plane: parallel facts that
# hold are mostly two pieces of one face, a few mm apart
PLANE_GAP_PREDS = ("parallel",)
PLANE_GAP_FEATURES = ["plane_gap_mm"]
# facts about one face: their final maps are chosen on their rows alone (fit_final); with the (n - 1) side counts,
# which have maps of their own (grounding.calibration_key)
FACE_PREDS = tuple(p for p, (arity, _) in PREDICATES.items() if arity == 1 and p != "object")
FACE_PREDS += tuple(calibration_key(p, True) for p in SIDE_NAMES.values())


def row_key(r: dict) -> str:
    """The calibration key of a row (``lv3d.describe.calibration_features`` marks (n - 1) side counts and gives a
    pair's ``shared_side_px``), as ``lv3d.describe.calibration_keys`` gives it at run time."""
    return calibration_key(r["pred"], r.get("is_fewer", 0.0) > 0, r.get("shared_side_px"))


def scene_of(r: dict) -> str:
    """The scene a row comes from, the unit cross-validation keeps in one fold: a real row's folder/frame, a
    rendered row's render seed."""
    return r.get("scene") or f"render/{r['seed']}"


def is_real(r: dict) -> bool:
    return str(r.get("source", "")).startswith("real:")


def row_weights(rows: list[dict], real_share: float = REAL_SHARE) -> np.ndarray:
    """Fit weight of each row of one key: where there are rows of both kinds, the real ones carry
    ``real_share`` of the total, the rendered ones the rest; weights average 1."""
    real = np.array([is_real(r) for r in rows])
    w = np.ones(len(rows))
    if real.any() and (~real).any():
        w[real] = real_share / real.sum()
        w[~real] = (1.0 - real_share) / (~real).sum()
        w *= len(rows)
    return w


def _wlog_loss(p, y, w) -> float:
    p = np.clip(np.asarray(p, float), 1e-6, 1 - 1e-6)
    return float(-np.sum(w * (y * np.log(p) + (1 - y) * np.log(1 - p))) / np.sum(w))


def _fit(x: np.ndarray, y: np.ndarray, w: np.ndarray):
    """Weighted logistic regression on standardised x with one pseudo-observation of each label (weight 1/2 each,
    at the mean inputs: Laplace smoothing, so a type that was always true on dev gets (n + 1/2) / (n + 1),
    not 1); returns (bias, coef) in the original units."""
    from sklearn.linear_model import LogisticRegression

    mu = np.average(x, axis=0, weights=w)
    sd = np.sqrt(np.average((x - mu) ** 2, axis=0, weights=w)) + 1e-9
    xs = np.concatenate([(x - mu) / sd, np.zeros((2, x.shape[1]))])
    ys = np.concatenate([y, [0.0, 1.0]])
    ws = np.concatenate([w, [0.5, 0.5]])
    m = LogisticRegression(C=C_REG, max_iter=1000).fit(xs, ys, sample_weight=ws)
    coef = m.coef_[0] / sd
    return float(m.intercept_[0] - coef @ mu), coef


def _predict(bias, coef, x):
    return 1.0 / (1.0 + np.exp(-np.clip(bias + x @ coef, -50, 50)))


def _slope(coef, feats: list[str], rows: list[dict]) -> np.ndarray:
    """The slope on logit p of a map (bias, ``coef`` of ``feats``) at each row (grounding._calibration)."""
    on_p = np.array([is_slope(n) for n in feats], bool)
    if not on_p.any():
        return np.zeros(len(rows))
    g = np.array([factors(r["pred"], r, feats) for r in rows]).reshape(len(rows), len(feats))
    return g[:, on_p] @ np.asarray(coef)[on_p]


def predict_rows(bias, coef, feats: list[str], rows: list[dict]) -> np.ndarray:
    """The map's confidences of ``rows`` as grounding applies it: the slope on logit p never below 0."""
    coef = np.asarray(coef, float)
    if not len(feats):
        return np.full(len(rows), 1.0 / (1.0 + np.exp(-bias)))
    on_p = np.array([is_slope(n) for n in feats], bool)
    x = np.array([inputs(r["pred"], r["p"], r, feats) for r in rows]).reshape(len(rows), len(feats))
    z = bias + x[:, ~on_p] @ coef[~on_p]
    if on_p.any():
        lp = np.array([logit(r["p"]) for r in rows])
        z = z + np.maximum(_slope(coef, feats, rows), 0.0) * lp
    return 1.0 / (1.0 + np.exp(-np.clip(z, -50, 50)))


def _fit_shift(rows: list[dict], w: np.ndarray):
    """(bias, coef, features) of ``sigmoid(logit p + bias)``: the raw probability moved in logit space by
    one smoothed constant (types whose dev candidates were all true or all false keep p's order)."""
    from scipy.optimize import minimize_scalar

    z = np.array([inputs(r["pred"], r["p"], r, ["logit_p"])[0] for r in rows])
    y = np.array([r["y"] for r in rows], float)

    def loss(b):  # weighted log loss plus the two half pseudo-observations at logit 0
        return np.sum(w) * _wlog_loss(_predict(b, np.ones(1), z[:, None]), y, w) + \
            0.5 * (np.logaddexp(0, -b) + np.logaddexp(0, b))

    return float(minimize_scalar(loss, bounds=(-15, 15), method="bounded").x), np.ones(1), ["logit_p"]


def _fit_monotone(rows: list[dict], feats: list[str] | None, w: np.ndarray):
    """(bias, coef, features) of a logistic map (``feats`` None: :func:`_fit_shift`); refitted without the terms
    on logit p when its slope (:func:`_slope`) comes out negative on most (weighted) rows (where p carries no
    information, e.g. always 1, the map must not turn it upside down; where it is negative on a few rows, grounding
    holds it at 0 there)."""
    if feats is None:
        return _fit_shift(rows, w)
    y = np.array([r["y"] for r in rows], float)
    if not feats:  # a constant: the smoothed weighted rate
        return float(np.log((np.sum(w * y) + .5) / (np.sum(w * (1 - y)) + .5))), np.zeros(0), []
    x = np.array([inputs(r["pred"], r["p"], r, feats) for r in rows])
    b, c = _fit(x, y, w)
    if np.average(_slope(c, feats, rows) < 0, weights=w) > 0.5:
        # the fit would lower the confidence as p rises on most rows: p is left out
        return _fit_monotone(rows, [n for n in feats if not is_slope(n)], w)
    return b, c, feats


def _scene_fold_of(scenes, seed: int) -> dict:
    """{scene: one of 5 folds} over ``scenes`` (render seeds or real frames), seeded: every row of one scene
    goes to the same fold. A scene's facts share its view and its perception errors; rows of one scene on both
    sides of a split would reward a map for learning the scene rather than the fact type."""
    names = np.unique(np.asarray(scenes))
    return dict(zip(names.tolist(), np.random.default_rng(seed).permutation(len(names)) % 5))


def candidate_maps(pred: str) -> dict:
    """{name: the inputs of the map (``"raw"``: none; None: a shift of logit p)} that compete for ``pred``."""
    tol = ["tol_frac"] if pred in TOL_FRAC_PREDS else []  # the measured value in tolerances
    cands = {"raw": "raw", "shift": None, "platt": ["logit_p"], "platt+measures": ["logit_p"] + FEATURES + tol,
             "platt+measures+fit": ["logit_p"] + FEATURES + FIT_FEATURES + tol}
    cands["platt+measures+fit+gated"] = ["logit_p"] + FEATURES + FIT_FEATURES + tol + GATE_FEATURES
    cands["platt+fit"] = ["logit_p"] + FIT_FEATURES
    cands["platt+fit+gated"] = ["logit_p"] + FIT_FEATURES + GATE_FEATURES + PLANE_GATE
    if pred in PAIR_PREDS:
        cands["platt+measures+shared"] = ["logit_p"] + FEATURES + PAIR_FEATURES + tol
        cands["platt+measures+shared+fit"] = ["logit_p"] + FEATURES + PAIR_FEATURES + FIT_FEATURES + tol
        cands["platt+measures+shared+fit+gated"] = (["logit_p"] + FEATURES + PAIR_FEATURES + FIT_FEATURES + tol
                                                    + GATE_FEATURES)
    if pred in PLANE_GAP_PREDS:
        cands["platt+measures+gap"] = ["logit_p"] + FEATURES + PLANE_GAP_FEATURES + tol
        cands["platt+measures+gap+shared"] = ["logit_p"] + FEATURES + PLANE_GAP_FEATURES + PAIR_FEATURES + tol
    if pred in SUPPORT_PREDS:  # p is edge support, not a geometric probability: may be ignored
        cands["const"] = []
    return cands


def fit_one(rows: list[dict], seed: int = 0, w: np.ndarray | None = None):
    """The best map for one (modality, key) by scene-grouped 5-fold CV weighted log loss (:func:`_scene_fold_of`):
    (None (raw) or a map, {map: CV log loss}, the winner's out-of-fold confidences (n,), and where the key has rows
    of both kinds {"real"/"rendered": {map: CV log loss over that kind's rows, unweighted}}, else {}: which kind
    of frame chose the map)."""
    y = np.array([r["y"] for r in rows], float)
    p = np.array([r["p"] for r in rows])
    w = np.ones(len(rows)) if w is None else w
    if len(rows) < MIN_ROWS:
        return None, {}, np.clip(p, 0, 1), {}
    fold = _scene_fold_of([scene_of(r) for r in rows], seed)
    folds = np.array([fold[scene_of(r)] for r in rows])
    cands = candidate_maps(rows[0]["pred"])
    losses, oof = {}, {}
    for name, feats in cands.items():
        pred = np.empty(len(rows))
        for k in range(5):
            tr, te = folds != k, folds == k
            if feats == "raw":
                pred[te] = np.clip(p[te], 0, 1)
                continue
            trows = [r for r, t in zip(rows, tr) if t]
            b, c, f = _fit_monotone(trows, feats, w[tr])
            pred[te] = predict_rows(b, c, f, [r for r, t in zip(rows, te) if t])
        losses[name], oof[name] = _wlog_loss(pred, y, w), pred
    real = np.array([is_real(r) for r in rows])
    by_kind = {} if real.all() or not real.any() else \
        {kind: {n: _wlog_loss(v[m], y[m], np.ones(int(m.sum()))) for n, v in oof.items()}
         for kind, m in (("real", real), ("rendered", ~real))}
    name = min(losses, key=losses.get)
    if cands[name] == "raw":
        return None, losses, oof[name], by_kind
    b, c, f = _fit_monotone(rows, cands[name], w)
    return {"features": f, "bias": round(b, 5), "coef": [round(float(v), 5) for v in c], "n": len(rows),
            "map": name, "cv_logloss": round(losses[name], 4)}, losses, oof[name], by_kind


def _isotonic(conf: np.ndarray, y: np.ndarray, w: np.ndarray | None = None):
    from sklearn.isotonic import IsotonicRegression

    return IsotonicRegression(y_min=1e-3, y_max=1 - 1e-3, out_of_bounds="clip").fit(conf, y, sample_weight=w)


def _knots(iso) -> dict:
    """An isotonic fit as knots {"x": [...], "y": [...]} (ascending x), values within [0.001, 0.999]."""
    return {"x": [round(float(v), 5) for v in iso.X_thresholds_], "y": [round(float(v), 5) for v in iso.y_thresholds_]}


def _parts(entry: tuple) -> tuple:
    """(confidences, truth, scenes, weights) of an out-of-fold entry; weights 1 where it has none."""
    c, t, s = entry[:3]
    return c, t, s, (entry[3] if len(entry) > 3 else np.ones(len(c)))


def _choose_final(oof: dict, pool: list[str], members: list[str], seed: int) -> tuple[dict, dict, dict]:
    """Fit the isotonic map of the rows of the keys in ``pool`` together and choose, for each key in
    ``members``, among none, that pooled map and the key's own (with ``MIN_OWN_FINAL`` rows of each label)
    by scene-grouped 5-fold CV weighted log loss on its own rows, averaged over ``FINAL_REPEATS`` fold draws.
    Returns (pooled knots, {member: "pooled", None or own knots}, {member: {choice: mean CV log loss}}). Nothing
    outside ``pool`` enters the choice."""
    conf, y, scenes, w = (np.concatenate([_parts(oof[p])[i] for p in pool]) for i in range(4))
    sums: dict = defaultdict(lambda: defaultdict(float))
    for rep in range(FINAL_REPEATS):
        fold = _scene_fold_of(scenes, seed + rep)
        folds = np.array([fold[s] for s in scenes.tolist()])
        pooled = [_isotonic(conf[folds != k], y[folds != k], w[folds != k]) for k in range(5)]
        for pred in members:
            c, t, s, wp = _parts(oof[pred])
            f = np.array([fold[x] for x in s.tolist()])
            cands = {"none": c, "pooled": np.empty(len(c))}
            if min(t.sum(), len(t) - t.sum()) >= MIN_OWN_FINAL:
                cands["own"] = np.empty(len(c))
            for k in range(5):
                te = f == k
                if not te.any():  # a rare key may miss a fold
                    continue
                cands["pooled"][te] = pooled[k].predict(c[te])
                if "own" in cands:
                    cands["own"][te] = _isotonic(c[~te], t[~te], wp[~te]).predict(c[te])
            for name, v in cands.items():
                sums[pred][name] += _wlog_loss(v, t, wp) / FINAL_REPEATS
    choice, losses = {}, {}
    for pred in members:
        losses[pred] = dict(sums[pred])
        best = min(losses[pred], key=losses[pred].get)
        c, t, _, wp = _parts(oof[pred])
        choice[pred] = best if best == "pooled" else None if best == "none" else _knots(_isotonic(c, t, wp))
    return _knots(_isotonic(conf, y, w)), choice, losses


def fit_final(oof: dict, seed: int = 0) -> tuple[dict, dict]:
    """The final maps of one modality from ``oof`` {key: (out-of-fold stage-1 confidences (n,), truth (n,),
    scenes (n,)[, weights (n,)])}. Per-face keys (``FACE_PREDS``) choose among none, the pooled isotonic map of the
    per-face keys' rows and their own isotonic map; the other keys among none, the pooled map of every key's rows
    and their own (:func:`_choose_final`). So a per-face key's final map depends on per-face rows only: a new
    input of the pair keys' maps cannot move it. Returns (the modality's final maps: the every-key pooled knots,
    "faces" the per-face pooled knots and "by_pred" {key: own knots, None for no final stage, or "faces"} for
    each key that does not take the every-key pooled map, {key: {choice: CV log loss}})."""
    preds = sorted(oof)
    faces = [p for p in preds if p in FACE_PREDS]
    final, choice, losses = _choose_final(oof, preds, [p for p in preds if p not in FACE_PREDS], seed)
    by_pred = {p: c for p, c in choice.items() if c != "pooled"}
    if faces:
        final["faces"], choice, face_losses = _choose_final(oof, faces, faces, seed)
        by_pred.update({p: "faces" if c == "pooled" else c for p, c in choice.items()})
        losses.update(face_losses)
    return {**final, "by_pred": by_pred}, losses


def fit(rows: list[dict], modalities, real_share: float = REAL_SHARE, log=print,
        memo: dict | None = None) -> tuple[dict, dict]:
    """(table, final) fitted on ``rows`` (rendered and real together) for ``modalities``. ``memo``: a dict that
    keeps the per-key fits of keys without real rows between calls on the same rendered rows (the held-out fits
    differ in their real rows only)."""
    by = defaultdict(list)
    for r in rows:
        if r["modality"] in modalities and r["p"] > 0 and not reads_as_other(r):
            by[(r["modality"], row_key(r))].append(r)
    table: dict = {}
    oof = defaultdict(dict)  # per modality, per key: out-of-fold confidences, truth, scenes, weights
    for key in sorted(by):
        rs = by[key]
        n_real = sum(is_real(r) for r in rs)
        w = row_weights(rs, real_share)
        if memo is not None and not n_real and (key, len(rs)) in memo:
            entry, losses, conf, by_kind = memo[(key, len(rs))]
        else:
            entry, losses, conf, by_kind = fit_one(rs, w=w)
            if memo is not None and not n_real:
                memo[(key, len(rs))] = entry, losses, conf, by_kind
        oof[key[0]][key[1]] = (conf, np.array([r["y"] for r in rs], float), np.array([scene_of(r) for r in rs]), w)
        log(f"  {key[0]:5s} {key[1]:20s} n={len(rs):5d} ({n_real} real)  cv log loss "
            + "  ".join(f"{k} {v:.4f}" for k, v in losses.items())
            + f"  -> {'raw' if entry is None else entry['map'] + ' ' + ','.join(entry['features'])}")
        for kind, ls in by_kind.items():  # the same maps' losses over one kind of frame's rows alone
            log(f"  {'':5s} {'':20s} {kind + ' rows':>13s}  " + "  ".join(f"{k} {v:.4f}" for k, v in ls.items()))
        if entry is not None:
            table.setdefault(key[0], {})[key[1]] = entry
    final = {}
    log("final map per key, scene-grouped 5-fold CV log loss:")
    for mod in sorted(oof):
        final[mod], losses = fit_final(oof[mod])
        for pred, ls in losses.items():
            log(f"  {mod:5s} {pred:20s} " + "  ".join(f"{k} {v:.4f}" for k, v in ls.items()) + f"  -> {min(ls, key=ls.get)}")
    for mod, other in READ_AS.items():  # the keys a modality reads as another does take that one's maps
        if mod in final and other in final:
            angle_keys = {k for (m, k), rs in by.items() if m == other and rs[0]["pred"] in ANGLE_PREDS}
            for key in sorted(angle_keys):
                if key in table.get(other, {}):
                    table.setdefault(mod, {})[key] = table[other][key]
                else:  # the other modality keeps the raw probability (then its final map)
                    table.get(mod, {}).pop(key, None)
                final[mod]["by_pred"][key] = final_knots(final[other], key)
                log(f"  {mod:5s} {key:20s} takes {other}'s maps")
    return table, final


def reads_as_other(r: dict) -> bool:
    """Whether the row's fact is read as another modality reads it (``READ_AS``), so that it takes that
    modality's maps and fits none of its own."""
    return r["modality"] in READ_AS and r["pred"] in ANGLE_PREDS


def final_knots(final: dict, key: str) -> dict | None:
    """The final map one modality's ``final`` (:func:`fit_final`'s layout) gives ``key``, as grounding reads it
    (its own knots, None for no final stage, or the per-face pooled knots), the every-key pooled map as its knots
    alone."""
    knots = grounding_final_knots(key, final)
    return {"x": final["x"], "y": final["y"]} if knots is final else knots


# ---------------------------------------------------------------------------------------------- checks


def rendered_ece(rows: list[dict], maps: tuple) -> dict:
    """{modality: {predicate: (ECE, facts)}} of the facts emitted under ``maps`` (table, final) (confidence >=
    MIN_CONF), grouped by predicate as lv3d.calibrate.check groups them, and "all" over every fact."""
    facts = defaultdict(list)
    for r in rows:
        if r["modality"] not in MODALITIES or not r["p"] > 0:
            continue
        c = calibrate_with(maps[0], r["modality"], row_key(r), r["p"], r, maps[1])
        if c >= MIN_CONF:
            facts[(r["modality"], r["pred"])].append((c, float(r["y"])))
            facts[(r["modality"], "all")].append((c, float(r["y"])))
    out: dict = defaultdict(dict)
    for (mod, pred), v in sorted(facts.items()):
        a = np.array(v)
        out[mod][pred] = (round(ece(a[:, 0], a[:, 1]), 4), len(a))
    return dict(out)


def report_rendered(rows: list[dict], table: tuple, title: str, shipped: tuple | None = None) -> None:
    """Per (modality, key): ECE of the raw probabilities, of ``shipped`` (the maps in the tree when the fit began)
    if given, and of ``table`` (table, final), with the chance level of its confidences; then per modality over
    every emitted fact."""
    print(f"== {title}: per-key ECE of emitted facts (conf >= {MIN_CONF}), raw -> "
          + ("shipped -> " if shipped is not None else "") + "calibrated")
    by = defaultdict(list)
    for r in rows:
        by[(r["modality"], row_key(r))].append(r)

    def emitted(tab):
        return np.array([(c, r["y"]) for r in rs if (c := calibrate_with(tab[0], *key, r["p"], r, tab[1])) >= MIN_CONF],
                        float).reshape(-1, 2)

    for key in sorted(by):
        if key[0] not in MODALITIES:
            continue
        rs = by[key]
        raw = np.array([(min(r["p"], 1.0), r["y"]) for r in rs if r["p"] >= MIN_CONF], float).reshape(-1, 2)
        cal = emitted(table)
        old = f"  shipped {ece(*emitted(shipped).T):.3f}" if shipped is not None else ""
        print(f"  {key[0]:5s} {key[1]:20s} raw {ece(*raw.T):.3f} (n={len(raw):5d}){old}  calibrated {ece(*cal.T):.3f} "
              f"(n={len(cal):5d}, chance {chance_ece(cal[:, 0]):.3f})  mean conf "
              f"{cal[:, 0].mean() if len(cal) else float('nan'):.2f} true {cal[:, 1].mean() if len(cal) else float('nan'):.2f}")
    for mod in MODALITIES:  # every emitted fact, and the log loss of every candidate (p > 0): a proper score
        rs = [r for r in rows if r["modality"] == mod and r["p"] > 0]
        if not rs:
            continue
        y = np.array([r["y"] for r in rs], float)
        line = f"  {mod:5s} all facts           "
        for name, tab in (("shipped", shipped), ("calibrated", table)):
            if tab is None:
                continue
            c = np.array([calibrate_with(tab[0], mod, row_key(r), r["p"], r, tab[1]) for r in rs])
            line += (f"  {name} ECE {ece(c[c >= MIN_CONF], y[c >= MIN_CONF]):.3f} (n={int((c >= MIN_CONF).sum())}) "
                     f"log loss {log_loss(c, y):.4f}")
        print(line)


def real_figures(frames: list[dict], maps: tuple | None = None, conf: dict | None = None) -> dict:
    """bench_real's box and calibration figures (lv3d.calibrate.real.figures) of real frame entries under ``maps``
    (table, final), or with each candidate's confidence looked up in ``conf`` {id(row): confidence}."""
    if conf is not None:
        return real_rows.figures(frames, lambda r: conf[id(r)])
    return real_rows.figures(frames, lambda r: calibrate_with(maps[0], r["modality"], r["key"], r["p"], r, maps[1]))


def frame_folds(real: list[tuple[Path, dict, str]], k: int = 5, seed: int = 0) -> dict[str, int]:
    """{folder/frame: one of ``k`` folds}, each folder's frames dealt out over the folds in a seeded random order
    (so every fold holds frames of every folder)."""
    rng = np.random.default_rng(seed)
    out = {}
    for _, d, _ in real:
        names = sorted({f"{e['folder']}/{e['frame']}" for e in d["frames"]})
        out.update({n: i % k for n, i in zip(names, rng.permutation(len(names)))})
    return out


def print_real(title: str, sets: dict[str, dict], before: dict[str, dict] | None = None) -> None:
    """One line per set (folder, or "pooled") and modality: the figures, after the shipped ones if given."""
    print(f"== {title}")
    for name, figs in sets.items():
        for m, f in sorted(figs.items()):
            b = (before or {}).get(name, {}).get(m, {})
            cells = []
            for k in ("perpendicular_ece", "box_perpendicular_frac", "cylinder_as_prism_frac"):
                v = f[k]
                was = f"{b[k]:.3f} -> " if b.get(k) is not None else ""
                cells.append(f"{k} {was}{'null' if v is None else f'{v:.3f}'}")
            print(f"  {name:16s} {m:5s} " + "  ".join(cells) + f"  ({f['pairs']} pairs)")


def real_sets(real: list[tuple[Path, dict, str]], **kw) -> dict[str, dict]:
    """:func:`real_figures` of each real pickle's frames and of all of them pooled."""
    sets = {d["folders"][0] if len(d.get("folders", [])) == 1 else p.name: real_figures(d["frames"], **kw)
            for p, d, _ in real}
    if len(real) > 1:
        sets["pooled"] = real_figures([e for _, d, _ in real for e in d["frames"]], **kw)
    return sets


# ---------------------------------------------------------------------------------------------- provenance


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _git(*args: str) -> str | None:
    """The output of a git command in the repository (trailing newline off), None where git cannot answer."""
    try:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.rstrip("\n")
    except (OSError, subprocess.CalledProcessError):
        return None


# the fit's sources and the code that makes its data: files that differ from the git commit are named
CODE = ("grounding", "lv3d/perception", "lv3d/describe.py", "lv3d/calibrate", "lv3d/object_facts.py",
        "lv3d/frame_folder.py")


def provenance(command: str, data: list[tuple[Path, dict, str]]) -> dict:
    """Who made the file: the command (the ``lv3d calibrate fit`` command line), the code version (git commit,
    the files of ``CODE`` that differed from it), the sources' digests (lv3d.calibration.source_digests) and each
    data file (name, sha256, rows, scenes, the command that made it, its kind)."""
    from ..calibration import source_digests

    dirty = _git("status", "--porcelain", "--", *CODE)
    return {
        "command": command,
        "git_commit": _git("rev-parse", "HEAD"),
        "uncommitted": sorted(line[3:] for line in (dirty or "").splitlines()),
        "sources_sha256": source_digests(),
        "fitted_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "data": [{"file": p.name, "kind": kind, "sha256": _sha256(p), "rows": len(d["rows"]),
                  "scenes": len({scene_of(r) for r in d["rows"]}),
                  "made_by": d.get("made_by")}
                 for p, d, kind in data],
    }


def to_json(doc: dict) -> str:
    """``doc`` as indented JSON with every list of numbers or strings on one line (knots and coefficients)."""
    import re

    text = json.dumps(doc, indent=1)
    return re.sub(r"\[[^\[\]{}]*\]", lambda m: " ".join(m.group(0).split()).replace("[ ", "[").replace(" ]", "]"),
                  text) + "\n"


def run(data: list[Path], real: list[Path] = (), check: list[Path] = (), holdout: bool = False,
        real_share: float = REAL_SHARE, out: Path | None = None, dry_run: bool = False,
        modalities: tuple[str, ...] = MODALITIES, command: str = "") -> Path | None:
    """The whole fit: read the rendered pickles ``data`` (lv3d.calibrate.rows), the real ones ``real``
    (lv3d.calibrate.real) and the rendered check sets ``check``; with ``holdout``, first the held-out checks;
    fit on every set; print the figures and, unless ``dry_run``, write the calibration file ``out`` (default:
    the shipped one) with its provenance (``command``: the command line). Returns the file written."""
    from ..calibration import DATA, FORMAT, read

    out = DATA if out is None else Path(out)
    bad = [m for m in modalities if m not in MODALITIES]
    if bad or not modalities:
        raise InputError("--modalities", f"choose among {', '.join(MODALITIES)}, not {','.join(modalities)!r}")
    if not 0.0 <= real_share <= 1.0:
        raise InputError("--real-share", f"a share within [0, 1], not {real_share}")
    if not data:
        raise InputError("DATA", "no rendered rows given (lv3d calibrate rows makes them)")
    if not dry_run:
        _check_out(out)
    mods = list(modalities)
    rendered = [(Path(p), rendered_rows.read(p), "rendered") for p in data]
    reals = [(Path(p), real_rows.read(p), "real") for p in real]
    checks = [(Path(p), rendered_rows.read(p), "rendered check") for p in check]
    shipped_file = read(DATA) if DATA.is_file() else None
    shipped = None if shipped_file is None else (shipped_file["table"], shipped_file["final"])
    render_rows = [r for _, d, _ in rendered for r in d["rows"]]
    check_rows = [r for _, d, _ in checks for r in d["rows"]]
    out_checks: dict = {}

    def quiet(*_args, **_kw):
        return None

    memo: dict = {}
    before = real_sets(reals, maps=shipped) if shipped and reals else None
    if holdout and reals:
        # 1. a new sensor: fit without each real pickle, figures on the one left out
        held = {}
        for i, (path, d, _) in enumerate(reals):
            others = [r for j, (_, e, _) in enumerate(reals) if j != i for r in e["rows"]]
            maps = fit(render_rows + others, mods, real_share, log=quiet, memo=memo)
            name = d["folders"][0] if len(d.get("folders", [])) == 1 else path.name
            held[name] = real_figures(d["frames"], maps)
        print_real("each real set left out of the fit (fitted on the rendered rows and the other real sets)"
                   + ("; shipped -> held out" if before else ""), held, before)
        out_checks["real_held_out"] = held
        # 2. new frames of the same sensors: frame-grouped folds over every real set
        folds = frame_folds(reals, HOLDOUT_FOLDS)
        conf = {}
        for k in range(HOLDOUT_FOLDS):
            train = [r for _, d, _ in reals for r in d["rows"] if folds[r["scene"]] != k]
            maps = fit(render_rows + train, mods, real_share, log=quiet, memo=memo)
            for _, d, _ in reals:
                for e in d["frames"]:
                    if folds[f"{e['folder']}/{e['frame']}"] == k:
                        for r in e["cands"]:
                            conf[id(r)] = calibrate_with(maps[0], r["modality"], r["key"], r["p"], r, maps[1])
        cv = real_sets(reals, conf=conf)
        print_real(f"real frames in {HOLDOUT_FOLDS} frame-grouped folds, each fold's confidences from a fit without "
                   "it" + ("; shipped -> out of fold" if before else ""), cv, before)
        out_checks["real_frame_folds"] = cv
    print("== fit on every set")
    maps = fit(render_rows + [r for _, d, _ in reals for r in d["rows"]], mods, real_share, memo=memo)
    for m in MODALITIES:  # a modality not refitted keeps the shipped maps
        if m not in mods and shipped is not None:
            maps[0][m], maps[1][m] = shipped[0].get(m, {}), shipped[1].get(m, {})
    if reals:
        in_fit = real_sets(reals, maps=maps)
        print_real("real sets in the fit" + ("; shipped -> calibrated" if before else ""), in_fit, before)
        out_checks["real_in_fit"] = in_fit
    report_rendered(render_rows, maps, f"fit rows ({', '.join(Path(p).name for p in data)})")
    if check_rows:
        report_rendered(check_rows, maps, f"check rows ({', '.join(Path(p).name for p in check)})", shipped)
        out_checks["rendered_check"] = {"sets": [Path(p).name for p in check], "ece": rendered_ece(check_rows, maps)}
    if dry_run:
        return None
    doc = {"format": FORMAT,
           "about": "Confidence calibration maps of lv3d (lv3d/calibration.py, grounding.Calibration); written by "
                    "lv3d calibrate fit, not to be edited by hand.",
           "provenance": provenance(command, rendered + reals + checks), "checks": out_checks,
           "table": maps[0], "final": maps[1]}
    write_atomic(out, to_json(doc))
    print(f"wrote {out}")
    return out


def _check_out(out: Path) -> None:
    """A calibration file may replace only a calibration file (or nothing): a one-line InputError otherwise."""
    if out.is_dir():
        raise InputError(out, "is a folder; --out names a calibration file")
    if out.exists():
        try:
            doc = json.loads(out.read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            doc = None
        if not (isinstance(doc, dict) and "format" in doc and "provenance" in doc):
            raise InputError(out, "exists and is not a calibration file; lv3d calibrate fit replaces only its own")
