"""The cylinder-search diagnostic: its command line, and on real frames its tests agreeing with the depth stage's."""

import csv
from pathlib import Path

import pytest

import benchmarks.why_curved as why

YCB = Path(__file__).resolve().parents[3] / "shared" / "data" / "real" / "ycb-realsense"


def test_bad_arguments_stop_with_a_message(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        why.main([str(tmp_path), "--limit", "0"])
    assert e.value.code == 2
    assert why.main([str(tmp_path), "--set", "curved.no_such=1"]) == 2
    assert "no_such" in capsys.readouterr().err
    assert why.main([str(tmp_path)]) == 2  # no objects.csv: the folder is named
    assert str(tmp_path) in capsys.readouterr().err


@pytest.mark.real
def test_a_soup_can_has_its_cylinder_and_every_verdict_is_the_depth_stages(tmp_path, capsys):
    if not (YCB / "objects.csv").is_file():
        pytest.skip(f"real YCB frames not found at {YCB} (../shared/data/real/ycb-realsense)")
    out_csv = tmp_path / "why.csv"
    assert why.main([str(YCB), "--limit", "2", "--csv", str(out_csv)]) == 0
    out = capsys.readouterr().out
    can = next(line for line in out.splitlines() if "pcnn000001 object 1 " in line)
    assert "tomato soup can" in can and ": cylinder;" in can and "consensus ran" in can
    assert "verdicts that differ from the depth stage's: 0" in out
    with open(out_csv, newline="") as f:
        rows = list(csv.DictReader(f))
    mine = [r for r in rows if r["frame"] == "pcnn000001" and r["object"] == "1"]
    # the can's side stands; the other candidate on it fails a test, named with its value and limit
    assert any(r["verdict"] == "stands" and r["stood"] == "True" for r in mine)
    failed = [r for r in mine if r["verdict"] != "stands"]
    assert failed and all(r["stood"] == "False" and "FAIL" in r[r["verdict"]] for r in failed)
    assert {r["shape"] for r in rows} <= {"cylinder", "box"}
