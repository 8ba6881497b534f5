"""grounding.Calibration and the maps lv3d ships (lv3d/data/calibration.json): monotone in the raw probability,
stay in (0, 1), leave unmapped predicates and impossible facts alone, read a fact's value in tolerances,
take a type's own final map (or none) over the pooled one, per-face types the per-face pooled one, chosen
without the pair types' rows; the file names its provenance and a malformed one is refused in one line;
pack_object picks the small padded shape for small objects."""

import math
from types import SimpleNamespace

import numpy as np

import pytest

import grounding
from grounding import calibrate_with
from grounding._confidence import ACUTE_BELOW_DEG, EQUAL_SIDES_RATIO, PERPENDICULAR_DEG
from grounding._problem import SIZES
from lv3d import calibration
from lv3d.describe import calibration_features, shared_side_px
from lv3d.errors import InputError

SHIPPED = calibration.read()
TABLE, FINAL = SHIPPED["table"], SHIPPED["final"]

MEASURES = {"support": 0.9, "log_area_px": 8.0, "min_turn_z": 6.0, "min_side_px": 40.0, "sides": 4, "faces": 3,
            "value": 1.05}


def test_every_shipped_map_grows_with_the_raw_probability():
    assert TABLE, "no calibration maps shipped"
    ps = np.linspace(0.01, 1.0, 25)
    for modality, maps in TABLE.items():
        for pred in maps:
            c = np.array([calibration.calibrate(modality, pred, p, MEASURES) for p in ps])
            assert np.all((c > 0) & (c < 1)), (modality, pred)
            assert np.all(np.diff(c) >= -1e-12), (modality, pred)


def test_unmapped_predicates_and_impossible_facts_keep_their_probability():
    assert calibration.calibrate("no-such-modality", "square", 0.7, MEASURES) == 0.7
    modality, maps = next(iter(TABLE.items()))
    assert calibration.calibrate(modality, next(iter(maps)), 0.0, MEASURES) == 0.0


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
    assert abs(conf("perpendicular", 90.0 + PERPENDICULAR_DEG / 2) - 0.5) < 1e-9
    # two tolerances inside the acute limit: 1 - 2
    assert abs(conf("acute", ACUTE_BELOW_DEG - 2 * PERPENDICULAR_DEG) - -1.0) < 1e-9
    assert abs(conf("square", 50.0) - 3.0) < 1e-9                     # clipped: 3 tolerances out at most


def test_calibration_features_carry_each_candidates_value():
    cands = [("square", ("f1",), 0.9, 1.05), ("rectangle", ("f1",), 0.8, 3.0), ("face_of", ("o1", "f1"), 1.0, None)]
    feats = calibration_features(cands, [])
    assert [f.get("value") for f in feats] == [1.05, 3.0, None]


def test_shared_side_is_the_longest_side_two_polygons_have_in_common():
    a = np.array([[0.0, 0.0], [30.0, 0.0], [30.0, 40.0], [0.0, 40.0]])
    edge = np.array([[30.0, 0.0], [60.0, 0.0], [60.0, 40.0], [30.0, 40.0]])   # shares a's side x = 30 (40 px)
    point = np.array([[30.0, 40.0], [60.0, 40.0], [60.0, 80.0]])               # touches a at one vertex
    across = np.array([[30.0, 0.0], [50.0, 20.0], [0.0, 40.0]])                # two shared vertices, not a side
    assert shared_side_px(a, edge) == 40.0 and shared_side_px(edge, a) == 40.0
    assert shared_side_px(a, point) == 0.0 and shared_side_px(a, across) == 0.0
    assert shared_side_px(a, a + 0.5) == 0.0


