"""The appearance, scene and sensor knobs of the realistic presets do what docs/dataset.md says, and the
ground truth stays exact under them."""

import cv2
import numpy as np
import pytest

from lv3d.camera import Intrinsics
from lv3d.errors import InputError
from lv3d.plane import Plane
from lv3d.render import PRESETS, noise_config, render_scene
from lv3d.render.noise import DEPTH_MODELS, EDGE_JUMP_M, quantise_disparity, sensor_shadow
from lv3d.render.sampler import _moved, overlaps, sample_layout

W, H = 320, 240


def _edge_far_side(depth: np.ndarray, reach: int) -> np.ndarray:
    """Pixels with a surface nearer by more than EDGE_JUMP_M within ``reach`` pixels."""
    zz = np.where(depth > 0, depth, np.float32(1e3))
    near = cv2.erode(zz, np.ones((2 * reach + 1, 2 * reach + 1), np.uint8))
    return (depth > 0) & (depth - near > EDGE_JUMP_M)


def test_new_knobs_are_off_in_the_old_presets_and_on_in_the_new():
    new = ("printed_faces", "face_hues", "touching", "stacked", "small_table", "edge_dropout_px")
    for p in ("clean", "mild", "realsense", "hard"):
        cfg = noise_config(p)
        assert all(getattr(cfg, k) == 0 for k in new) and cfg.depth_model == "ideal"
    real = noise_config("realistic")
    assert all(getattr(real, k) > 0 for k in new) and real.depth_model == "realsense"
    assert noise_config("kinect").depth_model == "kinect" and noise_config("kinect").printed_faces > 0
    assert {"realistic", "kinect"} <= set(PRESETS)
    with pytest.raises(InputError, match="knob 'depth_model' takes one of ideal, kinect, realsense"):
        noise_config("clean", depth_model="lidar")
    with pytest.raises(InputError, match="knob 'depth_model' takes one of"):
        noise_config("clean", depth_model=1)


def test_appearance_knobs_leave_depth_and_truth_alone_and_depth_knobs_leave_colour_alone():
    base, base_faces = render_scene("cuboid", 3, "realsense", 160, 120)
    painted, painted_faces = render_scene("cuboid", 3, noise_config("realsense", printed_faces=1.0, face_hues=1.0),
                                          160, 120)
    assert np.array_equal(base.depth, painted.depth) and np.array_equal(base_faces, painted_faces)
    assert base.meta["truth"] == painted.meta["truth"]
    assert not np.array_equal(base.color, painted.color)
    sensed, _ = render_scene("cuboid", 3, noise_config("realsense", depth_model="kinect", edge_dropout_px=2.0),
                             160, 120)
    assert np.array_equal(base.color, sensed.color) and not np.array_equal(base.depth, sensed.depth)


def test_kinect_shadow_lies_left_of_nearer_surfaces_and_never_inside_a_face():
    k = Intrinsics.realsense_d435(W, H)
    seen = 0
    for seed in range(3):
        ideal, faces = render_scene("cube", seed, "clean", W, H)
        frame, _ = render_scene("cube", seed, noise_config("clean", depth_model="kinect"), W, H)
        lost = (frame.depth == 0) & (ideal.depth > 0)
        seen += lost.sum()
        # each lost pixel has a nearer pixel to its right, no farther than the disparity step between them
        fb = k.fx * DEPTH_MODELS["kinect"].baseline_m
        for v, u in zip(*np.nonzero(lost)):
            z = ideal.depth[v, u]
            right = ideal.depth[v, u + 1:]
            gap = (np.arange(1, len(right) + 1) - fb * (1 / np.maximum(right, 1e-6) - 1 / z))
            assert np.any((right < z - 0.005) & (gap <= 0.5)), (seed, v, u)
        # nothing lost inside the target's faces away from their outline
        inner = cv2.erode((faces > 0).astype(np.uint8), np.ones((7, 7), np.uint8)) > 0
        assert not (lost & inner).any()
        # where it reads, it reads the ideal depth up to the disparity quantisation (and whole millimetres)
        ok = frame.depth > 0
        step = ideal.depth[ok] ** 2 / (615.0 * 0.075) / 8
        assert np.all(np.abs(frame.depth[ok] - ideal.depth[ok]) <= step / 2 + 0.0011)  # both whole mm
    assert seen > 30


