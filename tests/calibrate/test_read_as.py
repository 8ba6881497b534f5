"""The calibration fit: rgbd's facts about the angle between two planes are read as depth reads them
(lv3d.describe.ANGLE_PREDS), so they take depth's maps; rgbd's other facts keep maps of their own."""

import numpy as np

from grounding import calibrate_with
from lv3d.calibrate.fit import fit


def _rows(modality: str, pred: str, truth_power: float, seed: int, n: int = 300) -> list[dict]:
    rng = np.random.default_rng(seed)
    return [{"modality": modality, "pred": pred, "p": float(p), "y": bool(rng.random() < p ** truth_power),
             "seed": 30000 + i, "value": 90.0, "support": float(rng.uniform(0.5, 1.0)), "log_area_px": 8.0,
             "min_side_px": 30.0, "min_turn_z": 5.0, "shared_side_px": 40.0, "source": "render:realsense"}
            for i, p in enumerate(rng.uniform(0.05, 0.99, n))]


def test_rgbd_angle_facts_take_depths_maps_and_its_other_facts_their_own():
    rows = (_rows("depth", "perpendicular", 2.0, 1) + _rows("rgbd", "perpendicular", 4.0, 2)
            + _rows("depth", "square", 1.0, 3) + _rows("rgbd", "square", 4.0, 4))
    lines = []
    table, final = fit(rows, ("rgbd", "depth"), log=lines.append)
    assert table["rgbd"]["perpendicular"] == table["depth"]["perpendicular"]
    assert any("rgbd  perpendicular" in line and "takes depth's maps" in line for line in lines)
    probe = {"support": 0.8, "log_area_px": 8.0, "min_side_px": 30.0, "min_turn_z": 5.0, "shared_side_px": 40.0,
             "value": 90.0}
    for p in (0.2, 0.5, 0.9):
        assert calibrate_with(table, "rgbd", "perpendicular", p, probe, final) == \
            calibrate_with(table, "depth", "perpendicular", p, probe, final)
    # rgbd's square was fitted on its own rows, whose truth is far rarer than depth's at the same probability
    assert calibrate_with(table, "rgbd", "square", 0.5, probe, final) < \
        calibrate_with(table, "depth", "square", 0.5, probe, final) - 0.1
