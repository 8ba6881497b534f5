"""lv3d.calibrate.real: bench_real's box and calibration figures recomputed from stored candidates for any
calibration; the fit's weights of real rows and its predictions as grounding applies a map."""

import math

import numpy as np

from lv3d.calibrate.fit import predict_rows, row_weights
from lv3d.calibrate.real import figures
from grounding import calibrate_with


def _row(args, p, y=None, key="perpendicular"):
    r = {"modality": "depth", "pred": "perpendicular", "key": key, "p": p, "args": args, "value": 90.0,
         "edge_scale2": 1.5, "support": 0.9}
    if y is not None:
        r["y"] = y
    return r


def test_figures_take_the_larger_order_count_missing_pairs_as_zero_and_drop_facts_below_the_floor():
    frame = {"modality": "depth",
             # object 0 a box (two adjacent pairs, one without any candidate), object 1 a can (one pair)
             "pairs": {0: [("a", "b"), ("b", "c")], 1: [("d", "e")]}, "truth": {0: True, 1: False},
             "boxes": [0, None], "rounds": [1],
             "cands": [_row(("a", "b"), 0.8, True), _row(("b", "a"), 0.9, True), _row(("d", "e"), 0.04, False)]}
    f = figures([frame], lambda r: r["p"])["depth"]
    assert f["box_perpendicular_frac"] == 0.5            # the second box was not found
    assert f["cylinder_as_prism_frac"] == 0.0             # 0.04 is below the floor: no fact
    assert f["pairs"] == 3
    # pairs (0.9, true), (0, true), (0, false): bins 0.9 (|0.9 - 1| * 1/3) and 0.0 (|0 - 1/2| * 2/3)
    assert math.isclose(f["perpendicular_ece"], 0.1 / 3 + 1 / 3)


def test_real_rows_carry_their_share_of_the_weight():
    rows = [{"source": "render:realsense"}] * 90 + [{"source": "real:osd-learn"}] * 10
    w = row_weights(rows, 0.5)
    assert math.isclose(w.mean(), 1.0) and math.isclose(w[-10:].sum(), w[:90].sum())
    assert np.all(row_weights(rows[:90], 0.5) == 1.0)    # one kind only: equal weights


def test_predictions_during_the_fit_are_grounding_s():
    feats = ["logit_p", "logit_p*edge_scale2", "support"]
    rows = [_row(("a", "b"), p) | {"edge_scale2": e} for p in (0.1, 0.6, 0.99) for e in (0.5, 2.0, 40.0)]
    got = predict_rows(0.3, [1.5, -0.8, 0.4], feats, rows)
    table = {"depth": {"perpendicular": {"features": feats, "bias": 0.3, "coef": [1.5, -0.8, 0.4]}}}
    want = [calibrate_with(table, "depth", "perpendicular", r["p"], r) for r in rows]
    assert np.allclose(got, want)