def test_sensor_shadow_band_is_as_wide_as_the_disparity_step():
    depth = np.full((4, 100), 2.0, np.float32)
    depth[:, 50:70] = 1.0  # a near slab in front of a far wall
    lost = sensor_shadow(depth, 600.0, 0.075)
    width = 600.0 * 0.075 * (1 / 1.0 - 1 / 2.0)  # 22.5 pixels
    cols = np.flatnonzero(lost[0])
    assert cols.max() == 49 and abs(len(cols) - width) <= 1  # left of the slab, on the far surface
    assert np.array_equal(lost[0], lost[3])


def test_edge_dropout_is_a_band_on_the_far_side_of_depth_edges():
    for seed in range(3):
        ideal, faces = render_scene("hexagonal_prism", seed, "clean", W, H)
        frame, _ = render_scene("hexagonal_prism", seed, noise_config("clean", edge_dropout_px=3.0), W, H)
        lost = (frame.depth == 0) & (ideal.depth > 0)
        assert lost.sum() > 20
        reach = int(np.ceil(1.5 * 3.0 * W / 640))
        assert not (lost & ~_edge_far_side(ideal.depth, reach)).any()
        assert not (lost & (faces > 0)).any()  # the target is the near side of its outline here


def test_disparity_quantisation_step_grows_with_z_squared():
    model = DEPTH_MODELS["kinect"]
    z = np.linspace(0.5, 2.5, 20001, dtype=np.float32)[None, :]
    q = quantise_disparity(z, 615.0, model)[0]
    levels = np.unique(q)
    for z0 in (0.7, 1.0, 1.5, 2.2):
        i = np.searchsorted(levels, z0)
        step = levels[i + 1] - levels[i]
        want = z0 ** 2 * model.disparity_step_px / (615.0 * model.baseline_m)
        assert step == pytest.approx(want, rel=0.02), z0
    near = np.diff(levels[(levels > 0.6) & (levels < 0.7)]).mean()
    far = np.diff(levels[(levels > 1.8) & (levels < 2.0)]).mean()
    assert far / near == pytest.approx((1.9 / 0.65) ** 2, rel=0.1)


def test_face_hues_give_faces_of_different_hue():
    spreads = {}
    for hues in (0.0, 1.0):
        out = []
        for seed in range(3):
            frame, faces = render_scene("cube", seed, noise_config("clean", face_hues=hues), W, H)
            hsv = cv2.cvtColor(frame.color, cv2.COLOR_RGB2HSV_FULL)
            hue = [np.median(hsv[..., 0][faces == f["id"] + 1]) for f in frame.meta["truth"]["faces"]
                   if f["pixels"] > 200]
            if len(hue) >= 2:
                d = np.abs(np.subtract.outer(hue, hue))
                out.append(np.minimum(d, 256 - d).max())
        spreads[hues] = max(out)
    assert spreads[0.0] <= 8 and spreads[1.0] >= 25


def test_printed_faces_add_edges_inside_faces_but_no_faces():
    more = 0
    for seed in range(3):
        plain, faces = render_scene("cuboid", seed, "clean", W, H)
        printed, faces_p = render_scene("cuboid", seed, noise_config("clean", printed_faces=1.0), W, H)
        assert np.array_equal(faces, faces_p) and plain.meta["truth"] == printed.meta["truth"]
        inner = np.zeros(faces.shape, bool)  # inside the target's faces, 2 pixels clear of their outlines
        for f in plain.meta["truth"]["faces"]:
            inner |= cv2.erode(np.uint8(faces == f["id"] + 1), np.ones((5, 5), np.uint8)) > 0
        edges = [(cv2.Canny(cv2.cvtColor(im.color, cv2.COLOR_RGB2GRAY), 40, 100) > 0) & inner
                 for im in (plain, printed)]
        more += edges[1].sum() > edges[0].sum() + 20
    assert more >= 2


def test_stacked_boxes_one_above_the_other_with_exact_support():
    relations = set()
    for seed in range(12):
        frame, _ = render_scene("cube", seed, noise_config("clean", stacked=1.0), W, H)
        t = frame.meta["truth"]
        (c,) = t["contacts"]
        relations.add(c["relation"])
        assert c["class"] == "cuboid" and set(c["size_m"]) == {"x", "y", "z"}
        support, table = Plane.from_dict(t["support_plane"]), Plane.from_dict(t["table_plane"])
        up = np.asarray(t["table_plane"]["normal"])
        mine = np.asarray(t["object_to_camera"])[:3, 3]
        box = np.asarray(c["object_to_camera"])[:3, 3]
        edge = t["size_m"]["edge"]
        # the cube's centre sits half an edge above the surface it stands on
        assert support.distance(mine[None])[0] == pytest.approx(edge / 2, abs=1e-6)
        if c["relation"] == "under_target":
            assert (mine - box) @ up == pytest.approx(edge / 2 + c["size_m"]["z"] / 2, abs=1e-6)
            assert support.offset - table.offset == pytest.approx(-c["size_m"]["z"], abs=1e-6)
        else:
            assert (box - mine) @ up == pytest.approx(edge / 2 + c["size_m"]["z"] / 2, abs=1e-6)
            assert t["support_plane"] == t["table_plane"]
        assert c["faces"] and all(f["pixels"] >= 50 for f in c["faces"])
        if {"on_target", "under_target"} <= relations:
            break
    assert relations == {"on_target", "under_target"}


