"""Calibration of fact probabilities against ground truth, per modality and predicate.

The Gaussian probability of a predicate (``_confidence``) speaks only of the errors the residuals can
see. End to end, perception also makes gross errors the Laplace covariance cannot know of: a spurious
corner on a long side (a pentagon that is a quadrilateral), a face split in two, a plane fitted across
an edge. A per-(modality, predicate) logistic map turns the raw probability ``p`` and a few measurements
of the faces behind it into a calibrated one:

    conf = sigmoid(bias + sum_k coef_k x_k),  x = (logit p, measurements named in the table)

The maps are fitted (L2-regularised logistic regression, ``benchmarks/fit_calibration.py``) on perceived
dev scenes (realsense preset, seeds 30000+; never the study's data) and live in
``_calibration_table.py``; a (modality, predicate) pair without a map keeps its raw probability.
The map is monotone increasing in ``p`` (its ``logit_p`` coefficient is kept positive), so a more
certain measurement never gets a lower confidence, other things equal.
"""

from __future__ import annotations

import functools
import math

from ._calibration_table import TABLE

P_CLIP = 1e-4  # logit(p) is taken of p clipped to [P_CLIP, 1 - P_CLIP]: saturated probabilities stay finite


def logit(p: float) -> float:
    p = min(max(float(p), P_CLIP), 1.0 - P_CLIP)
    return math.log(p / (1.0 - p))


# measurements on tame scales: a corner's turn in spreads clipped (a 40-spread corner is no surer than a
# 20-spread one), the shortest side as a log; absent measurements (e.g. of `object`) read as 0
_SCALE = {"min_turn_z": lambda v: min(max(v, -5.0), 20.0), "min_side_px": lambda v: math.log(max(v, 1.0))}


def design(p: float, x: dict, names: list[str]) -> list[float]:
    """The inputs of a calibration map: ``logit(p)`` then the named measurements of ``x``."""
    return [logit(p) if n == "logit_p" else _SCALE.get(n, float)(float(x.get(n, 0.0))) for n in names]


def measures_used(modality: str, pred: str) -> list[str]:
    """The face measurements the map of (modality, pred) reads (empty: it needs only p, or there is no map)."""
    entry = TABLE.get(modality, {}).get(pred)
    return [] if entry is None else [n for n in entry["features"] if n != "logit_p"]


def calibrate(modality: str, pred: str, p: float, x: dict | None = None) -> float:
    """Calibrated probability of one candidate fact with raw probability ``p`` and face measurements ``x``
    (keys as ``lv3d.describe.calibration_features`` gives them). ``p`` itself where no map was fitted;
    0 stays 0 (a predicate the geometry rules out is not revived). The same arithmetic as
    :func:`calibrate_with` on ``TABLE``, with each map's inputs looked up once (a frame has ~150 candidates)."""
    entry = _compiled(modality, pred)
    if entry is None or not p > 0.0 or not math.isfinite(p):
        return p
    bias, terms = entry
    x = x or {}
    z = bias + sum(c * (logit(p) if n is None else scale(float(x.get(n, 0.0)))) for c, n, scale in terms)
    return 1.0 / (1.0 + math.exp(-max(min(z, 50.0), -50.0)))


@functools.cache
def _compiled(modality: str, pred: str):
    """(bias, [(coefficient, measurement name or None for logit p, its scale)]) of TABLE's map, or None."""
    entry = TABLE.get(modality, {}).get(pred)
    if entry is None:
        return None
    return entry["bias"], [(c, None if n == "logit_p" else n, _SCALE.get(n, float))
                           for c, n in zip(entry["coef"], entry["features"])]


def calibrate_with(table: dict, modality: str, pred: str, p: float, x: dict | None = None) -> float:
    """:func:`calibrate` with the maps of ``table`` (same layout as ``TABLE``)."""
    entry = table.get(modality, {}).get(pred)
    if entry is None or not p > 0.0 or not math.isfinite(p):
        return p
    z = entry["bias"] + sum(c * v for c, v in zip(entry["coef"], design(p, x or {}, entry["features"])))
    return 1.0 / (1.0 + math.exp(-max(min(z, 50.0), -50.0)))
