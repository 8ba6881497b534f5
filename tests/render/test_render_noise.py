"""Noise presets and knobs: settable one by one, and they do what they say."""

import numpy as np
import pytest

from lv3d.errors import InputError
from lv3d.plane import Plane
from lv3d.render import PRESETS, NoiseConfig, noise_config, render_scene


def test_presets_and_overrides():
    assert noise_config("clean") == NoiseConfig()
    assert noise_config("realsense", clutter=0).clutter == 0
    hard, rs = noise_config("hard"), noise_config("realsense")
    for knob in ("depth_sigma_k", "hole_blobs", "flying_pixels", "color_sigma", "occluder", "clutter"):
        assert getattr(hard, knob) > getattr(rs, knob) > getattr(noise_config("clean"), knob) or knob == "occluder"
    with pytest.raises(InputError, match="unknown noise knob 'fog'"):
        noise_config("mild", fog=1.0)
    with pytest.raises(InputError, match="unknown noise preset 'foggy'"):
        noise_config("foggy")
    assert [noise_config(p).preset for p in PRESETS] == list(PRESETS)


@pytest.mark.parametrize("knob, value, says", [("shadows", "maybe", "true or false"), ("shadows", 1, "true or false"),
                                               ("clutter", 2.5, "a whole number"), ("clutter", True, "a whole number"),
                                               ("depth_sigma_k", "0.008", "a number"), ("blur_px", None, "a number")])
def test_a_knob_takes_only_its_own_type(knob, value, says):
    with pytest.raises(InputError, match=f"knob '{knob}' takes {says}"):
        noise_config("clean", **{knob: value})
    assert noise_config("clean", blur_px=1, clutter=2, shadows=True).blur_px == 1  # a whole number is a number


def test_realsense_depth_noise_is_about_a_d435():
    cfg = noise_config("clean", depth_sigma_base_m=0.001, depth_sigma_k=0.0018)
    ratios = []
    for seed in range(3):
        frame, faces = render_scene("cuboid", seed, cfg, 320, 240)
        for f in frame.meta["truth"]["faces"]:
            v, u = np.nonzero((faces == f["id"] + 1) & (frame.depth > 0))
            if len(u) < 200:
                continue
            z = frame.depth[v, u].astype(np.float64)
            k = frame.intrinsics
            pts = np.stack([(u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z], axis=1)
            res = Plane.from_dict(f["plane"]).distance(pts)
            n = np.asarray(f["plane"]["normal"])
            # residual along the normal of depth noise sigma along the ray: sigma * |n_z|
            sigma = (0.001 + 0.0018 * z ** 2) * abs(n[2])
            ratios.append(np.std(res) / np.mean(sigma))
    assert ratios and 0.7 < np.median(ratios) < 1.4


def test_clutter_and_occluder_knobs():
    frame, faces = render_scene("cube", 3, noise_config("clean", clutter=3, occluder=1.0), 160, 120)
    t = frame.meta["truth"]
    assert 1 <= len(t["clutter"]) <= 3 and t["occluder"] is not None
    target = np.asarray(t["object_to_camera"])[:3, 3]
    for c in t["clutter"]:  # never touching the target: centres well apart on the table
        assert np.linalg.norm(np.asarray(c["object_to_camera"])[:3, 3] - target) > 0.05
    clean, clean_faces = render_scene("cube", 3, "clean", 160, 120)
    assert (faces > 0).sum() <= (clean_faces > 0).sum()  # an occluder can only hide target pixels


def test_holes_and_grazing_remove_depth():
    clean, _ = render_scene("cube", 5, "clean", 160, 120)
    holes, _ = render_scene("cube", 5, noise_config("clean", hole_blobs=10, hole_radius_px=20), 160, 120)
    assert (clean.depth > 0).all()
    assert (holes.depth == 0).sum() > 100
    assert np.array_equal(clean.color, holes.color)  # depth knobs leave colour alone


def test_colour_knobs_change_colour_only():
    clean, _ = render_scene("cube", 5, "clean", 160, 120)
    noisy, _ = render_scene("cube", 5, noise_config("clean", color_sigma=8, jpeg_quality=60, blur_px=1.0), 160, 120)
    assert np.array_equal(clean.depth, noisy.depth)
    diff = np.abs(clean.color.astype(int) - noisy.color.astype(int))
    assert 2 < diff.mean() < 40


def test_gaussian_samples_every_channel_and_is_seeded():
    from lv3d.render.noise import gaussian
    g = gaussian((200, 200, 3), np.random.default_rng(1))
    assert np.allclose(g.reshape(-1, 3).std(axis=0), 1.0, atol=0.02) and abs(g.mean()) < 0.01
    assert np.array_equal(g, gaussian((200, 200, 3), np.random.default_rng(1)))


def test_grazing_angle_knob_drops_oblique_surfaces_only():
    clean, _ = render_scene("cube", 4, "clean", 160, 120)
    graze, _ = render_scene("cube", 4, noise_config("clean", grazing_deg=60.0), 160, 120)
    dropped = (clean.depth > 0) & (graze.depth == 0)
    assert dropped.any() and (graze.depth > 0).any()
    kept = graze.depth > 0
    assert np.array_equal(graze.depth[kept], clean.depth[kept])