def test_touching_solid_touches_and_never_overlaps():
    k = Intrinsics.realsense_d435(W, H)
    cfg = noise_config("clean", touching=1.0, stacked=0.5)
    for seed in range(6):
        rng, extra = np.random.default_rng(seed), np.random.default_rng(seed + 100)
        layout = sample_layout("cuboid", cfg, k, rng, extra)
        beside = [c.placed for c in layout.contacts if c.relation == "beside"]
        stack = [layout.target] + [c.placed for c in layout.contacts if c.relation != "beside"]
        assert len(beside) == 1
        (b,) = beside
        assert not any(overlaps(b, s) for s in stack)
        towards = layout.target.centre_xy() - b.centre_xy()
        shift = np.array([*(towards / np.linalg.norm(towards)), 0.0]) * 2e-5
        assert any(overlaps(_moved(b, shift), s) for s in stack)  # 20 micrometres closer: inside
        assert b.world_vertices()[:, 2].min() == pytest.approx(0.0, abs=1e-9)  # on the table


def test_small_table_shows_the_floor_beyond_its_edge():
    floor_seen = 0
    for seed in range(4):
        frame, _ = render_scene("cube", seed, noise_config("clean", small_table=1.0), W, H)
        k = frame.intrinsics
        v, u = np.nonzero(frame.depth > 0)
        z = frame.depth[v, u]
        pts = np.stack([(u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z], axis=1)
        below = -Plane.from_dict(frame.meta["truth"]["table_plane"]).distance(pts)
        floor_seen += np.mean(np.abs(below - 0.75) < 0.01) > 0.05  # the floor 0.75 m below the table top
    assert floor_seen >= 3


def test_realistic_and_kinect_presets_render_with_exact_truth():
    for preset in ("realistic", "kinect"):
        for seed, cls in enumerate(("cube", "pentagonal_prism", "tetrahedron")):
            frame, faces = render_scene(cls, seed, preset, 160, 120)
            t = frame.meta["truth"]
            assert t["class"] == cls and frame.meta["noise"]["preset"] == preset
            assert {f["id"] for f in t["faces"]} <= set(np.unique(faces) - 1)
            for c in t["contacts"]:
                assert c["relation"] in ("beside", "on_target", "under_target")


def test_docs_knob_table_lists_every_knob_of_every_preset():
    from dataclasses import fields
    from pathlib import Path

    from lv3d.render import NoiseConfig

    text = (Path(__file__).resolve().parents[2] / "docs" / "dataset.md").read_text()
    lines = text[text.index("| knob | clean |"):].split("\n")
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    presets = head[1:-1]
    assert presets == list(PRESETS)
    rows = {}
    for line in lines[2:]:
        if not line.startswith("| `"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        rows[cells[0].strip("`")] = cells[1:-1]
    assert set(rows) == {f.name for f in fields(NoiseConfig)} - {"preset"}
    for knob, values in rows.items():
        for preset, shown in zip(presets, values):
            assert shown == str(getattr(noise_config(preset), knob)), (knob, preset, shown)


def test_dataset_make_with_the_realistic_preset(tmp_path):
    import json

    from lv3d.cli import main
    from lv3d.rgbd import load_item

    out = tmp_path / "real"
    assert main(["dataset", "make", "--classes", "cube,tetrahedron", "--per-class", "1", "--noise", "realistic",
                 "--out", str(out), "--workers", "1", "--width", "160", "--height", "120"]) == 0
    m = json.loads((out / "manifest.json").read_text())
    assert m["noise"] == "realistic" and m["noise_knobs"]["depth_model"] == "realsense"
    frame = load_item(out / m["items"][0]["dir"])
    assert frame.meta["truth"]["class"] == "cube" and "contacts" in frame.meta["truth"]
