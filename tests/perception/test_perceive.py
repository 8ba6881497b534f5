import json
import re

import numpy as np
import pytest

from lv3d.errors import InputError
from lv3d.perception import perceive
from lv3d.rgbd import RGBD


def test_unknown_modality_is_an_input_error(box_frame):
    with pytest.raises(InputError, match="modality"):
        perceive(box_frame[0], "lidar")


def test_depth_without_readings_is_an_input_error(box_frame):
    frame = box_frame[0]
    empty = RGBD(frame.color, np.zeros_like(frame.depth), frame.intrinsics)
    with pytest.raises(InputError, match="no reading"):
        perceive(empty, "depth")
    assert perceive(empty, "rgb").objects  # colour alone still works


@pytest.mark.parametrize("modality", ["rgb", "depth", "rgbd"])
def test_each_modality_finds_the_three_faces_of_the_box(box_frame, modality):
    scene = perceive(box_frame[0], modality, scene_id="s000042")
    target = scene.target()
    assert target is not None and target.id == "s000042_o1"
    assert sorted(f.sides for f in target.faces) == [4, 4, 4]
    assert len(target.adjacency) == 3
    assert all(re.fullmatch(r"s000042_o1_f[1-3]", f.id) for f in target.faces)
    assert len({f.id for f in target.faces}) == 3
    assert all(v >= 0 for v in scene.timings_ms.values()) and scene.timings_ms
    if modality == "rgbd":
        assert all(f.provenance == "rgbd" and f.plane is not None for f in target.faces)
    if modality == "rgb":
        assert scene.support_plane is None and all(f.plane is None for f in target.faces)


def test_rgbd_keeps_colour_faces_where_depth_finds_no_object(box_frame):
    # a flat wall of depth: no object stands on a support, but colour still sees the box's three faces
    frame = box_frame[0]
    wall = RGBD(frame.color, np.full_like(frame.depth, 1.0), frame.intrinsics)
    assert perceive(wall, "depth").objects == []
    target = perceive(wall, "rgbd", scene_id="s000007").target()
    assert target is not None and sorted(f.sides for f in target.faces) == [4, 4, 4]
    assert all(f.provenance == "rgb" and f.plane is None for f in target.faces)


def test_perceive_is_deterministic(box_frame):
    a = perceive(box_frame[0], "rgbd")
    b = perceive(box_frame[0], "rgbd")
    da, db = a.to_dict(), b.to_dict()
    da.pop("timings_ms"), db.pop("timings_ms")
    assert json.dumps(da, default=float) == json.dumps(db, default=float)


def test_a_line_painted_across_a_face_does_not_make_it_two_faces(box_frame):
    import cv2

    frame, normals = box_frame
    ref = perceive(frame, "rgbd").target()
    biggest = max(ref.faces, key=lambda f: len(f.points))
    a, b = biggest.polygon[0], biggest.polygon[2]  # a diagonal of the largest face, drawn in another colour
    color = frame.color.copy()
    cv2.line(color, tuple(int(x) for x in a), tuple(int(x) for x in b), (250, 250, 250), 2)
    painted = perceive(RGBD(color, frame.depth, frame.intrinsics), "rgbd").target()
    assert sorted(f.sides for f in painted.faces) == [4, 4, 4]
    assert all(f.plane is not None for f in painted.faces)


def test_rgbd_has_the_faces_depth_has_and_print_adds_none(box_frame):
    import cv2

    frame, _ = box_frame
    depth = perceive(frame, "depth").target()
    color = frame.color.copy()
    biggest = max(depth.faces, key=lambda f: len(f.points))
    # a printed label of another colour inside the largest face: colour edges of its own, no face
    c = biggest.polygon.mean(axis=0)
    label = (c + 0.4 * (biggest.polygon - c)).astype(np.int32)
    cv2.fillPoly(color, [label], (30, 200, 240))
    for f in (frame, RGBD(color, frame.depth, frame.intrinsics)):
        fused = perceive(f, "rgbd").target()
        assert sorted(map(tuple, (np.round(g.polygon, 3).ravel() for g in fused.faces))) == \
            sorted(map(tuple, (np.round(g.polygon, 3).ravel() for g in depth.faces)))
        assert len(fused.adjacency) == len(depth.adjacency) == 3


@pytest.mark.real
def test_rgbd_keeps_the_faces_of_every_depth_object_on_a_real_frame_cylinders_too():
    from lv3d.rgbd import load_real
    from tests.conftest import REAL_DIR

    osd = REAL_DIR.parent / "osd-learn"
    if not osd.is_dir():
        pytest.skip(f"osd-learn frames not found at {osd}")
    frame = load_real(osd, "learn35")  # cans on a table
    depth, fused = perceive(frame, "depth"), perceive(frame, "rgbd")
    assert len(depth.objects) == len(fused.objects) and any(f.surface == "cylinder" for o in depth.objects
                                                            for f in o.faces)
    for d, r in zip(depth.objects, fused.objects):
        curved = lambda o: sorted(tuple(np.round(f.polygon, 3).ravel()) for f in o.faces  # noqa: E731
                                  if f.surface == "cylinder")
        assert curved(d) == curved(r)
