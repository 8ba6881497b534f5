import json

import cv2
import numpy as np
import pytest

from lv3d.camera import Intrinsics
from lv3d.errors import InputError
from lv3d.rgbd import load_frame, load_real, read_intrinsics, real_frame_files


def _write(tmp_path, w=64, h=48, depth=None):
    c = tmp_path / "c.png"
    d = tmp_path / "d.png"
    cv2.imwrite(str(c), np.full((h, w, 3), 128, np.uint8))
    cv2.imwrite(str(d), np.full((h, w), 1000, np.uint16) if depth is None else depth)
    return c, d


def test_loads_png_frame_in_metres(tmp_path):
    c, d = _write(tmp_path)
    f = load_frame(c, d, Intrinsics(60, 60, 32, 24, 64, 48))
    assert f.depth.dtype == np.float32 and np.allclose(f.depth, 1.0)
    pts, pix = f.points()
    assert pts.shape == (64 * 48, 3) and np.allclose(pts[:, 2], 1.0)


def test_bad_inputs_name_the_file(tmp_path):
    k = Intrinsics(60, 60, 32, 24, 64, 48)
    c, d = _write(tmp_path)
    with pytest.raises(InputError, match="not found"):
        load_frame(tmp_path / "nope.png", d, k)
    (tmp_path / "bad.png").write_bytes(b"not a png")
    with pytest.raises(InputError, match="bad.png.*corrupt"):
        load_frame(tmp_path / "bad.png", d, k)
    with pytest.raises(InputError, match="all zero"):
        _, dz = _write(tmp_path, depth=np.zeros((48, 64), np.uint16))
        load_frame(c, dz, k)
    with pytest.raises(InputError, match="depth is 32x48 but colour is 64x48"):
        d2 = tmp_path / "d2.png"
        cv2.imwrite(str(d2), np.full((48, 32), 1000, np.uint16))
        load_frame(c, d2, k)
    with pytest.raises(InputError, match="absurd focal"):
        Intrinsics(0.5, 0.5, 32, 24, 64, 48).validate()
    with pytest.raises(InputError, match="d.png.*no intrinsics"):
        load_frame(c, d, None)
    j = tmp_path / "k.json"
    j.write_text(json.dumps({"fx": 60, "fy": 60, "cx": 32}))
    with pytest.raises(InputError, match="k.json.*lack 'cy'"):
        read_intrinsics(j)


@pytest.mark.real
def test_real_kinect_frames_load(real_dir):
    names = real_frame_files(real_dir)
    assert len(names) == 5
    for name in names:
        f = load_real(real_dir, name)
        assert f.color.shape == (480, 640, 3) and f.depth.shape == (480, 640)
        valid = f.depth[f.depth > 0]
        assert 0.3 < np.median(valid) < 6.0, name


def test_colour_alone_takes_nominal_intrinsics(tmp_path):
    c, _ = _write(tmp_path)
    f = load_frame(c, None, None)
    assert f.intrinsics == Intrinsics.nominal(64, 48)
    assert (f.intrinsics.cx, f.intrinsics.cy) == (31.5, 23.5)
    assert not f.depth.any()
