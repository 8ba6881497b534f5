import cv2
import numpy as np

from lv3d.perception.polygons import area, drop_short_sides
from lv3d.perception.edges import channel_edges
from lv3d.perception.rgb.split import (_diagonal_samples, _mean_clear_of_outline, reflex_corners, split_by_diagonal,
                                   split_concave)


def gradient_magnitude(chans: list[np.ndarray]) -> np.ndarray:
    """The colour path's gradient for split.py (rgb.rgb_faces): the largest Sobel magnitude over the channels."""
    return np.maximum.reduce([channel_edges(c).magnitude for c in chans])


def _image(polys_colours, shape=(200, 200), background=90):
    img = np.full((*shape, 3), background, np.uint8)
    for poly, colour in polys_colours:
        cv2.fillPoly(img, [np.round(poly).astype(np.int32)], colour)
    return [np.ascontiguousarray(img[:, :, c]) for c in range(3)]


def test_a_non_convex_outline_splits_at_its_reflex_corner_along_the_faint_edge():
    # a cube's top and left faces in nearly one colour: their shared edge (80, 110)-(188, 135) is faint
    top = np.array([[80.0, 110.0], [155.0, 78.0], [260.0, 100.0], [188.0, 135.0]])
    left = np.array([[80.0, 110.0], [188.0, 135.0], [188.0, 262.0], [82.0, 228.0]])
    grad = gradient_magnitude(_image([(top, (200, 60, 60)), (left, (190, 60, 60))], shape=(300, 300)))
    outline = np.array([[80.0, 110.0], [155.0, 78.0], [260.0, 100.0], [188.0, 135.0], [188.0, 262.0],
                        [82.0, 228.0]])
    assert reflex_corners(outline) == [3]
    parts = split_concave(outline, grad, min_area_px=100.0)
    assert len(parts) == 2 and not any(reflex_corners(p) for p in parts)
    assert sorted(round(area(p)) for p in parts) == sorted([round(area(top)), round(area(left))])


def test_a_convex_outline_splits_only_where_the_image_has_an_edge():
    quad = np.array([[40.0, 40.0], [160.0, 40.0], [160.0, 160.0], [40.0, 160.0]])
    tri = np.array([[40.0, 40.0], [160.0, 160.0], [40.0, 160.0]])
    faint = gradient_magnitude(_image([(quad, (200, 60, 60)), (tri, (185, 60, 60))]))
    assert len(split_by_diagonal(quad, faint, min_area_px=100.0)) == 2
    flat = gradient_magnitude(_image([(quad, (200, 60, 60))]))
    assert len(split_by_diagonal(quad, flat, min_area_px=100.0)) == 1


def test_a_faint_edge_under_sensor_noise_is_cut_and_noise_alone_is_not():
    # two faces 14 grey levels apart under Gaussian sensor noise (sigma 4 levels, as the realsense preset), lightly
    # blurred as edges.channels does: the diagonal's mean gradient is about twice the interior's 90th percentile
    quad = np.array([[40.0, 40.0], [160.0, 40.0], [160.0, 160.0], [40.0, 160.0]])
    tri = np.array([[40.0, 40.0], [160.0, 160.0], [40.0, 160.0]])
    rng = np.random.default_rng(3)
    for lower, cuts in ((186, 2), (200, 1)):
        img = np.full((200, 200, 3), 90.0)
        cv2.fillPoly(img, [quad.astype(np.int32)], (200, 60, 60))
        cv2.fillPoly(img, [tri.astype(np.int32)], (lower, 60, 60))
        noisy = cv2.GaussianBlur(np.clip(img + rng.normal(0.0, 4.0, img.shape), 0, 255).astype(np.uint8), (3, 3), 0)
        grad = gradient_magnitude([np.ascontiguousarray(noisy[:, :, c]) for c in range(3)])
        assert len(split_by_diagonal(quad, grad, min_area_px=100.0)) == cuts


def test_a_corner_traced_as_two_goes_back_to_one():
    square = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [4.0, 100.0], [0.0, 96.0]])
    out = drop_short_sides(square)
    assert len(out) == 4
    assert np.abs(out - np.array([0.0, 100.0])).sum(axis=1).min() < 1e-9
    pentagon = np.array([[50.0, 0.0], [100.0, 36.0], [81.0, 95.0], [19.0, 95.0], [0.0, 36.0]])
    assert len(drop_short_sides(pentagon)) == 5  # real sides stay


def test_a_diagonal_running_close_along_the_outline_is_not_taken_for_an_edge():
    # a flat hexagon whose top corner lies 7 px off the diagonal below it (from hexagonal prism, dev seed 2001):
    # near its ends that diagonal runs within a pixel of the outline's own edge, which must not count for a cut
    hexagon = np.array([[315.0, 211.0], [348.0, 221.0], [338.0, 238.0], [289.0, 243.0], [256.0, 231.0],
                        [271.0, 215.0]])
    # the hexagon's lower sides border a face of nearly its colour; only its top sides have contrast
    below = np.array([[200.0, 213.0], [400.0, 222.0], [400.0, 300.0], [200.0, 300.0]])
    grad = gradient_magnitude(_image([(below, (225, 195, 245)), (hexagon, (230, 200, 250))], shape=(300, 400),
                                     background=20))
    assert len(split_by_diagonal(hexagon, grad, min_area_px=150.0)) == 1


def test_a_diagonal_within_a_blurred_edge_of_the_outline_has_no_strength_measured_clear_of_it():
    # the diagonal from corner 0 to corner 2 passes 1.9 px from corner 1: all along it lies within 2.5 px of the
    # outline, inside the blurred silhouette edge (sigma 1 px); measured 1 px clear it picks up that edge, which
    # is why split_by_diagonal's fainter test measures 2.5 px clear
    poly = np.array([[20.0, 60.0], [70.0, 38.0], [120.0, 20.0], [130.0, 90.0], [30.0, 100.0]])
    img = np.full((130, 160), 60.0)
    cv2.fillPoly(img, [np.round(poly).astype(np.int32)], 160)
    grad = gradient_magnitude([cv2.GaussianBlur(img, (0, 0), 1.0).astype(np.uint8)])
    samples = _diagonal_samples(poly, [(0, 2), (1, 3)], grad)
    shallow, across = _mean_clear_of_outline(2, *samples, clear_px=2.5)
    assert shallow == 0.0 and across < 5.0
    assert _mean_clear_of_outline(2, *samples, clear_px=1.0)[0] > 50.0