def test_calibration_features_give_a_pair_its_shared_side():
    from lv3d.describe import FaceResult, ObjectResult

    def face(fid, poly):
        return FaceResult(SimpleNamespace(id=fid), np.asarray(poly, float), None, np.zeros(len(poly)), dict(MEASURES))

    res = ObjectResult(SimpleNamespace(id="o1"), [face("f1", [[0, 0], [30, 0], [30, 40], [0, 40]]),
                                                  face("f2", [[30, 0], [60, 0], [60, 40], [30, 40]])], {}, 0, [])
    feats = calibration_features([("acute", ("f1", "f2"), 1.0, 60.0), ("acute", ("f2", "f1"), 1.0, 60.0),
                                  ("square", ("f1",), 0.9, 1.05)], [res])
    assert feats[0]["shared_side_px"] == feats[1]["shared_side_px"] == 40.0 and "shared_side_px" not in feats[2]
    assert "plane_gap_mm" not in feats[0]  # no planes: nothing to measure


def test_plane_gap_tells_two_pieces_of_one_face_from_two_faces():
    from lv3d.describe import FaceResult, plane_gap_mm

    rng = np.random.default_rng(0)

    def face(normal, offset, centre):  # points scattered on the plane n . x + d = 0 around centre
        n = np.asarray(normal, float) / np.linalg.norm(normal)
        u = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        pts = np.asarray(centre, float) + rng.uniform(-0.02, 0.02, (200, 1)) * u + rng.uniform(-0.02, 0.02, (200, 1)) * np.cross(n, u)
        pts -= np.outer(pts @ n + offset, n)  # onto the plane
        return FaceResult(SimpleNamespace(id="f", points=pts), np.zeros((4, 2)), np.r_[n, offset], np.zeros(4))

    top_left, top_right = face([0, -1, 0], 0.3, [-0.03, 0.3, 1.0]), face([0, -1, 0], 0.3, [0.03, 0.3, 1.0])
    lower = face([0, -1, 0], 0.35, [0.0, 0.35, 1.0])                  # parallel, 5 cm further down
    side = face([1, 0, 0], -0.05, [0.05, 0.33, 1.0])                   # perpendicular
    assert plane_gap_mm(top_left, top_right) < 1e-6
    assert abs(plane_gap_mm(top_left, lower) - 50.0) < 1e-6 and plane_gap_mm(lower, top_left) == plane_gap_mm(top_left, lower)
    assert plane_gap_mm(top_left, side) > 20.0
    assert plane_gap_mm(top_left, FaceResult(SimpleNamespace(id="g", points=None), np.zeros((3, 2)), None, np.zeros(3))) is None


def test_calibrate_is_calibrate_with_the_shipped_table():
    # Calibration keeps each map's inputs looked up; the numbers must be those of the general function
    for modality, maps in TABLE.items():
        for pred in maps:
            for p in (1e-6, 0.3, 0.97, 1.0):
                assert calibration.calibrate(modality, pred, p, MEASURES) == calibrate_with(TABLE, modality, pred, p, MEASURES, FINAL)
                assert calibration.calibrate(modality, pred, p) == calibrate_with(TABLE, modality, pred, p, None, FINAL)


def test_the_shipped_file_names_how_it_was_made_and_a_foreign_one_is_refused(tmp_path):
    prov = SHIPPED["provenance"]
    # the shipped maps were fitted before the fit became `lv3d calibrate fit`; the file keeps the command that
    # made it, and a refit records the new one
    assert prov["command"].startswith(("lv3d calibrate fit ", "python -m benchmarks.fit_calibration "))
    assert prov["data"] and prov["git_commit"]
    assert set(calibration.source_digests()) == set(calibration.SOURCES)
    assert set(calibration.stale_sources()) <= set(calibration.SOURCES)
    assert "perpendicular" in TABLE["rgbd"] and "perpendicular" in TABLE["depth"]
    bad = tmp_path / "calibration.json"
    bad.write_text('{"format": 0, "table": {}, "final": {}, "provenance": {}}')
    with pytest.raises(InputError, match="format 0, this code reads format"):
        calibration.read(bad)
    bad.write_text('{"format": %d, "table": {}}' % calibration.FORMAT)
    with pytest.raises(InputError, match="without its 'final' part"):
        calibration.read(bad)
    with pytest.raises(InputError, match="calibration file not found"):
        calibration.read(tmp_path / "absent.json")


