"""benchmarks/bench_frame_size.py: the enlarged copy of a real-layout folder reads back as the folder."""

import json

import cv2
import numpy as np
import pytest

from benchmarks.bench_frame_size import enlarge, main
from lv3d.frame_folder import FrameFolder


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    from lv3d.render.frame import render_scene

    f = tmp_path_factory.mktemp("real") / "frames"
    f.mkdir()
    intr = {"width": 640, "height": 480, "frames": {}}
    rows = ["frame,object,u,v,shape,partial,stacked,notes"]
    for i, cls in enumerate(["cube", "cylinder"]):
        frame, faces = render_scene(cls, 30 + i, "realsense")
        name = f"f{i}"
        cv2.imwrite(str(f / f"{name}_rgb.png"), cv2.cvtColor(frame.color, cv2.COLOR_RGB2BGR))
        cv2.imwrite(str(f / f"{name}_depth_mm.png"), np.round(frame.depth * 1000).astype(np.uint16))
        cv2.imwrite(str(f / f"{name}_label.png"), (faces > 0).astype(np.uint16))
        k = frame.intrinsics
        intr["frames"][name] = {"fx": k.fx, "fy": k.fy, "cx": k.cx, "cy": k.cy, "depth_scale_m": 0.001}
        v, u = np.nonzero(faces)
        rows.append(f"{name},1,{int(np.median(u))},{int(np.median(v))},{'box' if cls == 'cube' else 'cylinder'},no,no,")
    (f / "intrinsics.json").write_text(json.dumps(intr))
    (f / "objects.csv").write_text("\n".join(rows) + "\n")
    return f


def test_the_enlarged_copy_reads_back_as_the_folder(folder, tmp_path):
    big = FrameFolder(enlarge(folder, tmp_path / "big", 2, limit=1))
    small = FrameFolder(folder)
    assert big.frames == ["f0"]
    a, b = small.load("f0"), big.load("f0")
    assert b.scale == 2 and a.intrinsics == b.intrinsics
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(small.label_image("f0", a.shape), big.label_image("f0", b.shape))
    la, lb = small.labels()["f0"], big.labels()["f0"]
    assert [(o.u, o.v, o.shape) for o in la] == [(o.u, o.v, o.shape) for o in lb]
    assert lb[0].file_uv == (2 * la[0].u, 2 * la[0].v)


def test_bad_arguments_exit_2(folder, capsys):
    with pytest.raises(SystemExit) as e:
        main([str(folder), "--factor", "1"])
    assert e.value.code == 2
    assert "--factor must be at least 2" in capsys.readouterr().err


def test_the_full_size_run_leaves_the_working_size_as_it_was(folder, monkeypatch):
    import benchmarks.bench_frame_size as bench
    from lv3d import rgbd

    sides = []
    monkeypatch.setattr(bench.bench_real, "main", lambda argv: sides.append(rgbd.WORK_SIDE_PX) or 0)
    monkeypatch.setattr(bench.compare_real, "main", lambda argv: 0)
    assert bench.main([str(folder), "--limit", "1", "--full-size"]) == 0
    assert sides == [640, 640, 10 ** 9] and rgbd.WORK_SIDE_PX == 640
