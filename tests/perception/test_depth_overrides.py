"""Depth settings other than the defaults from ``{key: value}`` (lv3d.perception.depth.with_overrides), as the
benchmarks and the studies give them, and the facts of a frame perceived with them (lv3d.pipeline.scene_facts)."""

import pytest

from lv3d.perception.depth import DEFAULT, with_overrides
from lv3d.pipeline import scene_facts
from lv3d.render import noise_config, render_scene


def test_each_key_sets_its_field_and_nothing_else():
    assert with_overrides({}) is DEFAULT
    s = with_overrides({"sensor.base_m": 0.006, "quadrics.max_step_deg": 65, "stride": 2})
    assert (s.sensor.base_m, s.quadrics.max_step_deg, s.stride) == (0.006, 65, 2)
    assert s.sensor.per_m2 == DEFAULT.sensor.per_m2 and s.curved == DEFAULT.curved and s.holes == DEFAULT.holes
    again = with_overrides({"sensor.per_m2": 0.01}, s)  # on top of other settings
    assert (again.sensor.base_m, again.sensor.per_m2, again.stride) == (0.006, 0.01, 2)


@pytest.mark.parametrize("overrides, says", [
    ({"nope": 1}, "nope: unknown setting 'nope'; known here: stride"),
    ({"sensor.nope": 1.0}, "sensor.nope: unknown setting 'nope'; known here: base_m"),
    ({"stride.x": 1}, "stride.x: 'stride' is no part of the depth settings"),
    ({"stride": 1.5}, "stride: must be of type int"),
    ({"sensor.base_m": "big"}, "sensor.base_m: must be of type float"),
    ({"max_border": 1.5}, "max_border: max_border is a fraction"),
    ({"sensor.min_m": 0.5}, "sensor.min_m: min_m (0.5) must not exceed max_m")])
def test_a_bad_override_is_refused_naming_its_key(overrides, says):
    with pytest.raises(ValueError) as e:
        with_overrides(overrides)
    assert str(e.value).startswith(says)


def test_the_facts_of_a_frame_follow_the_depth_settings():
    frame = render_scene("cube", 0, noise_config("clean", stacked=1.0))[0]  # a box on a box: two objects

    def objects(facts):
        return {f.args[0] for f in facts.facts if f.pred == "face_of"}

    assert len(objects(scene_facts(frame, "s000000", "depth", refine=False))) == 2
    assert len(objects(scene_facts(frame, "s000000", "depth", refine=False, depth={"max_objects": 1}))) == 1
    with pytest.raises(ValueError, match="nope"):
        scene_facts(frame, "s000000", "depth", depth={"nope": 1})