def test_final_map_interpolates_its_knots_and_keeps_zero():
    final = {"rgbd": {"x": [0.2, 0.6, 0.6, 0.8], "y": [0.1, 0.3, 0.5, 0.7]}}  # a step at 0.6
    got = [calibrate_with({}, "rgbd", "triangle", p, None, final) for p in (0.0, 0.1, 0.4, 0.6, 0.7, 0.9)]
    assert np.allclose(got, [0.0, 0.1, 0.2, 0.5, 0.6, 0.7])
    for final in FINAL.values():
        own = [k for k in final.get("by_pred", {}).values() if isinstance(k, dict)]
        for knots in [final, *([final["faces"]] if "faces" in final else []), *own]:
            assert np.all(np.diff(knots["x"]) >= 0) and np.all(np.diff(knots["y"]) >= 0)


def test_a_type_takes_its_own_final_map_or_none_before_the_pooled_one():
    final = {"rgbd": {"x": [0.0, 1.0], "y": [0.2, 0.2],                 # pooled: everything to 0.2
                      "by_pred": {"square": {"x": [0.0, 1.0], "y": [0.5, 0.5]}, "parallel": None}}}
    got = {pred: calibrate_with({}, "rgbd", pred, 0.7, None, final) for pred in ("square", "parallel", "triangle")}
    assert got == {"square": 0.5, "parallel": 0.7, "triangle": 0.2}
    assert calibrate_with({}, "rgbd", "square", 0.0, None, final) == 0.0  # impossible stays impossible
    final["rgbd"]["faces"] = {"x": [0.0, 1.0], "y": [0.4, 0.4]}         # per-face pooled: everything to 0.4
    final["rgbd"]["by_pred"]["pentagon"] = "faces"
    assert calibrate_with({}, "rgbd", "pentagon", 0.7, None, final) == 0.4
    assert calibrate_with({}, "rgbd", "acute", 0.7, None, final) == 0.2


