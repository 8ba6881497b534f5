"""Camera frames larger than perception's working size are read at a whole fraction of it (lv3d.rgbd.to_working):
depth by taking every s-th reading, colour low-passed and taken at the same pixels, intrinsics, labelled pixels and
label images to match."""

import json

import cv2
import numpy as np
import pytest

from lv3d.camera import Intrinsics
from lv3d.frame_folder import FrameFolder
from lv3d.object_facts import frame_facts
from lv3d.rgbd import RGBD, WORK_SIDE_PX, to_working, working_factor


@pytest.mark.parametrize("size, factor", [((640, 480), 1), ((848, 480), 1), ((320, 240), 1), ((1280, 720), 2),
                                          ((1280, 960), 2), ((1920, 1080), 3), ((480, 1280), 2)])
def test_the_factor_brings_the_longer_side_nearest_the_working_size(size, factor):
    assert WORK_SIDE_PX == 640
    assert working_factor(*size) == factor


def test_a_large_frame_keeps_every_second_reading_and_its_registration():
    h, w = 960, 1280
    depth = np.full((h, w), 1.0, np.float32)
    depth[:, 601:] = 2.0                 # a depth edge between file columns 600 and 601
    depth[10, 10] = 0.0                  # a missing reading stays missing, never made up from its neighbours
    color = np.zeros((h, w, 3), np.uint8)
    color[:, 600:] = 255                 # a colour edge at the same place
    k = Intrinsics(1000.0, 1000.0, 640.0, 480.0, w, h)
    small = to_working(RGBD(color, depth, k, "big"))
    assert small.scale == 2 and small.depth.shape == (480, 640) and small.color.shape == (480, 640, 3)
    np.testing.assert_array_equal(small.depth, depth[::2, ::2])
    assert small.depth[5, 5] == 0.0
    assert small.intrinsics == Intrinsics(500.0, 500.0, 320.0, 240.0, 640, 480)
    # the colour edge stays where the depth edge is: between columns 299 and 301 of the smaller frame
    row = small.color[100, :, 0].astype(int)
    assert row[298] < 20 and row[301] > 235 and 20 <= row[300] <= 235
    assert small.depth[100, 300] == 1.0 and small.depth[100, 301] == 2.0
    # a point seen at a pixel of the file is seen at the matching pixel of the smaller frame
    x, y, z = 0.1, -0.05, 1.0
    u, v = k.fx * x / z + k.cx, k.fy * y / z + k.cy
    s = small.intrinsics
    assert (s.fx * x / z + s.cx, s.fy * y / z + s.cy) == pytest.approx((u / 2, v / 2))


def test_a_frame_of_the_working_size_is_read_as_it_is():
    f = RGBD(np.zeros((480, 640, 3), np.uint8), np.ones((480, 640), np.float32),
             Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480))
    assert to_working(f) is f and f.scale == 1


def _write(folder, frame, mask, u, v, factor):
    """``frame`` and its labelled target written in the real layout, every pixel repeated ``factor`` times each way,
    with intrinsics such that every factor-th pixel is the original frame's."""
    folder.mkdir()
    rep = (lambda a: np.repeat(np.repeat(a, factor, axis=0), factor, axis=1))
    cv2.imwrite(str(folder / "f-1_rgb.png"), cv2.cvtColor(rep(frame.color), cv2.COLOR_RGB2BGR))
    cv2.imwrite(str(folder / "f-1_depth_mm.png"), rep(np.round(frame.depth * 1000).astype(np.uint16)))
    cv2.imwrite(str(folder / "f-1_label.png"), rep(mask.astype(np.uint16)))
    k = frame.intrinsics
    (folder / "intrinsics.json").write_text(json.dumps(
        {"width": k.width * factor, "height": k.height * factor,
         "frames": {"f-1": {"fx": k.fx * factor, "fy": k.fy * factor, "cx": k.cx * factor, "cy": k.cy * factor}}}))
    (folder / "objects.csv").write_text(f"frame,object,u,v,shape\nf-1,1,{u * factor},{v * factor},box\n")
    return FrameFolder(folder)


def test_a_frame_twice_the_size_reads_as_the_frame_and_gives_its_depth_facts(tmp_path):
    from lv3d.render.frame import render_scene

    frame, faces = render_scene("cube", 5, "realsense")
    v, u = np.nonzero(faces)
    i = int(np.argmin(np.hypot(u - u.mean(), v - v.mean())))
    mask = (faces > 0).astype(np.uint16)
    one = _write(tmp_path / "one", frame, mask, int(u[i]), int(v[i]), 1)
    two = _write(tmp_path / "two", frame, mask, int(u[i]), int(v[i]), 2)
    a, b = one.load("f-1"), two.load("f-1")
    assert (a.scale, b.scale) == (1, 2)
    np.testing.assert_array_equal(a.depth, b.depth)
    assert a.intrinsics == b.intrinsics
    lab_a, lab_b = one.labels()["f-1"][0], two.labels()["f-1"][0]
    assert (lab_b.u, lab_b.v) == (lab_a.u, lab_a.v) and lab_b.file_uv == (2 * lab_a.u, 2 * lab_a.v)
    assert lab_b.pixel == f"({2 * lab_a.u}, {2 * lab_a.v})"
    np.testing.assert_array_equal(one.label_image("f-1", a.shape), two.label_image("f-1", b.shape))
    labels = [(1, lab_a.u, lab_a.v)]
    fa = frame_facts(a, "f_1", "depth", labels).to_json()
    fb = frame_facts(b, "f_1", "depth", labels).to_json()
    assert fa["under"] == fb["under"] and fa["under"]["1"] is not None
    assert fa == fb
