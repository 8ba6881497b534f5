"""The depth sensor's noise model (support.SensorNoise) is one setting of the depth stage: its inlier distance is
the documented one, a bad model is refused naming the field, and every fit of the depth stage reads the model the
settings carry, never another."""

import sys
from dataclasses import replace

import pytest

from lv3d.errors import InputError
from lv3d.perception import perceive
from lv3d.perception.depth import DEFAULT
from lv3d.perception.depth.support import SENSOR, SensorNoise


def test_the_inlier_distance_grows_as_the_square_of_depth_within_its_clip():
    assert SensorNoise().inlier_m(0.7) == pytest.approx(0.00596)
    assert SensorNoise().inlier_m(1.0) == pytest.approx(0.008)
    assert SensorNoise().inlier_m(0.1) == 0.005  # near the camera: no tighter than min_m
    assert SensorNoise().inlier_m(4.0) == 0.03  # far away: no looser than max_m
    noisier = SensorNoise(base_m=0.006, per_m2=0.01)
    assert noisier.inlier_m(1.0) == pytest.approx(0.016) and noisier.inlier_m(1.0) > SENSOR.inlier_m(1.0)
    assert DEFAULT.sensor == SENSOR


@pytest.mark.parametrize("values, says", [(dict(min_m=0.02, max_m=0.01), "min_m"),
                                          (dict(base_m=-0.001), "base_m"), (dict(per_m2=float("inf")), "per_m2"),
                                          (dict(min_m=0.0), "min_m"), (dict(base_m=True), "base_m")])
def test_a_bad_model_is_refused_naming_the_field(values, says):
    with pytest.raises(ValueError, match=says):
        SensorNoise(**values)


def test_the_benchmarks_set_it_by_key():
    from benchmarks.bench_real import depth_settings

    settings = depth_settings(["sensor.base_m=0.006", "sensor.per_m2=0.01"])
    assert settings.sensor == SensorNoise(base_m=0.006, per_m2=0.01) and settings.quadrics == DEFAULT.quadrics
    with pytest.raises(InputError, match="sensor.min_m"):
        depth_settings(["sensor.min_m=0.5"])  # above max_m


def test_every_fit_reads_the_settings_model(box_frame, monkeypatch):
    """With a model of the default's values given as the settings' own (another instance), perception finds what
    it finds with the default, and every inlier distance it asks for comes from that instance: the support
    plane, its noise band, the object's planes and the snapping of its polygon sides."""
    frame, _ = box_frame
    plain = perceive(frame, "depth")
    own = SensorNoise()
    asked = []
    inlier_m = SensorNoise.inlier_m

    def spy(self, z_m):
        asked.append((self, sys._getframe(1).f_code.co_name))
        return inlier_m(self, z_m)

    monkeypatch.setattr(SensorNoise, "inlier_m", spy)
    seen = perceive(frame, "depth", depth_settings=replace(DEFAULT, sensor=own))
    def found(scene):
        return {k: v for k, v in scene.to_dict().items() if k != "timings_ms"}

    assert found(seen) == found(plain)
    assert asked and all(s is own for s, _ in asked)
    assert {"support_plane", "support_band", "object_planes", "depth_scene"} <= {name for _, name in asked}
