"""render_scene: depth, face mask and ground truth agree with each other."""

import cv2
import numpy as np
import pytest

from lv3d.errors import InputError
from lv3d.plane import Plane
from lv3d.render import CLASSES, PRESETS, render_scene
from lv3d.render.truth import rasterise_polygon, surface_distance

W, H = 320, 240


def _face_points(frame, faces, face_id):
    v, u = np.nonzero((faces == face_id + 1) & (frame.depth > 0))
    z = frame.depth[v, u].astype(np.float64)
    k = frame.intrinsics
    return np.stack([(u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z], axis=1)


@pytest.mark.parametrize("cls", CLASSES)
def test_clean_depth_of_every_visible_face_lies_on_its_plane(cls):
    for seed in (0, 1):
        frame, faces = render_scene(cls, seed, "clean", W, H)
        truth = frame.meta["truth"]
        assert truth["faces"], f"{cls} seed {seed}: no visible face"
        for f in truth["faces"]:
            pts = _face_points(frame, faces, f["id"])
            if "surface" in f:  # the curved solids: every face's exact surface
                res = surface_distance(f["surface"], pts)
            else:
                res = np.abs(Plane.from_dict(f["plane"]).distance(pts))
            assert len(pts) == f["pixels"]
            assert np.median(res) < 0.001, (cls, seed, f["id"], np.median(res))


def _polygon_iou(poly, mask):
    if len(poly) > 12:  # a curved solid's outline, sampled along its curves (not always convex)
        a = np.zeros(mask.shape, np.uint8)
        cv2.fillPoly(a, [np.round(np.asarray(poly) * 16).astype(np.int32)], 1, cv2.LINE_8, shift=4)
        a = a.astype(bool)
    else:
        a = rasterise_polygon(poly, mask.shape)
    b = mask
    return (a & b).sum() / max((a | b).sum(), 1)


@pytest.mark.parametrize("cls", CLASSES)
def test_gt_polygons_agree_with_the_face_mask(cls):
    checked = 0
    for seed in range(3):
        frame, faces = render_scene(cls, seed, "clean", W, H)
        for f in frame.meta["truth"]["faces"]:
            poly = np.asarray(f["polygon"])
            # faces bounded by curves (sides 0) have outlines sampled along them
            assert poly.shape == (f["sides"], 2) if f["sides"] else (poly.shape[0] >= 16 and poly.shape[1] == 2)
            area = 0.5 * np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
            assert area > 0, "polygons are clockwise on screen"
            if f["visible_fraction"] > 0.95 and f["pixels"] >= 150:
                assert _polygon_iou(poly, faces == f["id"] + 1) >= 0.9, (cls, seed, f["id"])
                checked += 1
    assert checked >= 2


# (fewest, most) visible faces and the side counts a face of the class may have
EXPECTED = {"cube": (1, 3, {4}), "cuboid": (1, 3, {4}), "square_pyramid": (1, 4, {3, 4}),
            "triangular_prism": (1, 4, {3, 4}), "pentagonal_prism": (1, 4, {4, 5}),
            "hexagonal_prism": (1, 4, {4, 6}), "tetrahedron": (1, 3, {3}),
            "cylinder": (1, 2, {0}), "cone": (1, 2, {0}), "sphere": (1, 1, {0})}


@pytest.mark.parametrize("cls", CLASSES)
def test_visible_face_counts_and_sides_are_plausible(cls):
    lo, hi, sides = EXPECTED[cls]
    for seed in range(4):
        frame, _ = render_scene(cls, 100 + seed, "clean", 160, 120)
        faces = frame.meta["truth"]["faces"]
        assert lo <= len(faces) <= hi, (cls, seed, len(faces))
        assert {f["sides"] for f in faces} <= sides


def test_dihedral_angles_of_adjacent_faces():
    angles = {"cube": {90.0}, "tetrahedron": {70.5288}, "hexagonal_prism": {90.0, 120.0}}
    for cls, want in angles.items():
        seen = set()
        for seed in range(3):
            frame, _ = render_scene(cls, seed, "clean", W, H)
            seen |= {round(a["dihedral_deg"], 3) for a in frame.meta["truth"]["adjacency"]}
        assert seen and seen <= {round(x, 3) for x in want}, (cls, seen)


def test_support_plane_holds_the_object():
    for seed in range(3):
        frame, _ = render_scene("cube", seed, "clean", 160, 120)
        t = frame.meta["truth"]
        plane = Plane.from_dict(t["support_plane"])
        centre = np.asarray(t["object_to_camera"])[:3, 3]
        assert plane.offset > 0
        assert plane.distance(centre[None])[0] == pytest.approx(t["size_m"]["edge"] / 2, abs=1e-6)


def test_same_seed_same_frame_and_presets_share_the_scene():
    a, fa = render_scene("hexagonal_prism", 7, "realsense", 160, 120)
    b, fb = render_scene("hexagonal_prism", 7, "realsense", 160, 120)
    assert np.array_equal(a.color, b.color) and np.array_equal(a.depth, b.depth) and np.array_equal(fa, fb)
    assert a.meta == b.meta
    c, _ = render_scene("hexagonal_prism", 7, "clean", 160, 120)
    assert c.meta["truth"]["object_to_camera"] == a.meta["truth"]["object_to_camera"]
    d, _ = render_scene("hexagonal_prism", 8, "realsense", 160, 120)
    assert not np.array_equal(a.color, d.color)


def test_outputs_have_the_documented_types():
    frame, faces = render_scene("cube", 0, "clean", 160, 120, scene_id="s000042")
    assert frame.color.shape == (120, 160, 3) and frame.color.dtype == np.uint8
    assert frame.depth.dtype == np.float32 and faces.dtype == np.uint8 and faces.shape == (120, 160)
    assert np.all(np.round(frame.depth * 1000) == frame.depth * np.float32(1000)) or \
        np.allclose(frame.depth * 1000, np.round(frame.depth * 1000), atol=1e-3)  # whole millimetres
    assert frame.meta["id"] == "s000042" and frame.name == "s000042"
    assert frame.meta["noise"]["preset"] == "clean" and frame.intrinsics.fx == pytest.approx(615 / 4)
    assert frame.meta["truth"]["class"] == "cube" and frame.meta["truth"]["occluder"] is None


def test_bad_inputs_raise_input_error():
    with pytest.raises(InputError, match="unknown class 'dodecahedron'"):
        render_scene("dodecahedron", 0)
    with pytest.raises(InputError, match="unknown noise preset 'foggy'"):
        render_scene("cube", 0, "foggy")
    with pytest.raises(InputError, match="seed"):
        render_scene("cube", -1)
    with pytest.raises(InputError, match="image size"):
        render_scene("cube", 0, "clean", 4, 4)
    assert set(PRESETS) == {"clean", "mild", "realsense", "hard", "realistic", "kinect"}
