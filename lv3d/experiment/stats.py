"""Summaries and paired significance tests over folds x classes.

Two systems are compared on the same (fold, class) cells, so the test is paired: the exact sign
test counts cells where one wins (ties dropped; two-sided binomial p), and the Wilcoxon
signed-rank test also weighs by how much (scipy; exact for small n without ties, zero
differences dropped). Both are reported because with 5 folds x 4 classes many cells tie at 100 %.
Beside them, a bootstrap confidence interval of the mean difference (cells resampled with a fixed seed),
which says how far a margin measured on 20 cells can be trusted against a target such as "20 points".
"""

from __future__ import annotations

import math

import numpy as np


def mean_std(values: list[float]) -> tuple[float, float]:
    """Mean and sample standard deviation (ddof=1; 0 for a single value). NaN for no values."""
    v = np.asarray([x for x in values if x is not None and not math.isnan(x)], float)
    if len(v) == 0:
        return float("nan"), float("nan")
    return float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0


def _differences(a: list[float], b: list[float]) -> np.ndarray:
    """a - b, rounded to 12 decimals: accuracies are fractions of a test set, and float subtraction leaves noise
    (0.975 - 0.95 and 1.0 - 0.975 differ in the 17th digit) that would turn ties into wins and split tied ranks."""
    return np.round(np.asarray(a, float) - np.asarray(b, float), 12)


def sign_test(a: list[float], b: list[float]) -> dict:
    """Exact two-sided sign test of paired values: wins of a, wins of b, ties, p."""
    from scipy.stats import binomtest

    d = _differences(a, b)
    wins, losses = int((d > 0).sum()), int((d < 0).sum())
    n = wins + losses
    p = 1.0 if n == 0 else float(binomtest(wins, n, 0.5, alternative="two-sided").pvalue)
    return {"wins": wins, "losses": losses, "ties": int(len(d) - n), "p": p}


def wilcoxon_test(a: list[float], b: list[float]) -> dict:
    """Wilcoxon signed-rank test of paired values (zero differences dropped): statistic, n, p."""
    from scipy.stats import wilcoxon

    d = _differences(a, b)
    nz = d[d != 0]
    if len(nz) == 0:
        return {"n": 0, "statistic": float("nan"), "p": 1.0}
    r = wilcoxon(nz, alternative="two-sided")
    return {"n": int(len(nz)), "statistic": float(r.statistic), "p": float(r.pvalue)}


def mean_diff_ci(a: list[float], b: list[float], level: float = 0.95, resamples: int = 10000,
                 seed: int = 0) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of a - b at ``level`` (the cells resampled with replacement,
    ``resamples`` times, seeded). NaNs for fewer than two cells."""
    from scipy.stats import bootstrap

    d = np.asarray(a, float) - np.asarray(b, float)
    if len(d) < 2:
        return float("nan"), float("nan")
    if np.all(d == d[0]):  # every resample has the same mean (scipy warns on such data)
        return float(d[0]), float(d[0])
    r = bootstrap((d,), np.mean, confidence_level=level, n_resamples=resamples, method="percentile",
                  random_state=np.random.default_rng(seed), vectorized=True)
    return float(r.confidence_interval.low), float(r.confidence_interval.high)


def paired(a: list[float], b: list[float]) -> dict:
    """Both tests, the mean difference a - b and its 95 % bootstrap interval."""
    if len(a) != len(b):
        raise ValueError(f"paired test needs equal lengths, got {len(a)} and {len(b)}")
    return {"mean_diff": float(np.mean(np.asarray(a) - np.asarray(b))) if len(a) else float("nan"),
            "ci95": list(mean_diff_ci(a, b)), "sign": sign_test(a, b), "wilcoxon": wilcoxon_test(a, b)}


def reliability_bins(p, y, bins: int = 10) -> list[tuple[float, int, float, float]]:
    """Equal-width confidence bins: (lower edge, answers, mean confidence, share right) of each non-empty one.
    ``p`` (n,) confidences in [0, 1]; ``y`` (n,) right or wrong as 0/1 or bool."""
    p, y = np.asarray(p, float), np.asarray(y, float)
    idx = np.minimum((p * bins).astype(int), bins - 1)
    return [(b / bins, int(np.sum(idx == b)), float(p[idx == b].mean()), float(y[idx == b].mean()))
            for b in range(bins) if np.any(idx == b)]


def ece(p, y, bins: int = 10) -> float:
    """Expected calibration error: sum over the bins of :func:`reliability_bins` of |mean confidence - share
    right| times the share of answers in the bin; nan for no answers."""
    if len(p) == 0:
        return float("nan")
    return float(sum(abs(conf - true) * n / len(p) for _, n, conf, true in reliability_bins(p, y, bins)))
