import cv2
import numpy as np

from lv3d.perception.polygons import area
from lv3d.perception.rgb.step_edge import fork_cut, side_cut, smoothed_gradients, step_cut, step_lines

# a cube's top and front faces traced as one outline: their shared edge runs from the outline's corner (40, 80)
# to a point in the middle of its right side, (160, 80), not to a corner
OUTLINE = np.array([[40.0, 30.0], [160.0, 30.0], [160.0, 170.0], [40.0, 170.0], [40.0, 80.0]])
TOP = np.array([[40.0, 30.0], [160.0, 30.0], [160.0, 80.0], [40.0, 80.0]])


def _grads(top_level: float, rest_level: float, noise: float = 4.0, ramp: float = 0.0, seed: int = 3,
           top: np.ndarray = TOP):
    """smoothed_gradients of a 200 x 200 image of ``rest_level`` with the polygon ``top`` at ``top_level``."""
    rng = np.random.default_rng(seed)
    img = np.full((200, 200), rest_level, np.float64)
    mask = np.zeros((200, 200), np.uint8)
    cv2.fillPoly(mask, [np.round(top).astype(np.int32)], 1)
    img[mask.astype(bool)] = top_level
    img += ramp * np.arange(200)[:, None] + rng.normal(0.0, noise, img.shape)
    chan = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (3, 3), 0)
    return smoothed_gradients([chan, chan, chan])


def test_a_faint_step_under_noise_is_cut_from_a_corner_to_a_side():
    # 5 grey levels apart under sensor noise of 4 levels: no pixel tells them apart, the line's mean does
    parts = step_cut(OUTLINE, _grads(125.0, 120.0), min_area_px=150.0)
    assert parts is not None
    assert sorted(round(area(p) / 100) for p in parts) == sorted([round(area(TOP) / 100),
                                                                 round((area(OUTLINE) - area(TOP)) / 100)])


def test_noise_alone_or_a_smooth_shading_ramp_is_not_cut():
    assert step_cut(OUTLINE, _grads(120.0, 120.0), min_area_px=150.0) is None
    # shading that changes by 1.2 levels a pixel steps across every line, but as much on the shifted lines
    ramp = _grads(20.0, 20.0, ramp=1.2)
    assert step_cut(OUTLINE, ramp, min_area_px=150.0, rel_step=0.0) is not None
    assert step_cut(OUTLINE, ramp, min_area_px=150.0) is None


def test_lines_measured_once_give_the_same_cut_under_either_test():
    grads = _grads(125.0, 120.0)
    lines = step_lines(OUTLINE, grads)
    for kw in ({}, {"rel_step": 10.0, "min_samples": 12}):
        a = step_cut(OUTLINE, grads, min_area_px=150.0, **kw)
        b = step_cut(OUTLINE, grads, min_area_px=150.0, lines=lines, **kw)
        assert (a is None) == (b is None)
        if a is not None:
            assert all(np.array_equal(x, y) for x, y in zip(a, b))


# a prism seen from above its side: the silhouette is a hexagon, its top and two sides meet at a fork (100, 80)
# whose three inner edges run to the hexagon's corners 0, 2 and 4
HEXAGON = np.array([[30.0, 60.0], [100.0, 20.0], [170.0, 60.0], [170.0, 160.0], [100.0, 190.0], [30.0, 160.0]])
FORK = np.array([100.0, 80.0])


def _fork_grads(levels: tuple[float, float, float], noise: float = 3.0, seed: int = 4):
    rng = np.random.default_rng(seed)
    img = np.zeros((220, 200), np.float64)
    h = HEXAGON
    for level, part in zip(levels, ([h[0], h[1], h[2], FORK], [h[2], h[3], h[4], FORK], [h[4], h[5], h[0], FORK])):
        mask = np.zeros(img.shape, np.uint8)
        cv2.fillPoly(mask, [np.round(np.asarray(part)).astype(np.int32)], 1)
        img[mask.astype(bool)] = level
    img += rng.normal(0.0, noise, img.shape)
    chan = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (3, 3), 0)
    return smoothed_gradients([chan, chan, chan])


def test_three_faces_of_one_colour_traced_as_their_silhouette_are_cut_at_their_fork():
    # 4 and 6 grey levels apart under noise of 3: too faint for the edge map, clear along each whole line
    parts = fork_cut(HEXAGON, _fork_grads((110.0, 104.0, 100.0)), min_area_px=150.0)
    assert parts is not None and len(parts) == 3
    assert all(np.hypot(*(p[-1] - FORK)) <= 3.0 for p in parts)
    assert sorted(len(p) for p in parts) == [4, 4, 4]
    assert abs(sum(area(p) for p in parts) - area(HEXAGON)) < 1.0


def test_a_silhouette_of_one_shade_or_a_concave_outline_has_no_fork():
    assert fork_cut(HEXAGON, _fork_grads((104.0, 104.0, 104.0)), min_area_px=150.0) is None
    notched = np.concatenate([HEXAGON[:3], [[120.0, 110.0]], HEXAGON[3:]])  # a reflex corner: not one solid's
    assert fork_cut(notched, _fork_grads((110.0, 104.0, 100.0)), min_area_px=150.0) is None


# a cube's top and front faces traced as one rectangle: their left sides and right sides run on in one line each,
# so the edge between them runs from a point of the left side, (40, 85), to a point of the right side, (160, 75)
RECTANGLE = np.array([[40.0, 30.0], [160.0, 30.0], [160.0, 170.0], [40.0, 170.0]])
SLANTED_TOP = np.array([[40.0, 30.0], [160.0, 30.0], [160.0, 75.0], [40.0, 85.0]])


def _side_grads(top_level: float, rest_level: float, noise: float = 4.0, ramp: float = 0.0):
    return _grads(top_level, rest_level, noise=noise, ramp=ramp, seed=5, top=SLANTED_TOP)


def test_a_faint_step_from_side_to_side_is_cut_where_no_corner_line_runs():
    # 10 grey levels apart on a noise-free render (clean dev seed 3000's cube, about 15): too faint for the edge
    # map, while the flat faces' own lines do not step at all
    grads = _side_grads(130.0, 120.0, noise=0.0)
    assert step_cut(RECTANGLE, grads, min_area_px=150.0) is None  # no line from a corner runs along the edge
    parts = side_cut(RECTANGLE, grads, min_area_px=150.0)
    assert parts is not None and [len(p) for p in parts] == [4, 4]
    ends = sorted((p for p in parts[0] if not any(np.array_equal(p, c) for c in RECTANGLE)), key=lambda p: p[0])
    assert np.hypot(*(ends[0] - [40.0, 85.0])) <= 2.0 and np.hypot(*(ends[1] - [160.0, 75.0])) <= 2.0
    assert abs(sum(area(p) for p in parts) - area(RECTANGLE)) < 1.0


def test_noise_alone_or_a_shading_ramp_is_not_cut_from_side_to_side():
    assert side_cut(RECTANGLE, _side_grads(120.0, 120.0), min_area_px=150.0) is None
    ramp = _side_grads(20.0, 20.0, ramp=1.2, noise=0.0)
    assert side_cut(RECTANGLE, ramp, min_area_px=150.0, rel_step=0.0) is not None
    assert side_cut(RECTANGLE, ramp, min_area_px=150.0) is None
