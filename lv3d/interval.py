"""The probability that a measured quantity lies below a bound or between two, its error Gaussian: how the facts
read from a measurement and its spread (grounding's Laplace spread with its model-error floor) turn into
confidences when no calibration map is fitted for them."""

from __future__ import annotations

import math


def probability_below(x: float, mean: float, sd: float) -> float:
    """P(X < x) for X ~ N(mean, sd^2); sd > 0."""
    return 0.5 * (1.0 + math.erf((x - mean) / (sd * math.sqrt(2.0))))


def probability_between(lo: float, hi: float, mean: float, sd: float) -> float:
    """P(lo < X < hi) for X ~ N(mean, sd^2); sd > 0, lo <= hi."""
    z = sd * math.sqrt(2.0)
    return 0.5 * (math.erf((hi - mean) / z) - math.erf((lo - mean) / z))
