"""The ranges the depth stage's settings may take, checked where each settings object is made.

Every threshold of the depth stage is a fraction, an angle, a positive multiple (of a noise, a size, a number of
cells) or a whole count; each settings class (a frozen dataclass) names which of its fields are which and calls
:func:`check_ranges` from ``__post_init__``, so a value out of its range (from code, or from
``bench_real --set``) is one error naming the field, never a wrong result far downstream.
"""

from __future__ import annotations

import math
import numbers


def check_ranges(settings, *, fractions: tuple[str, ...] = (), acute: tuple[str, ...] = (),
                 angles: tuple[str, ...] = (), arcs: tuple[str, ...] = (), positive: tuple[str, ...] = (),
                 counts: dict[str, int] | None = None) -> None:
    """A ValueError naming the first field of ``settings`` outside its range: ``fractions`` within [0, 1];
    ``acute`` angles (degrees between two lines, or from face-on) within [0, 90]; ``angles`` (degrees between two
    directions, a bend) within [0, 180]; ``arcs`` (degrees around an axis) within [0, 360]; ``positive`` finite
    numbers above 0; ``counts`` {field: least} whole numbers (not bool) of at least that."""
    ranges = [(fractions, 0.0, 1.0, "a fraction in [0, 1]"),
              (acute, 0.0, 90.0, "an angle in [0, 90] degrees"),
              (angles, 0.0, 180.0, "an angle in [0, 180] degrees"),
              (arcs, 0.0, 360.0, "an arc in [0, 360] degrees")]
    for names, lo, hi, what in ranges:
        for name in names:
            v = getattr(settings, name)
            if not _number(v) or not lo <= v <= hi:
                raise ValueError(f"{name} is {what}, got {v!r}")
    for name in positive:
        v = getattr(settings, name)
        if not _number(v) or not 0 < v < math.inf:
            raise ValueError(f"{name} is a positive number, got {v!r}")
    for name, least in (counts or {}).items():
        v = getattr(settings, name)
        if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < least:
            raise ValueError(f"{name} must be a whole number of at least {least}, got {v!r}")


def _number(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)
