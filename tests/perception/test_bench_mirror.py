"""benchmarks/bench_mirror.py: the mirrored copy of a real-layout folder is the folder seen in a mirror."""

import numpy as np
import pytest

from benchmarks.bench_mirror import main, mirror
from lv3d.frame_folder import FrameFolder


def test_the_mirrored_copy_is_the_folder_seen_in_a_mirror(real_layout, tmp_path):
    plain, flipped = FrameFolder(real_layout), FrameFolder(mirror(real_layout, tmp_path / "m", limit=None))
    assert flipped.frames == plain.frames == ["f0", "f1"]
    for name in plain.frames:
        a, b = plain.load(name), flipped.load(name)
        np.testing.assert_array_equal(b.depth, a.depth[:, ::-1])
        np.testing.assert_array_equal(b.color, a.color[:, ::-1])
        np.testing.assert_array_equal(flipped.label_image(name, b.shape), plain.label_image(name, a.shape)[:, ::-1])
        (la,), (lb,) = plain.labels()[name], flipped.labels()[name]
        assert (lb.u, lb.v, lb.shape) == (a.intrinsics.width - 1 - la.u, la.v, la.shape)
        # the labelled pixel's point is the original's with x negated: the same scene, in a mirror
        z = a.depth[la.v, la.u]
        ka, kb = a.intrinsics, b.intrinsics
        assert (lb.u - kb.cx) * z / kb.fx == pytest.approx(-(la.u - ka.cx) * z / ka.fx)
        assert (kb.fy, kb.cy) == (ka.fy, ka.cy)
    # turned over, the labelled pixel moves down too, and so does the principal point
    over = FrameFolder(mirror(real_layout, tmp_path / "o", limit=1, flip="both"))
    a, b = plain.load("f0"), over.load("f0")
    np.testing.assert_array_equal(b.depth, a.depth[::-1, ::-1])
    (la,), (lb,) = plain.labels()["f0"], over.labels()["f0"]
    assert (lb.u, lb.v) == (a.intrinsics.width - 1 - la.u, a.intrinsics.height - 1 - la.v)
    assert b.intrinsics.cy == a.intrinsics.height - 1 - a.intrinsics.cy
    # the mirror of the mirror is the folder
    twice = FrameFolder(mirror(tmp_path / "m", tmp_path / "mm", limit=1))
    assert twice.frames == ["f0"]
    np.testing.assert_array_equal(twice.load("f0").depth, plain.load("f0").depth)
    assert twice.load("f0").intrinsics == plain.load("f0").intrinsics


def test_both_runs_share_the_modalities_and_seeds_and_bad_arguments_exit_2(real_layout, monkeypatch, capsys):
    import benchmarks.bench_mirror as bench

    calls = []
    monkeypatch.setattr(bench.bench_real, "main", lambda argv: calls.append(argv) or 0)
    monkeypatch.setattr(bench.compare_real, "main", lambda argv: calls.append(argv) or 0)
    assert main([str(real_layout), "--modalities", "depth", "--seed", "0,1"]) == 0
    (a, b, cmp) = calls
    assert a[0] == str(real_layout) and b[0] != a[0] and a[1:-2] == b[1:-2] == ["--modalities", "depth", "--seed", "0,1"]
    assert a[-2] == b[-2] == "--json" and a[-1] != b[-1]
    assert cmp[-1] == "--folders"
    with pytest.raises(SystemExit) as e:
        main([str(real_layout), "--limit", "0"])
    assert e.value.code == 2 and "--limit must be at least 1" in capsys.readouterr().err
