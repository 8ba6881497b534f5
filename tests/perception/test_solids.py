"""Depth's objects as solids: the support chosen by what stands on it, touching and stacked solids parted (at
valleys of height and at concave creases), a convex solid never cut, and the cap on objects."""

import numpy as np
import pytest

from lv3d.errors import InputError
from lv3d.perception import perceive
from lv3d.perception.depth.objects import _split_by_height
from lv3d.render import CLASSES, noise_config, render_scene


def _scene(cls: str, seed: int, **knobs):
    return render_scene(cls, seed, noise_config("clean", **knobs))[0]


def test_a_convex_solid_is_one_object():
    for cls in CLASSES:
        scene = perceive(_scene(cls, 1001), "depth")
        assert len(scene.objects) == 1, cls


@pytest.mark.parametrize("seed", [0, 2])
def test_a_box_on_a_box_is_two_objects(seed):
    frame = _scene("cube", seed, stacked=1.0)
    assert [c["relation"] for c in frame.meta["truth"]["contacts"]] in (["under_target"], ["on_target"])
    scene = perceive(frame, "depth")
    assert len(scene.objects) == 2
    masks = [o.mask for o in scene.objects]
    assert not np.any(masks[0] & masks[1])


def test_the_support_is_the_small_table_not_the_floor():
    frame = _scene("cube", 0, small_table=1.0)
    truth = frame.meta["truth"]["table_plane"]
    scene = perceive(frame, "depth")
    assert scene.support_plane is not None
    assert abs(scene.support_plane.offset - float(truth["offset"])) < 0.02
    assert float(np.dot(scene.support_plane.n, truth["normal"])) > 0.99


def test_height_valleys_part_two_objects_joined_by_a_ramp():
    h, w = 60, 120
    jj = np.arange(w)[None, :].repeat(h, 0)
    # two bumps 10 cm high joined by a 1 cm ramp of smoothed readings, as one connected piece
    height = 0.1 * np.exp(-((jj - 30) / 12.0) ** 2) + 0.1 * np.exp(-((jj - 90) / 12.0) ** 2) + 0.01
    labels = np.ones((h, w), np.int32)
    n, out, stats = _split_by_height(labels, 2, None, height.astype(np.float32), band_m=0.005, min_points=20)
    assert n == 3 and stats[1:, 4].sum() == h * w
    assert out[30, 20] != out[30, 100] and out[30, 20] > 0 and out[30, 100] > 0
    # one bump: kept whole
    one = 0.1 * np.exp(-((jj - 60) / 20.0) ** 2) + 0.01
    n, out, _ = _split_by_height(labels, 2, None, one.astype(np.float32), band_m=0.005, min_points=20)
    assert n == 2 and np.all(out == 1)


def test_the_object_cap_is_an_option_and_counts_what_it_drops():
    frame = _scene("cube", 0, stacked=1.0)
    scene = perceive(frame, "depth", max_objects=1)
    assert len(scene.objects) == 1 and scene.dropped_objects == 1
    assert scene.to_dict()["dropped_objects"] == 1
    assert perceive(frame, "depth").dropped_objects == 0
    with pytest.raises(InputError, match="max-objects"):
        perceive(frame, "depth", max_objects=0)
    # without the argument, the depth settings' cap
    from dataclasses import replace

    from lv3d.perception.depth import DEFAULT
    assert perceive(frame, "depth", depth_settings=replace(DEFAULT, max_objects=1)).dropped_objects == 1


def test_depth_settings_are_checked_and_hold_at_any_image_size():
    from lv3d.perception.depth import DepthSettings, depth_scene

    with pytest.raises(ValueError, match="max_objects"):
        DepthSettings(max_objects=0)
    with pytest.raises(ValueError, match="max_border"):
        DepthSettings(max_border=1.5)
    with pytest.raises(ValueError, match="stride"):
        DepthSettings(stride=0)
    counts = []
    for w, h in ((320, 240), (640, 480), (960, 720)):
        frame = render_scene("cube", 1, noise_config("clean", touching=1.0), w, h)[0]
        res = depth_scene(frame)
        counts.append((len(res.objects), [len(o.planes) for o in res.objects]))
    assert counts[0] == counts[1] == counts[2]
