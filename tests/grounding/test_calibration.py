"""grounding.calibrate: the shipped per-(modality, predicate) maps are monotone in the raw probability,
stay in (0, 1), leave unmapped predicates and impossible facts alone, read a fact's value in tolerances,
take a type's own final map (or none) over the pooled one;
pack_object picks the small padded shape for small objects."""

import math

import numpy as np

import grounding
from grounding._calibration import FINAL, TABLE, calibrate_with
from grounding._confidence import EQUAL_SIDES_RATIO, RIGHT_ANGLE_DEG
from grounding._problem import SIZES
from lv3d.describe import calibration_features

MEASURES = {"support": 0.9, "log_area_px": 8.0, "min_turn_z": 6.0, "min_side_px": 40.0, "sides": 4, "faces": 3,
            "value": 1.05}


def test_every_shipped_map_grows_with_the_raw_probability():
    assert TABLE, "no calibration maps shipped"
    ps = np.linspace(0.01, 1.0, 25)
    for modality, maps in TABLE.items():
        for pred in maps:
            c = np.array([grounding.calibrate(modality, pred, p, MEASURES) for p in ps])
            assert np.all((c > 0) & (c < 1)), (modality, pred)
            assert np.all(np.diff(c) >= -1e-12), (modality, pred)


def test_unmapped_predicates_and_impossible_facts_keep_their_probability():
    assert grounding.calibrate("no-such-modality", "square", 0.7, MEASURES) == 0.7
    modality, maps = next(iter(TABLE.items()))
    assert grounding.calibrate(modality, next(iter(maps)), 0.0, MEASURES) == 0.0


def test_a_map_reads_the_named_measurements():
    table = {"rgbd": {"square": {"features": ["logit_p", "support"], "bias": 0.0, "coef": [1.0, 2.0]}}}
    low = calibrate_with(table, "rgbd", "square", 0.5, {"support": 0.0})
    high = calibrate_with(table, "rgbd", "square", 0.5, {"support": 1.0})
    assert low == 0.5 and abs(high - 1 / (1 + np.exp(-2.0))) < 1e-12


def test_tol_frac_is_the_value_in_units_of_the_tolerance_clipped():
    def conf(pred, value):  # sigmoid of the tolerance fraction alone
        table = {"rgbd": {pred: {"features": ["logit_p", "tol_frac"], "bias": 0.0, "coef": [0.0, 1.0]}}}
        return -math.log(1 / calibrate_with(table, "rgbd", pred, 0.5, {"value": value}) - 1)

    assert abs(conf("square", EQUAL_SIDES_RATIO) - 1.0) < 1e-9        # at the boundary: 1
    assert abs(conf("square", EQUAL_SIDES_RATIO ** 2) - 2.0) < 1e-9
    assert abs(conf("perpendicular", 90.0 + RIGHT_ANGLE_DEG / 2) - 0.5) < 1e-9
    assert abs(conf("acute", 60.0) - -1.0) < 1e-9                     # 20 deg inside the 80 deg limit
    assert abs(conf("square", 50.0) - 3.0) < 1e-9                     # clipped: 3 tolerances out at most


def test_calibration_features_carry_each_candidates_value():
    cands = [("square", ("f1",), 0.9, 1.05), ("rectangle", ("f1",), 0.8, 3.0), ("face_of", ("o1", "f1"), 1.0, None)]
    feats = calibration_features(cands, [])
    assert [f.get("value") for f in feats] == [1.05, 3.0, None]


def test_calibrate_is_calibrate_with_the_shipped_table():
    # calibrate keeps each map's inputs looked up; the numbers must be those of the general function
    for modality, maps in TABLE.items():
        for pred in maps:
            for p in (1e-6, 0.3, 0.97, 1.0):
                assert grounding.calibrate(modality, pred, p, MEASURES) == calibrate_with(TABLE, modality, pred, p, MEASURES, FINAL)
                assert grounding.calibrate(modality, pred, p) == calibrate_with(TABLE, modality, pred, p, None, FINAL)


def test_final_map_interpolates_its_knots_and_keeps_zero():
    final = {"rgbd": {"x": [0.2, 0.6, 0.6, 0.8], "y": [0.1, 0.3, 0.5, 0.7]}}  # a step at 0.6
    got = [calibrate_with({}, "rgbd", "triangle", p, None, final) for p in (0.0, 0.1, 0.4, 0.6, 0.7, 0.9)]
    assert np.allclose(got, [0.0, 0.1, 0.2, 0.5, 0.6, 0.7])
    for final in FINAL.values():
        for knots in [final, *(k for k in final.get("by_pred", {}).values() if k is not None)]:
            assert np.all(np.diff(knots["x"]) >= 0) and np.all(np.diff(knots["y"]) >= 0)


def test_a_type_takes_its_own_final_map_or_none_before_the_pooled_one():
    final = {"rgbd": {"x": [0.0, 1.0], "y": [0.2, 0.2],                 # pooled: everything to 0.2
                      "by_pred": {"square": {"x": [0.0, 1.0], "y": [0.5, 0.5]}, "parallel": None}}}
    got = {pred: calibrate_with({}, "rgbd", pred, 0.7, None, final) for pred in ("square", "parallel", "triangle")}
    assert got == {"square": 0.5, "parallel": 0.7, "triangle": 0.2}
    assert calibrate_with({}, "rgbd", "square", 0.0, None, final) == 0.0  # impossible stays impossible


def _square(x0, y0, s=40.0):
    return np.array([[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]], float)


def test_pack_object_uses_the_small_shape_when_the_object_fits():
    small, _ = grounding.pack_object([_square(100, 100), _square(140, 100)], intrinsics=(600.0, 600.0, 320.0, 240.0))
    assert small.face_index.shape == SIZES[0][:2] and small.vertices.shape[0] == SIZES[0][2]
    five = [_square(100 + 50 * i, 100) for i in range(SIZES[0][0] + 1)]
    big, index = grounding.pack_object(five, intrinsics=(600.0, 600.0, 320.0, 240.0))
    assert big.face_index.shape == SIZES[-1][:2] and index.shape == (len(five), SIZES[-1][1])
