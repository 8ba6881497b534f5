"""Calibration of fact probabilities: maps handed in as plain data turn a raw probability into a calibrated one.

The Gaussian probability of a predicate (``_confidence``) speaks only of the errors the residuals can
see. End to end, perception also makes gross errors the Laplace covariance cannot know of: a spurious
corner on a long side (a pentagon that is a quadrilateral), a face split in two, a plane fitted across
an edge, a curved surface read as a plane. A per-(modality, key) logistic map turns the raw probability ``p``
and a few measurements of the faces behind it into a calibrated one:

    conf = sigmoid(bias + sum_k coef_k m_k + max(0, slope) logit p),  slope = sum_j coef_j g_j

with ``m`` the measurements named in the map and ``g`` the factors of its ``logit_p`` inputs: ``"logit_p"``
itself (g = 1) and products ``"logit_p*NAME"`` (g = the measurement NAME), so that how far the measured
probability is trusted may depend on how the faces look (a measured angle says little about faces whose
outlines are not straight). Then a final non-decreasing piecewise-linear map (knots of an isotonic regression)
corrects what the logistic form leaves over. Per (modality, key) the final map is the key's own, one pooled over
the modality's facts about one face (``"faces"``), one pooled over every key, or none (``"by_pred"`` names the
choice; a key it does not name takes the pooled one). Both stages are monotone non-decreasing in ``p`` (the
slope on logit p is never below 0), so a more certain measurement never gets a lower confidence, other things
equal.

This package holds no maps: :class:`Calibration` is built from them (``{"table": {modality: {key: map}},
"final": {modality: final maps}}``, the layout the fitting code writes); a (modality, key) without a map keeps
its raw probability (then the final map, if any).
"""

from __future__ import annotations

import bisect
import math

from ._confidence import (ACUTE_BELOW_DEG, EQUAL_SIDES_RATIO, OBTUSE_ABOVE_DEG, PARALLEL_SIDES_DEG, PLANE_ANGLE_DEG,
                          PERPENDICULAR_DEG, RIGHT_ANGLE_DEG)

P_CLIP = 1e-4  # logit(p) is taken of p clipped to [P_CLIP, 1 - P_CLIP]: saturated probabilities stay finite


def logit(p: float) -> float:
    p = min(max(float(p), P_CLIP), 1.0 - P_CLIP)
    return math.log(p / (1.0 - p))


# measurements on tame scales: a corner's turn in spreads clipped (a 40-spread corner is no surer than a
# 20-spread one), lengths and variance factors as logs; absent measurements (e.g. of `object`) read as 0.
# Floors of the logs: 1 px and 1 mm (below them a length is no surer), 0.25 for a variance factor (the least
# that grounding's Laplace step lets a residual block claim, its MIN_SCALE2), 0.1 mm of plane residual (far
# below any depth sensor's noise)
_SCALE = {"min_turn_z": lambda v: min(max(v, -5.0), 20.0), "min_side_px": lambda v: math.log(max(v, 1.0)),
          "shared_side_px": lambda v: math.log(max(v, 1.0)), "plane_gap_mm": lambda v: math.log(max(v, 1.0)),
          "edge_scale2": lambda v: math.log(max(v, 0.25)), "plane_rms_mm": lambda v: math.log(max(v, 0.1))}

# "tol_frac": the fact's measured value (describe's candidate value) as a fraction of its predicate's
# tolerance, 1 at the boundary, below 1 inside it. The Gaussian probability reads the same value in units of
# its spread; where perception's errors are heavy-tailed the distance in tolerances tells more (a near-square
# face 3 spreads past the ratio limit is often square; one 2 tolerances past it, never).
_TOL_FRACTION = {
    "square": lambda v: math.log(max(v, 1.0)) / math.log(EQUAL_SIDES_RATIO),  # v: longest / shortest side
    "regular": lambda v: math.log(max(v, 1.0)) / math.log(EQUAL_SIDES_RATIO),
    "rectangle": lambda v: v / RIGHT_ANGLE_DEG,                               # v: largest |corner - 90| deg
    "parallelogram": lambda v: v / PARALLEL_SIDES_DEG,                        # v: opposite sides' angle deg
    "perpendicular": lambda v: abs(v - 90.0) / PERPENDICULAR_DEG,               # v: interior dihedral deg
    "acute": lambda v: 1.0 + (v - ACUTE_BELOW_DEG) / PERPENDICULAR_DEG,
    "obtuse": lambda v: 1.0 + (OBTUSE_ABOVE_DEG - v) / PERPENDICULAR_DEG,
    "parallel": lambda v: v / PLANE_ANGLE_DEG,                                # v: angle between the planes deg
    "horizontal": lambda v: v / PLANE_ANGLE_DEG,                              # v: tilt to the support deg
    "vertical": lambda v: abs(90.0 - v) / PLANE_ANGLE_DEG,
}
TOL_FRAC_PREDS = tuple(_TOL_FRACTION)


