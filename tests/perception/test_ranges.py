"""Every settings class of the depth stage refuses a value outside its unit's range, naming the field; the
defaults pass."""

import dataclasses

import numpy as np
import pytest

from lv3d.perception.depth.convexity import ConvexitySettings
from lv3d.perception.depth.creases import CreaseSettings
from lv3d.perception.depth.curved import CurvedSettings
from lv3d.perception.depth.holes import HoleSettings, UnreadSettings
from lv3d.perception.depth.occlusion import OcclusionSettings
from lv3d.perception.depth.quadrics import QuadricSettings
from lv3d.perception.depth.ranges import check_ranges
from lv3d.perception.depth.stage import DepthSettings
from lv3d.perception.depth.support import SensorNoise

CLASSES = (ConvexitySettings, CreaseSettings, CurvedSettings, HoleSettings, UnreadSettings, OcclusionSettings, QuadricSettings,
           SensorNoise, DepthSettings)


@dataclasses.dataclass
class _Values:
    f: float = 0.5
    a: float = 45.0
    n: int = 3


def test_each_kind_of_range():
    check_ranges(_Values(), fractions=("f",), acute=("a",), counts={"n": 0})
    cases = [(dict(f=1.5), dict(fractions=("f",)), "f is a fraction"),
             (dict(f=float("nan")), dict(fractions=("f",)), "f is a fraction"),
             (dict(a=120.0), dict(acute=("a",)), "a is an angle in \\[0, 90\\]"),
             (dict(a=-1.0), dict(angles=("a",)), "a is an angle in \\[0, 180\\]"),
             (dict(a=400.0), dict(arcs=("a",)), "a is an arc"),
             (dict(a=0.0), dict(positive=("a",)), "a is a positive number"),
             (dict(a=float("inf")), dict(positive=("a",)), "a is a positive number"),
             (dict(f=True), dict(fractions=("f",)), "f is a fraction"),
             (dict(n=2.0), dict(counts={"n": 0}), "n must be a whole number of at least 0"),
             (dict(n=True), dict(counts={"n": 0}), "n must be a whole number"),
             (dict(n=0), dict(counts={"n": 1}), "n must be a whole number of at least 1")]
    for values, kinds, message in cases:
        with pytest.raises(ValueError, match=message):
            check_ranges(_Values(**values), **kinds)
    check_ranges(_Values(n=np.int64(2), f=np.float32(0.25)), fractions=("f",), counts={"n": 1})


@pytest.mark.parametrize("cls", CLASSES, ids=lambda c: c.__name__)
def test_every_numeric_field_is_checked(cls):
    """A negative value is out of range for every threshold and count of every class, and the error names it."""
    cls()
    for f in dataclasses.fields(cls):
        default = getattr(cls(), f.name)
        if dataclasses.is_dataclass(default):
            continue
        with pytest.raises(ValueError, match=f.name):
            cls(**{f.name: -1 if isinstance(default, int) else -1.0})


def test_related_bounds():
    with pytest.raises(ValueError, match="min_fill must not exceed max_fill"):
        HoleSettings(min_fill=0.9, max_fill=0.8)
    with pytest.raises(ValueError, match="half-angles"):
        QuadricSettings(min_half_angle_deg=40.0, max_half_angle_deg=30.0)
    with pytest.raises(ValueError, match="min_m .* must not exceed max_m"):
        SensorNoise(min_m=0.04, max_m=0.03)
