"""benchmarks.compare_objects: two bench_real --objects runs, object by object."""

import csv

import pytest

from benchmarks.bench_real import OBJECT_COLUMNS
from benchmarks.compare_objects import compare, main, paired, read_rows


def _write(path, verdicts, column="cylinder_read", frames=10, seeds=(1, 2)):
    """A --objects CSV: for each frame and seed, one cylinder whose ``column`` verdict is verdicts[frame]
    (None: the figure does not count it)."""
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=OBJECT_COLUMNS)
        w.writeheader()
        for f in range(frames):
            for s in seeds:
                row = {k: "" for k in OBJECT_COLUMNS}
                v = verdicts[f]
                row.update(folder="ycb", frame=f"f{f}", object="1", shape="cylinder", modality="depth", seed=str(s),
                           found="yes", merged="no", **{column: "" if v is None else v})
                w.writerow(row)
    return path


def test_objects_are_paired_and_flips_counted_towards_the_target(tmp_path):
    a = read_rows(_write(tmp_path / "a.csv", ["no"] * 6 + ["yes"] * 4))
    b = read_rows(_write(tmp_path / "b.csv", ["yes"] * 6 + ["yes"] * 3 + [None]))
    pairs = paired(a, b, "cylinder_read", "depth")
    assert len(pairs) == 18  # the frame B does not count is left out, both its seeds
    c = compare(pairs, True, 500, 0)
    assert (c["better"], c["worse"], c["frames"]) == (12, 0, 9)
    assert c["a"] == pytest.approx(6 / 18) and c["b"] == pytest.approx(1.0)
    # the frame is the unit of the sign test: six frames each better (at both seeds), none worse
    assert (c["frames_up"], c["frames_down"]) == (6, 0) and c["p"] == pytest.approx(2 * 0.5 ** 6)
    lo, hi = c["interval"]
    assert 0 < lo <= c["b"] - c["a"] <= hi


def test_a_figure_whose_target_wants_no_counts_a_new_yes_as_worse(tmp_path):
    a = read_rows(_write(tmp_path / "a.csv", ["no"] * 10, column="box_curved"))
    b = read_rows(_write(tmp_path / "b.csv", ["yes"] + ["no"] * 9, column="box_curved"))
    c = compare(paired(a, b, "box_curved", "depth"), False, 500, 0)
    assert (c["better"], c["worse"]) == (0, 2) and c["a"] == 0.0 and c["b"] == pytest.approx(0.1)
    assert (c["frames_up"], c["frames_down"]) == (0, 1) and c["p"] == 1.0  # one frame, both seeds: no evidence


def test_no_change_is_no_flip_and_p_one(tmp_path, capsys):
    a = _write(tmp_path / "a.csv", ["yes", "no"] * 5)
    assert main([str(a), str(a), "--resamples", "200"]) == 0
    out = capsys.readouterr().out
    line = next(l for l in out.splitlines() if l.startswith("cylinder_read_frac"))
    assert "+0.000" in line and line.split()[-3] == "1"  # p, before the target ">= 0.85"


def test_a_file_that_is_no_objects_csv_is_one_line(tmp_path, capsys):
    good = _write(tmp_path / "a.csv", ["yes"] * 10)
    (tmp_path / "bad.csv").write_text("frame,object\nx,1\n")
    assert main([str(good), str(tmp_path / "bad.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bad.csv" in err and "bench_real --objects" in err
    assert main([str(good), str(tmp_path / "missing.csv")]) == 2
    assert "missing.csv" in capsys.readouterr().err