def _tol_fraction(pred: str):
    frac = _TOL_FRACTION[pred]
    return lambda v: min(max(frac(v), -3.0), 3.0)  # 3 tolerances out is as false as it gets


# facts about two faces whose maps may read the length of the side the two share (0: they touch at a point); the
# facts about two faces that touch at a point have maps of their own (``calibration_key``)
SHARED_SIDE_PREDS = ("adjacent", "acute", "obtuse", "perpendicular")

# the suffixes of the kinds of candidate filed apart from their predicate (calibration_key)
_FEWER, _TOUCH = "_fewer", "_touch"


def calibration_key(pred: str, fewer: bool = False, shared_side_px: float | None = None) -> str:
    """The name a fact's maps are filed under: the predicate, or one of two kinds filed apart.

    - A side count read as one side fewer than the polygon has (``fewer``: a face's ``p_fewer`` fact, one vertex a
      point on a straight side): ``pred + "_fewer"``. The two kinds of one predicate have different probabilities
      behind them (a pentagon face's own count and a hexagon's count without its weakest corner) and came out
      calibrated in opposite directions on one map.
    - A fact about two faces (``SHARED_SIDE_PREDS``) that share no side (``shared_side_px`` 0, the length in pixels
      of the longest side their refined polygons have in common: they touch at a point, or a gap or a spurious
      corner parts their outlines):
      ``pred + "_touch"``. Their errors are of another kind (opposite laterals of a pyramid meeting at its apex are
      no neighbours; a tetrahedron's faces traced apart are), and one map over both kinds would read its
      measurements alike for both."""
    if fewer:
        return pred + _FEWER
    if pred in SHARED_SIDE_PREDS and shared_side_px is not None and shared_side_px <= 0.0:
        return pred + _TOUCH
    return pred


LOGIT_P = "logit_p"  # the input logit(p); "logit_p*NAME": logit(p) times the measurement NAME


def inputs(pred: str, p: float, x: dict, names: list[str]) -> list[float]:
    """The named inputs of ``pred``'s calibration map, on their scales: ``"logit_p"`` logit(p), ``"logit_p*NAME"``
    logit(p) times measurement NAME, NAME the measurement of ``x``."""
    lp = logit(p)
    return [(lp if slope else 1.0) * (1.0 if k is None else scale(float(x.get(k, 0.0))))
            for slope, k, scale in _inputs(pred, names)]


def factors(pred: str, x: dict, names: list[str]) -> list[float]:
    """The factor each named input multiplies (``"logit_p"``: 1, ``"logit_p*NAME"``: measurement NAME) or, for
    a plain measurement, its value: the terms the map's slope on logit p and its other terms are made of."""
    return [1.0 if k is None else scale(float(x.get(k, 0.0))) for _, k, scale in _inputs(pred, names)]


def is_slope(name: str) -> bool:
    """Whether the input ``name`` multiplies logit p (a term of the slope on logit p)."""
    return name == LOGIT_P or name.startswith(LOGIT_P + "*")


def calibrate_with(table: dict, modality: str, pred: str, p: float, x: dict | None = None,
                   final: dict | None = None) -> float:
    """The calibrated probability of one candidate fact with raw probability ``p`` and face measurements ``x``
    under the maps ``table`` ({modality: {key: map}}) and final maps ``final`` ({modality: {"x", "y"} pooled
    knots, optionally "faces", the knots pooled over facts about one face, and "by_pred", {key: the key's own
    knots, None for no final stage, or "faces"}}; None: no final stage); ``pred``: the fact's calibration key
    (:func:`calibration_key`). Uncached: :class:`Calibration` is the same, with each map's inputs looked up once."""
    fin = (final or {}).get(modality)
    return _apply(_compile(pred, table.get(modality, {}).get(pred), fin), p, x)


