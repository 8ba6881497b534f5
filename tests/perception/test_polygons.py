import numpy as np

from lv3d.perception.polygons import (area, clockwise, is_simple, merge_close_corners, rasterize, sample_boundary,
                                      signed_area, simplify)


def test_simplify_keeps_only_true_corners():
    square = np.array([[0, 0], [50, 0.4], [100, 0], [100, 60], [100, 100], [0, 100], [0, 40]], float)
    out = simplify(square)
    assert len(out) == 4
    assert area(out) == np.float64(area(out)) and abs(area(out) - 10000) < 100


def test_simplify_keeps_a_pentagon():
    ang = np.radians(np.arange(5) * 72 - 90)
    pent = np.stack([100 + 60 * np.cos(ang), 100 + 60 * np.sin(ang)], 1)
    assert len(simplify(pent)) == 5


def test_is_simple_rejects_a_bow_tie():
    assert is_simple(np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float))
    assert not is_simple(np.array([[0, 0], [10, 10], [10, 0], [0, 10]], float))


def test_clockwise_in_the_image_has_positive_area():
    p = np.array([[0, 0], [0, 10], [10, 10], [10, 0]], float)  # anticlockwise with v down
    assert signed_area(p) < 0
    assert signed_area(clockwise(p)) > 0


def test_rasterize_counts_the_inside():
    m = rasterize(np.array([[2, 2], [11, 2], [11, 11], [2, 11]], float), (20, 20))
    assert m.sum() == 100


def test_sample_boundary_steps_along_every_side():
    tri = np.array([[0, 0], [10, 0], [0, 4.5]], float)
    pts = sample_boundary(tri, 1.0)
    # ceil(side / step) samples per side, starting at each vertex: 10 + 11 + 5
    assert len(pts) == 10 + int(np.ceil(np.hypot(10, 4.5))) + 5
    np.testing.assert_allclose(pts[:10], np.stack([np.arange(10.0), np.zeros(10)], axis=1))
    np.testing.assert_allclose(pts[-5:], np.stack([np.zeros(5), 4.5 - 0.9 * np.arange(5)], axis=1))


def test_simplify_removes_the_least_deviating_vertex_first():
    # two candidates: the near-collinear one goes, the true corner of the triangle-with-a-bump stays
    poly = np.array([[0, 0], [50, 1], [100, 0], [50, 80]], float)
    np.testing.assert_allclose(simplify(poly), [[0, 0], [100, 0], [50, 80]])


def test_merge_close_corners_joins_a_cut_tip():
    # a sliver's sharp tip traced as two corners 1.9 px apart whose sides cross 5 px away: one corner, midway
    sliver = np.array([[299.4, 214.8], [301.1, 215.7], [310.8, 241.6], [309.6, 265.4], [301.8, 243.8]])
    out = merge_close_corners(sliver, 3.0)
    assert len(out) == 4
    assert np.allclose(out[0], [300.25, 215.25])
    # corners 2 px apart whose sides cross within 3 px: the crossing
    square = np.array([[0, 0], [40, 0], [40, 39], [39, 40], [0, 40]], float)
    assert np.allclose(merge_close_corners(square, 3.0), [[0, 0], [40, 0], [40, 40], [0, 40]])


def test_merge_close_corners_keeps_sides_it_can_measure():
    strip = np.array([[0, 0], [100, 0], [100, 3.5], [0, 3.5]])  # a hairline's short ends are real sides
    assert len(merge_close_corners(strip, 3.0)) == 4
    tiny = np.array([[0, 0], [2, 0], [1, 1]], float)  # never fewer than three corners
    assert len(merge_close_corners(tiny, 3.0)) == 3


def test_polygon_fast_forms_are_numpys_general_calls_bit_for_bit():
    """following / preceding are np.roll's arrays, pair_dots the two products added as numpy's sum adds them, and
    distance_to_segments the numbers of its general form (sums over an axis two long, a squared offset)."""
    from lv3d.perception.polygons import distance_to_segments, following, pair_dots, preceding

    rng = np.random.default_rng(3)
    for n in (1, 3, 4, 9, 40):
        p = rng.uniform(-300, 300, (n, 2))
        np.testing.assert_array_equal(following(p), np.roll(p, -1, axis=0))
        np.testing.assert_array_equal(preceding(p), np.roll(p, 1, axis=0))
        np.testing.assert_array_equal(following(p[:, 0]), np.roll(p[:, 0], -1))
        q = rng.uniform(-300, 300, (25, 2))
        steps = following(p) - p
        rel = q[:, None, :] - p[None]
        assert pair_dots(rel, steps[None]).tobytes() == (rel * steps[None]).sum(-1).tobytes()
        t = np.clip((rel * steps[None]).sum(-1) / np.maximum((steps * steps).sum(-1), 1e-12), 0.0, 1.0)
        want = np.sqrt(((rel - t[..., None] * steps[None]) ** 2).sum(-1)).min(axis=1)
        assert distance_to_segments(q, p, steps).tobytes() == want.tobytes()


def test_chromaticity_is_the_share_of_the_channel_sum():
    from lv3d.perception.rgb.background import chromaticity

    color = np.random.default_rng(4).integers(0, 256, (30, 40, 3), dtype=np.uint8)
    color[0, 0] = 0
    c = color.astype(np.float32)
    want = c[..., :2] / np.maximum(c.sum(axis=2, keepdims=True), 1.0)
    assert chromaticity(color).tobytes() == want.tobytes()
