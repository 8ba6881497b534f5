"""The perception benchmark's pooled seeds, bootstrap intervals and resumable rows (--seeds, --rows)."""

import json

import pytest

import benchmarks.bench_perception as bench


def _row(found, gt, det_ok=1, det=1):
    return {"found": found, "gt_faces": gt, "det_ok": det_ok, "det_faces": det, "sides_ok": found}


def test_interval_brackets_the_pooled_ratio_and_is_a_point_when_scenes_agree():
    same = [_row(3, 4)] * 20
    assert bench.interval(same, "recall") == pytest.approx((0.75, 0.75))
    mixed = [_row(4, 4)] * 10 + [_row(1, 4)] * 10
    lo, hi = bench.interval(mixed, "recall")
    assert lo < 0.625 < hi and hi - lo > 0.2
    assert bench.interval(mixed, "recall", seed=0) == (lo, hi)  # seeded: the same interval each run


@pytest.mark.parametrize("seeds, says", [("1000,x", "whole numbers"), ("1000,1000", "names a seed twice"),
                                         ("1000,1001", "share scenes")])
def test_bad_seeds_stop_before_any_work(seeds, says, capsys):
    with pytest.raises(SystemExit) as e:
        bench.main(["--per-class", "2", "--presets", "clean", "--seeds", seeds])
    assert e.value.code == 2 and says in capsys.readouterr().err


def test_rows_resume_without_perceiving_again(tmp_path, monkeypatch, capsys):
    rows = tmp_path / "new" / "rows.jsonl"  # its folder is made
    argv = ["--per-class", "1", "--presets", "clean", "--modalities", "rgb", "--seeds", "7,9", "--rows", str(rows)]
    assert bench.main(argv) == 0
    first = capsys.readouterr().out
    lines = rows.read_text().splitlines()
    assert len(lines) == 2 * len(bench.CLASSES)  # one scene a class and seed
    assert "recall by seed: 7 " in first and "95% intervals over scenes" in first

    def fail(*args, **kwargs):
        raise AssertionError("a scene kept in --rows was perceived again")

    monkeypatch.setattr(bench, "perceive", fail)
    rows.write_text("\n".join(lines) + "\n" + lines[0][:20])  # a last row cut short by a stop is skipped
    assert bench.main(argv) == 0
    strip = lambda out: [ln for ln in out.splitlines() if not ln.startswith("== preset")]  # noqa: E731 (its time)
    assert strip(capsys.readouterr().out) == strip(first)


def test_rows_of_another_kind_are_named(tmp_path, capsys):
    rows = tmp_path / "rows.jsonl"
    rows.write_text("not json\n" + json.dumps({"key": ["x"], "eval": {}}) + "\n")
    with pytest.raises(SystemExit) as e:
        bench.main(["--per-class", "1", "--presets", "clean", "--rows", str(rows)])
    assert f"{rows} line 1" in str(e.value)
