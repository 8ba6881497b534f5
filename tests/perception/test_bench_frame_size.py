"""benchmarks/bench_frame_size.py: the enlarged copy of a real-layout folder reads back as the folder."""

import numpy as np
import pytest

from benchmarks.bench_frame_size import enlarge, main
from lv3d.frame_folder import FrameFolder


def test_the_enlarged_copy_reads_back_as_the_folder(real_layout, tmp_path):
    big = FrameFolder(enlarge(real_layout, tmp_path / "big", 2, limit=1))
    small = FrameFolder(real_layout)
    assert big.frames == ["f0"]
    a, b = small.load("f0"), big.load("f0")
    assert b.scale == 2 and a.intrinsics == b.intrinsics
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(small.label_image("f0", a.shape), big.label_image("f0", b.shape))
    la, lb = small.labels()["f0"], big.labels()["f0"]
    assert [(o.u, o.v, o.shape) for o in la] == [(o.u, o.v, o.shape) for o in lb]
    assert lb[0].file_uv == (2 * la[0].u, 2 * la[0].v)


def test_bad_arguments_exit_2(real_layout, capsys):
    with pytest.raises(SystemExit) as e:
        main([str(real_layout), "--factor", "1"])
    assert e.value.code == 2
    assert "--factor must be at least 2" in capsys.readouterr().err


def test_the_full_size_run_leaves_the_working_size_as_it_was(real_layout, monkeypatch):
    import benchmarks.bench_frame_size as bench
    from lv3d import rgbd

    sides = []
    monkeypatch.setattr(bench.bench_real, "main", lambda argv: sides.append(rgbd.WORK_SIDE_PX) or 0)
    monkeypatch.setattr(bench.compare_real, "main", lambda argv: 0)
    assert bench.main([str(real_layout), "--limit", "1", "--full-size"]) == 0
    assert sides == [640, 640, 10 ** 9] and rgbd.WORK_SIDE_PX == 640
