"""lv3d.calibrate.check (``lv3d calibrate check``): per-type ECE of calibrated rows per set and pooled, grouped by
predicate; a missing or foreign pickle is one line naming it."""

import pickle

import numpy as np

from lv3d.calibrate.check import score
from lv3d.cli import main


def _rows(seed0: int, n: int = 40) -> list[dict]:
    rng = np.random.default_rng(seed0)
    rows = []
    for i in range(n):
        p = 1.0 - 10.0 ** float(rng.uniform(-6, -2))  # a clear acute dihedral: calibrated to 0.15-0.9
        rows.append({"modality": "rgbd", "pred": "acute", "p": p, "y": bool(rng.random() < 0.7), "seed": seed0 + i,
                     "value": 60.0, "shared_side_px": 0.0 if i % 2 else 40.0, "support": 0.95, "log_area_px": 8.0,
                     "min_side_px": 30.0, "min_turn_z": 5.0})
    rows.append({"modality": "depth", "pred": "acute", "p": 0.9, "y": True, "seed": seed0, "value": 70.0})
    rows.append({"modality": "rgbd", "pred": "acute", "p": 0.0, "y": False, "seed": seed0, "value": 120.0})
    return rows


def test_score_groups_kinds_filed_apart_under_their_predicate_and_skips_other_rows():
    cands, facts = score(_rows(1), "rgbd")
    assert len(cands) == 40                                  # the depth row and the p = 0 row are left out
    assert set(facts) == {"acute"}                            # acute and acute_touch rows together
    assert np.all(facts["acute"][:, 0] >= 0.05)


def test_each_set_alone_then_pooled(tmp_path, capsys):
    paths = []
    for s in (1000, 2000):
        paths.append(tmp_path / f"rows{s}.pkl")
        paths[-1].write_bytes(pickle.dumps({"rows": _rows(s), "scenes": []}))
    assert main(["calibrate", "check", *map(str, paths), "--draws", "20"]) == 0
    out = capsys.readouterr().out
    assert "== rows1000.pkl: 40 scenes" in out and "== rows2000.pkl: 40 scenes" in out
    assert "== all pooled: 80 scenes" in out
    assert out.count("ECE acute") == 3 and "target <= 0.05" in out


def test_a_missing_or_foreign_file_is_named(tmp_path, capsys):
    assert main(["calibrate", "check", str(tmp_path / "absent.pkl")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "absent.pkl: no such file" in err[0]
    bad = tmp_path / "bad.pkl"
    bad.write_bytes(pickle.dumps({"other": 1}))
    assert main(["calibrate", "check", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.pkl: not a pickle of lv3d calibrate rows" in err[0]
    bad.write_bytes(b"not a pickle at all")
    assert main(["calibrate", "fit", str(bad), "--dry-run"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.pkl: not a pickle of lv3d calibrate rows" in err[0]
