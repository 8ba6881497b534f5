"""The perception benchmark's --set KNOB=VALUE overrides: typed as the noise knobs are, bad ones named."""

import pytest

from benchmarks.bench_perception import _overrides


def test_overrides_take_each_knob_s_type():
    got = _overrides(["depth_sigma_k=0.008", "clutter=2", "shadows=false"])
    assert got == {"depth_sigma_k": 0.008, "clutter": 2, "shadows": False}
    assert isinstance(got["clutter"], int)


@pytest.mark.parametrize("bad, says", [("foo=1", "unknown noise knob 'foo'"), ("clutter", "expected KNOB=VALUE"),
                                        ("shadows=maybe", "true or false"), ("preset=hard", "unknown noise knob")])
def test_bad_overrides_are_named(bad, says):
    with pytest.raises(ValueError, match=says):
        _overrides([bad])