class Calibration:
    """Calibration maps handed in as plain data (``table`` and ``final`` as :func:`calibrate_with` takes them),
    each map compiled once on first use (a frame has ~150 candidates)."""

    def __init__(self, table: dict, final: dict | None = None):
        self.table = table
        self.final = final or {}
        self._compiled: dict[tuple[str, str], tuple | None] = {}

    def calibrate(self, modality: str, pred: str, p: float, x: dict | None = None) -> float:
        """Calibrated probability of one candidate fact with raw probability ``p`` and face measurements ``x``
        (a dict by measurement name; a name the map reads and ``x`` lacks reads 0); ``pred``: its calibration key
        (:func:`calibration_key`). ``p`` itself where nothing was fitted; 0 stays 0 (a predicate the geometry
        rules out is not revived). Equal to :func:`calibrate_with` on the same maps."""
        key = (modality, pred)
        if key not in self._compiled:
            self._compiled[key] = _compile(pred, self.table.get(modality, {}).get(pred), self.final.get(modality))
        return _apply(self._compiled[key], p, x)

    def measures_used(self, modality: str, pred: str) -> list[str]:
        """The face measurements the map of (modality, key ``pred``) reads (empty: it needs only p, or there is
        no map)."""
        entry = self.table.get(modality, {}).get(pred)
        return [] if entry is None else [n for n in entry["features"] if n != "logit_p"]


def _predicate(key: str) -> str:
    """The predicate a calibration key is of (the key without the suffix of a kind filed apart)."""
    for suffix in (_FEWER, _TOUCH):
        if key.endswith(suffix):
            return key[: -len(suffix)]
    return key


def _inputs(key: str, names: list[str]) -> list:
    """[(whether it multiplies logit p, key of the measurement in x or None for none, its scale)] of the named
    inputs of the map filed under ``key`` (a predicate, or the key of a kind filed apart: its predicate's
    tolerance)."""
    out = []
    for n in names:
        slope = is_slope(n)
        m = n[len(LOGIT_P) + 1:] if slope else n
        out.append((slope, None, None) if not m else
                   (slope, "value", _tol_fraction(_predicate(key))) if m == "tol_frac" else
                   (slope, m, _SCALE.get(m, float)))
    return out


def final_knots(pred: str, final: dict | None) -> dict | None:
    """The final map of ``pred`` in one modality's ``final`` (:func:`calibrate_with`'s layout): the type's own
    (or None, no final stage) where "by_pred" names it, the per-face pooled one ("faces") where it says
    "faces", else the pooled one of every type."""
    if final is None:
        return None
    by_pred = final.get("by_pred", {})
    knots = by_pred[pred] if pred in by_pred else final
    return final["faces"] if knots == "faces" else knots


def _compile(pred: str, entry: dict | None, final: dict | None):
    """(bias, [(coefficient, whether it multiplies logit p, key in x or None for 1, scale)], final knots (xs, ys))
    of ``pred``'s table entry (bias and terms None without one) and its final map in its modality's ``final`` (None
    without one); None if neither."""
    knots = final_knots(pred, final)
    if entry is None and knots is None:
        return None
    terms = None if entry is None else [(c, *t) for c, t in zip(entry["coef"], _inputs(pred, entry["features"]))]
    return (None if entry is None else entry["bias"]), terms, (None if knots is None else (knots["x"], knots["y"]))


def _apply(compiled, p: float, x: dict | None) -> float:
    """The maps ``compiled`` (:func:`_compile`; None: none) applied to raw probability ``p`` and measurements ``x``."""
    if compiled is None or not p > 0.0 or not math.isfinite(p):
        return p
    bias, terms, knots = compiled
    if terms is not None:
        x = x or {}
        s = slope = 0.0
        for c, on_p, n, scale in terms:
            v = c * (1.0 if n is None else scale(float(x.get(n, 0.0))))
            if on_p:
                slope += v
            else:
                s += v
        z = bias + s + max(slope, 0.0) * logit(p)
        p = 1.0 / (1.0 + math.exp(-max(min(z, 50.0), -50.0)))
    return p if knots is None else _interp(knots, p)


def _interp(knots: tuple, c: float) -> float:
    """Piecewise-linear non-decreasing map through the knots (xs non-decreasing: a repeated x is a step,
    taken from the right; ys non-decreasing), constant beyond the ends."""
    xs, ys = knots
    i = bisect.bisect_right(xs, c)  # xs[i - 1] <= c < xs[i]
    if i == 0:
        return ys[0]
    if i == len(xs):
        return ys[i - 1]
    return ys[i - 1] + (ys[i] - ys[i - 1]) * (c - xs[i - 1]) / (xs[i] - xs[i - 1])
