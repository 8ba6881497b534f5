"""grounding.calibrate: the shipped per-(modality, predicate) maps are monotone in the raw probability,
stay in (0, 1), leave unmapped predicates and impossible facts alone; pack_object picks the small padded
shape for small objects."""

import numpy as np

import grounding
from grounding._calibration import TABLE, calibrate_with
from grounding._problem import SIZES

MEASURES = {"support": 0.9, "log_area_px": 8.0, "min_turn_z": 6.0, "min_side_px": 40.0, "sides": 4, "faces": 3}


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


def test_calibrate_is_calibrate_with_the_shipped_table():
    # calibrate keeps each map's inputs looked up; the numbers must be those of the general function
    for modality, maps in TABLE.items():
        for pred in maps:
            for p in (1e-6, 0.3, 0.97, 1.0):
                assert grounding.calibrate(modality, pred, p, MEASURES) == calibrate_with(TABLE, modality, pred, p, MEASURES)
                assert grounding.calibrate(modality, pred, p) == calibrate_with(TABLE, modality, pred, p)


def _square(x0, y0, s=40.0):
    return np.array([[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]], float)


def test_pack_object_uses_the_small_shape_when_the_object_fits():
    small, _ = grounding.pack_object([_square(100, 100), _square(140, 100)], intrinsics=(600.0, 600.0, 320.0, 240.0))
    assert small.face_index.shape == SIZES[0][:2] and small.vertices.shape[0] == SIZES[0][2]
    five = [_square(100 + 50 * i, 100) for i in range(SIZES[0][0] + 1)]
    big, index = grounding.pack_object(five, intrinsics=(600.0, 600.0, 320.0, 240.0))
    assert big.face_index.shape == SIZES[-1][:2] and index.shape == (len(five), SIZES[-1][1])
