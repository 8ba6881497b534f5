"""``lv3d calibrate``: the fit writes its command line into the file's provenance; rows, real and fit refuse
to replace a file they did not write, in one line and before any work."""

import json
import pickle

import numpy as np

from lv3d.cli import main


def _rows(n: int = 60) -> list[dict]:
    rng = np.random.default_rng(3)
    return [{"modality": "rgbd", "pred": "perpendicular", "p": float(p), "y": bool(rng.random() < p), "seed": 30000 + i,
             "value": 90.0, "support": 0.9, "log_area_px": 8.0, "min_side_px": 30.0, "min_turn_z": 5.0,
             "shared_side_px": 40.0, "source": "render:realsense"}
            for i, p in enumerate(rng.uniform(0.05, 0.99, n))]


def test_the_fit_records_its_command_line_and_data(tmp_path, capsys):
    rows = tmp_path / "rows.pkl"
    rows.write_bytes(pickle.dumps({"rows": _rows(), "scenes": [], "made_by": "lv3d calibrate rows --out rows.pkl"}))
    out = tmp_path / "calibration.json"
    assert main(["calibrate", "fit", str(rows), "--modalities", "rgbd", "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    prov = doc["provenance"]
    assert prov["command"] == (f"lv3d calibrate fit {rows} --real-share 0.5 --out {out} --modalities rgbd")
    assert prov["data"][0]["made_by"] == "lv3d calibrate rows --out rows.pkl" and prov["data"][0]["rows"] == 60
    assert "lv3d calibrate fit" in doc["about"] and f"wrote {out}" in capsys.readouterr().out


def test_a_file_the_command_did_not_write_is_not_replaced(tmp_path, capsys):
    foreign = tmp_path / "notes.txt"
    foreign.write_text("mine")
    for argv in (["calibrate", "rows", "--per-class", "1", "--out", str(foreign)],
                 ["calibrate", "rows", "--per-class", "1", "--fresh", "--out", str(foreign)],
                 ["calibrate", "real", str(tmp_path), "--out", str(foreign)]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("lv3d: error: "), argv
    rows = tmp_path / "rows.pkl"
    rows.write_bytes(pickle.dumps({"rows": _rows(), "scenes": []}))
    assert main(["calibrate", "fit", str(rows), "--out", str(foreign)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notes.txt: exists and is not a calibration file" in err[0]
    assert foreign.read_text() == "mine"


def test_bad_options_are_one_line(capsys, tmp_path):
    assert main(["calibrate", "real", str(tmp_path), "--modalities", "rgb", "--out", str(tmp_path / "r.pkl")]) == 2
    assert "--modalities: choose among depth, rgbd" in capsys.readouterr().err
    for seeds, what in (("0,x", "whole numbers"), ("1,1", "distinct")):
        assert main(["calibrate", "real", str(tmp_path), "--seed", seeds, "--out", str(tmp_path / "r.pkl")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "--seed" in err[0] and what in err[0]
    assert main(["calibrate", "rows", "--preset", "nosuch", "--out", str(tmp_path / "r.pkl")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nosuch" in err[0]
    assert not (tmp_path / "r.pkl").exists()
