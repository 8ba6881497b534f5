"""Fit the per-(modality, predicate) confidence calibration maps and write grounding/_calibration_table.py.

The table in the tree (docs/grounding.md, "Calibration on perceived scenes"): rgbd refitted in session 21, when
parallel's maps were offered the side the two faces share, on 9800 fresh scenes of dev seeds (session 20's 5600
and 4200 more; each 1050-scene set ~2-4 min on one core, two at a time), checked on 3570 scenes (seeds 100000+,
50000+, 150000+ and 160000+)::

    for a in "30000 150 a150" "40000 150 b150" "60000 100 d60000" "70000 100 d70000" "80000 150 e80000" \
             "90000 150 f90000" "110000 150 g110000" "120000 150 g120000" "130000 150 g130000" \
             "140000 150 g140000" "100000 150 chk100000" "50000 60 c60" "150000 150 k150000" \
             "160000 150 k160000"; do set -- $a
        .venv/bin/python benchmarks/calibration_data.py --fresh --seed $1 --per-class $2 --modalities rgbd \
            --out out/calib/$3.pkl; done
    .venv/bin/python benchmarks/fit_calibration.py out/calib/{a150,b150,d60000,d70000,e80000,f90000}.pkl \
        out/calib/{g110000,g120000,g130000,g140000}.pkl --check out/calib/chk_all.pkl --modalities rgbd

(chk_all: the rows and scenes of chk100000, c60, k150000 and k160000 concatenated into one pickle; the fit takes ~30 s). Depth is session 17's, fitted for both
modalities after the dihedral tolerance became 90 +- 7 deg (docs/facts.md) and side counts moved onto the plane:
3500 scenes, each 1050-scene set ~3.5 min on one core with rgbd and depth, the 420-scene check set ~1.2 min, the fit
~20 s:

    for a in "30000 150 a150" "40000 150 b150" "60000 100 d60000" "70000 100 d70000"; do set -- $a
        .venv/bin/python benchmarks/calibration_data.py --fresh --seed $1 --per-class $2 --modalities rgbd,depth \
            --out out/calib/s17p_$3.pkl; done
    .venv/bin/python benchmarks/calibration_data.py --fresh --seed 50000 --per-class 60 --modalities rgbd,depth --out out/calib/s17p_c60.pkl
    .venv/bin/python benchmarks/fit_calibration.py out/calib/s17p_{a150,b150,d60000,d70000}.pkl --check out/calib/s17p_c60.pkl

For each (modality, predicate) four maps compete by scene-grouped 5-fold cross-validated log loss on the dev rows:
the raw probability unchanged, a shift in logit space, Platt scaling (bias + slope on logit p), and Platt
plus a few face measurements (``FEATURES``) and, for predicates with a tolerance, the measured value in
tolerances (``tol_frac``); for facts about two faces (``PAIR_PREDS``) also that map plus the length of the side
the two faces share (``PAIR_FEATURES``), and for parallel (``PLANE_GAP_PREDS``) that map plus how far the two faces
are from one plane (``PLANE_GAP_FEATURES``), and that map plus the shared side. The winner is refitted on all rows (L2-regularised logistic regression,
measurements standardised, the standardisation folded into the coefficients). A map whose slope on
logit p comes out negative is not used (confidence must grow with the measured probability). Then the
final map (``FINAL``) of out-of-fold confidences: per modality one isotonic map of every type pooled, one of
the per-face types (``FACE_PREDS``) pooled, and per type the best by scene-grouped 5-fold CV log loss of
none, its group's pooled map (per-face types: the per-face one, so the pair types' inputs cannot move their
choice) and the type's own isotonic map (``fit_final``).
``--modalities rgbd`` refits one modality and keeps the other's maps from the table in the tree (session 14 refitted
rgbd alone: a depth refit on fresh rows scored worse on held-out dev scenes, docs/grounding.md).
``--check`` prints per-type ECE on another dev set (rows with confidence >= 0.05, as facts are emitted)
for the raw probabilities, the table in the tree and the new one, and each modality's ECE and log loss
over all facts. Rows come from dev seeds only, never the study's data.
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

from benchmarks.calibration_error import chance_ece, ece, log_loss  # noqa: E402
from grounding._calibration import SHARED_SIDE_PREDS, TOL_FRAC_PREDS, calibration_key, inputs  # noqa: E402
from lv3d.describe import SIDE_NAMES  # noqa: E402
from lv3d.facts import PREDICATES  # noqa: E402

MODALITIES = ("rgbd", "depth")  # rgb is left raw: see docs/grounding.md (its labels need a look first)
FEATURES = ["support", "log_area_px", "min_turn_z", "min_side_px"]
MIN_ROWS = 12        # fewer rows (or one class of label only): keep the raw probability
C_REG = 0.5          # inverse L2 strength of the logistic fits (standardised inputs)
MIN_CONF = 0.05
MIN_OWN_FINAL = 50   # fewer rows of either label: a type's own isotonic map would be steps of a few facts
FINAL_REPEATS = 5    # fold draws the final maps are chosen over (_choose_final)
SUPPORT_PREDS = ("face_of", "adjacent", "object")
# facts about two faces whose map may also read the side the faces share (0: none, e.g. pyramid laterals
# touching at the apex); parallel is offered it beside the plane gap (PLANE_GAP_PREDS): with ~60 fit rows (session
# 14) it made parallel's log loss worse out of sample, with ~900 (session 21) better
PAIR_PREDS = SHARED_SIDE_PREDS
PAIR_FEATURES = ["shared_side_px"]
# facts about two planes whose map may also read how far the two faces are from one plane: parallel facts that
# hold are mostly two pieces of one face, a few mm apart (docs/grounding.md, session 14)
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

    z = np.array([inputs(r["pred"], r["p"], r, ["logit_p"])[0] for r in rows])
    y = np.array([r["y"] for r in rows], float)

    def loss(b):  # log loss plus the two half pseudo-observations at logit 0
        return len(y) * log_loss(_predict(b, np.ones(1), z[:, None]), y) + 0.5 * (np.logaddexp(0, -b) + np.logaddexp(0, b))

    return float(minimize_scalar(loss, bounds=(-15, 15), method="bounded").x), np.ones(1), ["logit_p"]


def _fit_monotone(rows: list[dict], feats: list[str] | None):
    if feats is None:
        return _fit_shift(rows)
    """(bias, coef, features) of a logistic map; refitted without logit p when its slope comes out
    negative (where p carries no information, e.g. always 1, the map must not turn it upside down)."""
    y = np.array([r["y"] for r in rows], float)
    if not feats:  # a constant: the smoothed rate
        return float(np.log((y.sum() + .5) / ((1 - y).sum() + .5))), np.zeros(0), []
    x = np.array([inputs(r["pred"], r["p"], r, feats) for r in rows])
    b, c = _fit(x, y)
    if feats and feats[0] == "logit_p" and c[0] < 0:
        return _fit_monotone(rows, feats[1:])
    return b, c, feats


def _scene_fold_of(seeds, seed: int) -> dict:
    """{scene (its render seed): one of 5 folds} over the scenes of ``seeds``, seeded: every row of one scene
    goes to the same fold. A scene's facts share its view and its perception errors; rows of one scene on both
    sides of a split would reward a map for learning the scene rather than the fact type."""
    scenes = np.unique(np.asarray(seeds))
    return dict(zip(scenes.tolist(), np.random.default_rng(seed).permutation(len(scenes)) % 5))


def fit_one(rows: list[dict], seed: int = 0):
    """The best map for one (modality, predicate) by scene-grouped 5-fold CV log loss (:func:`_scene_fold_of`):
    (None (raw) or a table entry, {map: CV log loss}, the winner's out-of-fold confidences (n,))."""
    y = np.array([r["y"] for r in rows], float)
    p = np.array([r["p"] for r in rows])
    if len(rows) < MIN_ROWS:
        return None, {}, np.clip(p, 0, 1)
    fold = _scene_fold_of([r["seed"] for r in rows], seed)
    folds = np.array([fold[r["seed"]] for r in rows])
    tol = ["tol_frac"] if rows[0]["pred"] in TOL_FRAC_PREDS else []  # the measured value in tolerances
    cands = {"raw": "raw", "shift": None, "platt": ["logit_p"], "platt+measures": ["logit_p"] + FEATURES + tol}
    if rows[0]["pred"] in PAIR_PREDS:
        cands["platt+measures+shared"] = ["logit_p"] + FEATURES + PAIR_FEATURES + tol
    if rows[0]["pred"] in PLANE_GAP_PREDS:
        cands["platt+measures+gap"] = ["logit_p"] + FEATURES + PLANE_GAP_FEATURES + tol
        cands["platt+measures+gap+shared"] = ["logit_p"] + FEATURES + PLANE_GAP_FEATURES + PAIR_FEATURES + tol
    if rows[0]["pred"] in SUPPORT_PREDS:  # p is edge support, not a geometric probability: may be ignored
        cands["const"] = []
    losses, oof = {}, {}
    for name, feats in cands.items():
        pred = np.empty(len(rows))
        for k in range(5):
            tr, te = folds != k, folds == k
            if feats == "raw":
                pred[te] = np.clip(p[te], 0, 1)
                continue
            trows = [r for r, t in zip(rows, tr) if t]
            b, c, f = _fit_monotone(trows, feats)
            x = np.array([inputs(r["pred"], r["p"], r, f) for r, t in zip(rows, te) if t]).reshape(int(te.sum()), len(f))
            pred[te] = _predict(b, c, x)
        losses[name], oof[name] = log_loss(pred, y), pred
    name = min(losses, key=losses.get)
    if cands[name] == "raw":
        return None, losses, oof[name]
    b, c, f = _fit_monotone(rows, cands[name])
    return {"features": f, "bias": round(b, 5), "coef": [round(float(v), 5) for v in c], "n": len(rows),
            "map": name, "cv_logloss": round(losses[name], 4)}, losses, oof[name]


def _isotonic(conf: np.ndarray, y: np.ndarray):
    from sklearn.isotonic import IsotonicRegression

    return IsotonicRegression(y_min=1e-3, y_max=1 - 1e-3, out_of_bounds="clip").fit(conf, y)


def _knots(iso) -> dict:
    """An isotonic fit as knots {"x": [...], "y": [...]} (ascending x), values within [0.001, 0.999]."""
    return {"x": [round(float(v), 5) for v in iso.X_thresholds_], "y": [round(float(v), 5) for v in iso.y_thresholds_]}


def _choose_final(oof: dict, pool: list[str], members: list[str], seed: int) -> tuple[dict, dict, dict]:
    """Fit the isotonic map of the rows of the types in ``pool`` together and choose, for each type in
    ``members``, among none, that pooled map and the type's own (with ``MIN_OWN_FINAL`` rows of each label)
    by scene-grouped 5-fold CV log loss on its own rows, averaged over ``FINAL_REPEATS`` fold draws (one draw's
    choice between near-equal maps was a coin toss: rgbd pentagon flipped from the pooled map to none when a
    sixth of the rows was added, and its check-set ECE doubled). Returns (pooled knots, {member: "pooled", None or
    own knots}, {member: {choice: mean CV log loss}}). Nothing outside ``pool`` enters the choice."""
    conf, y, seeds = (np.concatenate([oof[p][i] for p in pool]) for i in range(3))
    sums: dict = defaultdict(lambda: defaultdict(float))
    for rep in range(FINAL_REPEATS):
        fold = _scene_fold_of(seeds, seed + rep)
        folds = np.array([fold[s] for s in seeds.tolist()])
        pooled = [_isotonic(conf[folds != k], y[folds != k]) for k in range(5)]
        for pred in members:
            c, t = oof[pred][0], oof[pred][1]
            f = np.array([fold[s] for s in oof[pred][2]])
            cands = {"none": c, "pooled": np.empty(len(c))}
            if min(t.sum(), len(t) - t.sum()) >= MIN_OWN_FINAL:
                cands["own"] = np.empty(len(c))
            for k in range(5):
                te = f == k
                if not te.any():  # a rare type (depth parallel: 8 rows in session 9) may miss a fold
                    continue
                cands["pooled"][te] = pooled[k].predict(c[te])
                if "own" in cands:
                    cands["own"][te] = _isotonic(c[~te], t[~te]).predict(c[te])
            for name, v in cands.items():
                sums[pred][name] += log_loss(v, t) / FINAL_REPEATS
    choice, losses = {}, {}
    for pred in members:
        losses[pred] = dict(sums[pred])
        best = min(losses[pred], key=losses[pred].get)
        c, t = oof[pred][0], oof[pred][1]
        choice[pred] = best if best == "pooled" else None if best == "none" else _knots(_isotonic(c, t))
    return _knots(_isotonic(conf, y)), choice, losses


def fit_final(oof: dict, seed: int = 0) -> tuple[dict, dict]:
    """The final maps of one modality from ``oof`` {pred: (out-of-fold stage-1 confidences (n,), truth (n,),
    scene seeds (n,))}. Per-face types (``FACE_PREDS``) choose among none, the pooled isotonic map of the
    per-face types' rows and their own isotonic map; the other types among none, the pooled map of every
    type's rows and their own (:func:`_choose_final`, scene-grouped 5-fold CV log loss: a scene's facts share
    its view and perception errors). So a per-face type's final map depends on per-face rows only: a new
    input of the pair types' maps cannot move it (session 9: it flipped rgbd pentagon to the pooled map).
    Returns (the ``FINAL`` entry: the every-type pooled knots, "faces" the per-face pooled knots and
    "by_pred" {pred: own knots, None for no final stage, or "faces"} for each type that does not take the
    every-type pooled map, {pred: {choice: CV log loss}})."""
    preds = sorted(oof)
    faces = [p for p in preds if p in FACE_PREDS]
    final, choice, losses = _choose_final(oof, preds, [p for p in preds if p not in FACE_PREDS], seed)
    by_pred = {p: c for p, c in choice.items() if c != "pooled"}
    if faces:
        final["faces"], choice, face_losses = _choose_final(oof, faces, faces, seed)
        by_pred.update({p: "faces" if c == "pooled" else c for p, c in choice.items()})
        losses.update(face_losses)
    return {**final, "by_pred": by_pred, "fewer_maps": True, "touch_maps": True}, losses


def report(rows: list[dict], table: tuple, title: str, shipped: tuple | None = None) -> None:
    """Per (modality, predicate): ECE of the raw probabilities, of ``shipped`` (the (TABLE, FINAL) in the
    tree when the fit began) if given, and of ``table`` (TABLE, FINAL), with the chance level of its
    confidences."""
    from grounding._calibration import calibrate_with

    print(f"== {title}: per-type ECE of emitted facts (conf >= {MIN_CONF}), raw -> "
          + ("shipped table -> " if shipped is not None else "") + "calibrated")
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
        print(f"  {key[0]:5s} {key[1]:14s} raw {ece(*raw.T):.3f} (n={len(raw):4d}){old}  calibrated {ece(*cal.T):.3f} "
              f"(n={len(cal):4d}, chance {chance_ece(cal[:, 0]):.3f})  mean conf {cal[:, 0].mean() if len(cal) else float('nan'):.2f} "
              f"true {cal[:, 1].mean() if len(cal) else float('nan'):.2f}")
    for mod in MODALITIES:  # every emitted fact, and the log loss of every candidate (p > 0): a proper score
        rs = [r for r in rows if r["modality"] == mod and r["p"] > 0]
        if not rs:  # a set made for the other modality only
            continue
        y = np.array([r["y"] for r in rs], float)
        line = f"  {mod:5s} all facts     "
        for name, tab in (("shipped", shipped), ("calibrated", table)):
            if tab is None:
                continue
            c = np.array([calibrate_with(tab[0], mod, row_key(r), r["p"], r, tab[1]) for r in rs])
            line += f"  {name} ECE {ece(c[c >= MIN_CONF], y[c >= MIN_CONF]):.3f} (n={int((c >= MIN_CONF).sum())}) log loss {log_loss(c, y):.4f}"
        print(line)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("data", type=Path, nargs="+", help="pickles from benchmarks/calibration_data.py")
    ap.add_argument("--check", type=Path, help="another dev set to report ECE on")
    ap.add_argument("--out", type=Path, default=ROOT / "grounding" / "_calibration_table.py")
    ap.add_argument("--dry-run", action="store_true")
    ap.add_argument("--modalities", default=",".join(MODALITIES),
                    help="refit these; the other modalities' maps are kept from the table in the tree")
    a = ap.parse_args(argv)
    refit = a.modalities.split(",")
    if not set(refit) <= set(MODALITIES):
        ap.error(f"--modalities: choose from {', '.join(MODALITIES)}")
    rows = [r for path in a.data for r in pickle.loads(path.read_bytes())["rows"]]
    by = defaultdict(list)
    for r in rows:
        if r["modality"] in refit and r["p"] > 0:
            by[(r["modality"], row_key(r))].append(r)
    from grounding._calibration_table import FINAL, TABLE

    kept = [m for m in MODALITIES if m not in refit]
    table: dict = {m: TABLE[m] for m in kept if m in TABLE}
    oof = defaultdict(dict)  # per modality, per predicate: out-of-fold confidences, truth, scene seeds
    for key in sorted(by):
        entry, losses, conf = fit_one(by[key])
        oof[key[0]][key[1]] = (conf, np.array([r["y"] for r in by[key]], float), np.array([r["seed"] for r in by[key]]))
        print(f"  {key[0]:5s} {key[1]:14s} n={len(by[key]):5d}  cv log loss "
              + "  ".join(f"{k} {v:.4f}" for k, v in losses.items()) + f"  -> {'raw' if entry is None else entry['map'] + ' ' + ','.join(entry['features'])}")
        if entry is not None:
            table.setdefault(key[0], {})[key[1]] = entry
    final = {m: FINAL[m] for m in kept if m in FINAL}
    print("final map per type, scene-grouped 5-fold CV log loss:")
    for mod in sorted(oof):
        final[mod], losses = fit_final(oof[mod])
        for pred, ls in losses.items():
            print(f"  {mod:5s} {pred:14s} " + "  ".join(f"{k} {v:.4f}" for k, v in ls.items()) + f"  -> {min(ls, key=ls.get)}")
    report(rows, (table, final), f"fit rows ({', '.join(map(str, a.data))})")
    if a.check:
        report(pickle.loads(a.check.read_bytes())["rows"], (table, final), f"check rows ({a.check})", (TABLE, FINAL))
    if not a.dry_run:
        keep_note = f"; {', '.join(kept)} kept from the table before" if kept else ""
        a.out.write_text('"""Calibration maps (see _calibration.py), written by benchmarks/fit_calibration.py: '
                         f'{", ".join(refit)} from\n{", ".join(p.name for p in a.data)} (perceived realsense dev scenes)'
                         f'{keep_note}. Do not edit by hand."""\n\n'
                         f"TABLE: dict = {pprint.pformat(table, width=110, sort_dicts=True)}\n\n"
                         f"FINAL: dict = {pprint.pformat(final, width=110, compact=True)}\n")
        print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