def test_pair_types_cannot_move_a_per_face_types_final_map():
    from lv3d.calibrate.fit import fit_final

    rng = np.random.default_rng(1)
    n = 2000
    seeds = np.repeat(np.arange(n // 10), 10)
    c = rng.uniform(0.05, 0.95, (3, n))
    oof = {"pentagon": (c[0], (rng.random(n) < c[0] ** 2).astype(float), seeds),
           "square": (c[1], (rng.random(n) < c[1]).astype(float), seeds),
           "acute": (c[2], (rng.random(n) < c[2]).astype(float), seeds)}
    final, losses = fit_final(oof)
    # the pair type's rows made over-confident: the every-type pooled map moves, the per-face choices do not
    moved, moved_losses = fit_final({**oof, "acute": (c[2], (rng.random(n) < c[2] ** 4).astype(float), seeds)})
    assert final["x"] != moved["x"] or final["y"] != moved["y"]
    for pred in ("pentagon", "square"):
        assert final["by_pred"][pred] == moved["by_pred"][pred] and losses[pred] == moved_losses[pred]
    assert final["faces"] == moved["faces"] and set(final["by_pred"]) >= {"pentagon", "square"}


def _square(x0, y0, s=40.0):
    return np.array([[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]], float)


def test_pack_object_uses_the_small_shape_when_the_object_fits():
    small, _ = grounding.pack_object([_square(100, 100), _square(140, 100)], intrinsics=(600.0, 600.0, 320.0, 240.0))
    assert small.face_index.shape == SIZES[0][:2] and small.vertices.shape[0] == SIZES[0][2]
    five = [_square(100 + 50 * i, 100) for i in range(SIZES[0][0] + 1)]
    big, index = grounding.pack_object(five, intrinsics=(600.0, 600.0, 320.0, 240.0))
    assert big.face_index.shape == SIZES[-1][:2] and index.shape == (len(five), SIZES[-1][1])


def test_one_side_fewer_has_maps_of_its_own():
    assert grounding.calibration_key("pentagon") == "pentagon"
    assert grounding.calibration_key("pentagon", fewer=True) == "pentagon_fewer"
    own = {"features": ["logit_p"], "bias": 0.0, "coef": [1.0]}
    fewer = {"features": ["logit_p"], "bias": -2.0, "coef": [1.0]}
    table = {"rgbd": {"pentagon": own, "pentagon_fewer": fewer}}
    final = {"rgbd": {"x": [0.0, 1.0], "y": [0.0, 1.0]}}
    p = 0.6
    assert math.isclose(calibrate_with(table, "rgbd", "pentagon", p, {}, final), p)
    # logit 0.6 = log 1.5, moved by the fewer map's bias -2
    assert math.isclose(calibrate_with(table, "rgbd", "pentagon_fewer", p, {}, final),
                        1 / (1 + math.exp(2 - math.log(1.5))))


def test_facts_about_faces_that_touch_at_a_point_have_maps_of_their_own():
    from lv3d.describe import FaceResult, ObjectResult, calibration_keys

    assert grounding.calibration_key("acute", shared_side_px=40.0) == "acute"
    assert grounding.calibration_key("acute", shared_side_px=0.0) == "acute_touch"
    assert grounding.calibration_key("parallel", shared_side_px=0.0) == "parallel"  # its map reads no shared side
    assert grounding.calibration_key("acute") == "acute"                             # nothing measured

    def face(fid, poly):
        return FaceResult(SimpleNamespace(id=fid), np.asarray(poly, float), None, np.zeros(len(poly)), dict(MEASURES))

    res = ObjectResult(SimpleNamespace(id="o1"), [face("f1", [[0, 0], [30, 0], [30, 40], [0, 40]]),
                                                  face("f2", [[30, 0], [60, 0], [60, 40], [30, 40]]),
                                                  face("f3", [[30, 40], [60, 40], [60, 80]])], {}, 0, [])
    cands = [("acute", ("f1", "f2"), 0.9, 60.0), ("acute", ("f3", "f1"), 0.9, 60.0),
             ("adjacent", ("f1", "f3"), 0.9, None), ("parallel", ("f1", "f3"), 0.9, 2.0)]
    assert calibration_keys(cands, [res]) == ["acute", "acute_touch", "adjacent_touch", "parallel"]
    table = {"rgbd": {"acute": {"features": ["logit_p"], "bias": 0.0, "coef": [1.0]},
                      "acute_touch": {"features": ["logit_p"], "bias": -2.0, "coef": [1.0]}}}
    assert math.isclose(calibrate_with(table, "rgbd", "acute", 0.6, {}), 0.6)
    assert math.isclose(calibrate_with(table, "rgbd", "acute_touch", 0.6, {}), 1 / (1 + math.exp(2 - math.log(1.5))))
    assert "acute_touch" in TABLE["rgbd"] and "perpendicular_touch" in TABLE["depth"]


def test_the_slope_on_logit_p_may_depend_on_the_faces_and_never_falls_below_zero():
    table = {"rgbd": {"perpendicular": {"features": ["logit_p", "logit_p*edge_scale2", "support"],
                                        "bias": 0.0, "coef": [2.0, -1.0, 0.5]}}}

    def conf(p, edge):
        return calibrate_with(table, "rgbd", "perpendicular", p, {"edge_scale2": edge, "support": 1.0})

    # slope 2 - log(edge_scale2): straight outlines (edge_scale2 1) trust p fully, ragged ones less
    assert math.isclose(conf(0.9, 1.0), 1 / (1 + math.exp(-(0.5 + 2 * math.log(9)))))
    assert math.isclose(conf(0.9, math.e), 1 / (1 + math.exp(-(0.5 + 1 * math.log(9)))))
    # past edge_scale2 e^2 the slope would turn negative: it is held at 0, p no longer matters
    assert math.isclose(conf(0.9, math.e ** 3), conf(0.2, math.e ** 3)) and math.isclose(conf(0.9, 50.0), 1 / (1 + math.exp(-0.5)))
    cal = grounding.Calibration(table)
    assert cal.calibrate("rgbd", "perpendicular", 0.9, {"edge_scale2": 2.0, "support": 1.0}) == conf(0.9, 2.0)
    assert cal.measures_used("rgbd", "perpendicular") == ["logit_p*edge_scale2", "support"]
