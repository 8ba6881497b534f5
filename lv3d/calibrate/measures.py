"""Expected calibration error of fact confidences, the level sampling alone produces, its spread over scenes,
and the log loss: the measures the fit (lv3d.calibrate.fit), the check (lv3d.calibrate.check) and
benchmarks/bench_grounding.py print."""

from __future__ import annotations

import numpy as np

from ..experiment.stats import ece, reliability_bins  # noqa: F401  (the calibration's ECE is the studies')

ECE_TARGET = 0.05  # issue 4: per fact type, at the realsense preset


def ece_verdict(e: float) -> str:
    """The target beside a fact type's ECE ``e``: "(target <= 0.05: ok)" or "... MISS", as the benchmarks say it."""
    return f"(target <= {ECE_TARGET}: {'ok' if e <= ECE_TARGET else 'MISS'})"


def log_loss(p: np.ndarray, y: np.ndarray) -> float:
    """Mean log loss of confidences ``p`` (n,) against truth ``y`` (n,), confidences clipped to [1e-6, 1 - 1e-6]."""
    p = np.clip(np.asarray(p, float), 1e-6, 1 - 1e-6)
    y = np.asarray(y, float)
    return float(-np.mean(y * np.log(p) + (1 - y) * np.log(1 - p)))


def chance_ece(p: np.ndarray, bins: int = 10, draws: int = 400, seed: int = 0) -> float:
    """The ECE a perfectly calibrated fact type with these confidences shows on average by sampling alone
    (labels drawn from the confidences): an ECE near it cannot be told from perfect calibration on this
    many facts."""
    p = np.asarray(p, float)
    if len(p) == 0:
        return float("nan")
    rng = np.random.default_rng(seed)
    return float(np.mean([ece(p, rng.random(len(p)) < p, bins) for _ in range(draws)]))


def scene_interval(p: np.ndarray, y: np.ndarray, scenes: np.ndarray, bins: int = 10, level: float = 0.95,
                   draws: int = 1000, seed: int = 0) -> tuple[float, float]:
    """Percentile interval of :func:`ece` over sets of facts made by drawing whole scenes with replacement
    (``scenes`` (n,): the scene of each fact). A scene's facts share its view and its perception errors, so they
    are not independent draws: this interval, unlike :func:`chance_ece`, carries that. An interval wholly above a
    target says the type misses it on scenes like these, not only on this sample."""
    p, y, scenes = np.asarray(p, float), np.asarray(y, float), np.asarray(scenes)
    if len(p) == 0:
        return float("nan"), float("nan")
    ids, idx = np.unique(scenes, return_inverse=True)
    members = [np.flatnonzero(idx == k) for k in range(len(ids))]
    rng = np.random.default_rng(seed)
    vals = []
    for _ in range(draws):
        take = np.concatenate([members[k] for k in rng.integers(0, len(ids), len(ids))])
        vals.append(ece(p[take], y[take], bins))
    lo, hi = np.quantile(vals, [(1 - level) / 2, (1 + level) / 2])
    return float(lo), float(hi)
