import json

import cv2
import numpy as np
import pytest

from lv3d.camera import Intrinsics
from lv3d.errors import InputError
from lv3d.rgbd import DEPTH_RANGE_M, load_frame, load_real, read_intrinsics, real_frame_files


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


@pytest.mark.parametrize("raw, scale, median, suggested", [
    (1200, 1.0, "1200 m", "--depth-scale 0.001"),   # millimetres read as metres
    (900, 0.0001, "0.09 m", "--depth-scale 0.001"),  # millimetres read as tenths of a millimetre
    (12000, 0.001, "12 m", "--depth-scale 0.0001"),  # tenths of a millimetre read as millimetres
])
def test_depth_in_the_wrong_unit_names_the_file_and_the_scale(tmp_path, raw, scale, median, suggested):
    depth = np.full((48, 64), raw, np.uint16)
    depth[:10] = 0  # no reading: left out of the median
    c, d = _write(tmp_path, depth=depth)
    with pytest.raises(InputError) as e:
        load_frame(c, d, Intrinsics(60, 60, 32, 24, 64, 48), scale)
    msg = str(e.value)
    assert "d.png" in msg and "--depth-scale" in msg and median in msg and suggested in msg, msg
    assert "\n" not in msg


def test_depth_in_the_right_unit_loads(tmp_path):
    lo, hi = DEPTH_RANGE_M
    assert (lo, hi) == (0.15, 8.0)
    depth = np.zeros((48, 64), np.uint16)
    depth[:, :40] = 650  # the median is taken over readings only: 0.65 m, with 0 in over a third of the image
    c, d = _write(tmp_path, depth=depth)
    f = load_frame(c, d, Intrinsics(60, 60, 32, 24, 64, 48), 0.001)
    assert np.isclose(np.median(f.depth[f.depth > 0]), 0.65)


def test_float_depth_is_metres_whatever_the_scale_of_integer_depth(tmp_path):
    c, _ = _write(tmp_path)
    d = tmp_path / "d.tiff"
    cv2.imwrite(str(d), np.full((48, 64), 1.5, np.float32))
    k = Intrinsics(60, 60, 32, 24, 64, 48)
    assert np.allclose(load_frame(c, d, k, 0.001).depth, 1.5)  # not scaled by 0.001 again
    assert np.allclose(load_frame(c, d, k, 1.0).depth, 1.5)
    cv2.imwrite(str(d), np.full((48, 64), 1500.0, np.float32))  # millimetres in a float image
    with pytest.raises(InputError, match=r"d\.tiff.*read as metres"):
        load_frame(c, d, k, 0.001)


def test_images_above_the_pixel_limit_are_refused_before_decoding(tmp_path):
    from lv3d.limits import MAX_PIXELS

    big = tmp_path / "big.png"
    cv2.imwrite(str(big), np.zeros((2100, 2100, 3), np.uint8))
    assert 2100 * 2100 > MAX_PIXELS
    with pytest.raises(InputError, match=r"big\.png: colour image of 2100x2100 pixels is larger"):
        load_frame(big, None, None)


@pytest.mark.parametrize("text, key", [
    ('{"fx": 60, "fy": 60, "cx": 32, "cy": 24, "width": 640.7, "height": 48}', "width"),
    ('{"fx": 60, "fy": 60, "cx": 32, "cy": 24, "width": 64, "height": 48, "depth_scale_m": "x"}', "depth_scale_m"),
    ('{"width": 64, "height": 48, "frames": [1, 2]}', "frames"),
    ('{"width": 64, "height": 48, "frames": {"f": 3}}', "frames"),
    ('{"fx": "60", "fy": 60, "cx": 32, "cy": 24, "width": 64, "height": 48}', "fx"),
    ('{"fx": 60, "fy": 60, "cx": 32, "cy": 24, "width": 64, "height": 48, "depth_scale_m": 0}', "depth_scale_m"),
])
def test_bad_intrinsics_are_one_line_errors(tmp_path, text, key):
    from lv3d.rgbd import read_intrinsics

    p = tmp_path / "k.json"
    p.write_text(text)
    with pytest.raises(InputError) as e:
        read_intrinsics(p, "f")
    assert str(p) in str(e.value) and key in str(e.value)


def test_extract_reports_the_wrong_scale_in_one_line(tmp_path, capsys):
    from lv3d.cli import main

    c, d = _write(tmp_path, depth=np.full((48, 64), 1200, np.uint16))
    k = tmp_path / "k.json"
    k.write_text(json.dumps(Intrinsics(60, 60, 32, 24, 64, 48).to_dict()))
    out = tmp_path / "o"
    rc = main(["extract", str(c), "--depth", str(d), "--intrinsics", str(k), "--depth-scale", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert "d.png" in err and "--depth-scale 0.001" in err
    assert not out.exists()


def test_a_data_set_item_names_its_meta_json_key(tmp_path):
    from lv3d.rgbd import load_item

    item = tmp_path / "s000000"
    item.mkdir()
    _write(item, depth=np.full((48, 64), 1200, np.uint16))
    (item / "c.png").rename(item / "color.png")
    (item / "d.png").rename(item / "depth.png")
    (item / "meta.json").write_text(json.dumps({"intrinsics": Intrinsics(60, 60, 32, 24, 64, 48).to_dict(),
                                                "depth_scale_m": 1.0}))
    with pytest.raises(InputError, match=r"depth\.png.*set depth_scale_m in meta\.json to 0\.001"):
        load_item(item)
