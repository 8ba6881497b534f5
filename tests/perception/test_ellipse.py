"""The colour path's ellipse test of a face's outline (lv3d/perception/rgb/ellipse.py) and the ``elliptical`` fact."""

import math

import cv2
import numpy as np
import pytest

from lv3d.describe import ellipse_candidates
from lv3d.perception.rgb.ellipse import (EllipseSettings, elliptical_probability, fit_outline, measure_face,
                                         outline_points)
from lv3d.perception.polygons import clockwise
from lv3d.scene import Face

SIZE = (240, 320)


def _draw(contour: np.ndarray) -> np.ndarray:
    """A 1-px edge map (H, W) uint8 of the closed ``contour`` (n, 2) pixels, as Canny draws a step's edge."""
    img = np.zeros(SIZE, np.uint8)
    cv2.polylines(img, [np.round(contour).astype(np.int32)], True, 255, 1)
    return img


def _ellipse(a: float, b: float, angle_deg: float = 0.0, n: int = 720) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    x, y = a * np.cos(t), b * np.sin(t)
    return np.stack([160 + c * x - s * y, 120 + s * x + c * y], axis=1)


def _regular(n: int, r: float, squash: float = 1.0, turn_deg: float = 10.0) -> np.ndarray:
    t = np.radians(turn_deg) + 2 * np.pi * np.arange(n) / n
    return np.stack([160 + r * np.cos(t), 120 + squash * r * np.sin(t)], axis=1)


def _polygon_of(contour: np.ndarray, n: int = 8) -> np.ndarray:
    """A polygon of ``n`` points of the curve ``contour``, as the colour path outlines a lid or a ball."""
    return clockwise(contour[:: len(contour) // n])


def _noisy(edges: np.ndarray, seed: int, share: float = 0.5) -> np.ndarray:
    """``edges`` with each edge pixel moved by one pixel up/down/left/right with probability ``share``."""
    rng = np.random.default_rng(seed)
    v, u = np.nonzero(edges)
    move = rng.random(len(u)) < share
    step = rng.integers(-1, 2, size=(len(u), 2)) * move[:, None]
    out = np.zeros_like(edges)
    out[np.clip(v + step[:, 1], 0, SIZE[0] - 1), np.clip(u + step[:, 0], 0, SIZE[1] - 1)] = 255
    return out


@pytest.mark.parametrize("a,b,angle,n", [(60, 60, 0, 8), (70, 35, 20, 6), (40, 25, -50, 10), (60, 50, 5, 12)])
def test_a_circle_or_ellipse_outlined_as_a_polygon_is_elliptical(a, b, angle, n):
    contour = _ellipse(a, b, angle)
    poly = _polygon_of(contour, n)
    e = measure_face(poly, _draw(contour))
    assert e is not None
    assert e.axes[0] == pytest.approx(max(a, b), rel=0.05) and e.axes[1] == pytest.approx(min(a, b), rel=0.05)
    assert e.rms_px < e.polygon_rms_px
    assert elliptical_probability(e) > 0.9


@pytest.mark.parametrize("n,squash", [(4, 1.0), (4, 0.6), (6, 1.0), (6, 0.55), (5, 0.8), (3, 1.0), (8, 1.0), (8, 0.6)])
def test_polygons_are_not_elliptical(n, squash):
    poly = _regular(n, 60, squash)
    e = measure_face(poly, _draw(poly))
    p = elliptical_probability(e)
    assert p is None or p < 0.05  # no fact (describe drops what is below 0.05)


@pytest.mark.parametrize("seed", range(3))
def test_noisy_outlines_keep_their_kind(seed):
    circle = _ellipse(55, 45, 30)
    e = measure_face(_polygon_of(circle), _noisy(_draw(circle), seed))
    assert elliptical_probability(e) > 0.5
    for n in (4, 6):
        poly = _regular(n, 55, 0.8)
        p = elliptical_probability(measure_face(poly, _noisy(_draw(poly), seed)))
        assert p is None or p < 0.05


def test_stray_edge_pixels_in_the_band_do_not_make_a_square_elliptical():
    poly = _regular(4, 60, 1.0, turn_deg=45)
    edges = _draw(poly)
    rng = np.random.default_rng(0)
    pts = poly[rng.integers(0, 4, 40)] + rng.normal(0, 6, (40, 2))
    edges[np.clip(pts[:, 1].astype(int), 0, SIZE[0] - 1), np.clip(pts[:, 0].astype(int), 0, SIZE[1] - 1)] = 255
    p = elliptical_probability(measure_face(poly, edges))
    assert p is None or p < 0.05


@pytest.mark.parametrize("points", [np.zeros((0, 2)), np.array([[1.0, 2.0]]),
                                    np.array([[0, 0], [1, 1], [2, 0], [1, 3.0]]), np.array([[10.0, 10.0]] * 30), np.array([[float("nan"), 1.0]] * 30),
                                    np.stack([np.arange(30.0), 2 * np.arange(30.0)], axis=1)],
                         ids=["none", "one", "four", "one-point-repeated", "nan", "a-line"])
def test_degenerate_outlines_give_no_fit_and_no_fact(points):
    poly = _regular(6, 30)
    e = fit_outline(poly, points)
    assert e is None and elliptical_probability(e) is None
    assert ellipse_candidates(Face("o_f1", poly, "rgb", ellipse=e)) == []


def test_degenerate_polygons_and_empty_edge_maps_give_no_fit():
    edges = _draw(_ellipse(40, 30))
    assert measure_face(np.zeros((0, 2)), edges) is None
    assert measure_face(np.array([[1.0, 1.0], [2.0, 2.0]]), edges) is None
    assert measure_face(np.array([[5.0, 5.0], [5.0, 5.0], [5.0, 5.0]]), edges) is None
    assert measure_face(_regular(6, 40), np.zeros(SIZE, np.uint8)) is None
    assert len(outline_points(np.full((4, 2), np.nan), edges)) == 0
    far = _regular(4, 20) + 1000.0  # outside the image
    assert measure_face(far, edges) is None


def test_a_partial_arc_is_no_ellipse():
    # edge pixels along a third of a circle only: an ellipse through them is not the face's outline
    contour = _ellipse(50, 50)
    edges = np.zeros(SIZE, np.uint8)
    arc = contour[:240]
    edges[np.round(arc[:, 1]).astype(int), np.round(arc[:, 0]).astype(int)] = 255
    assert measure_face(_polygon_of(contour), edges) is None


def test_the_fact_carries_a_measured_confidence():
    contour = _ellipse(60, 40, 15)
    poly = _polygon_of(contour)
    e = measure_face(poly, _draw(contour))
    [(pred, args, conf, value)] = ellipse_candidates(Face("o_f1", poly, "rgb", ellipse=e))
    assert pred == "elliptical" and args == ("o_f1",) and 0.05 <= conf <= 1.0
    assert value == pytest.approx(e.log_ratio, abs=1e-3)
    # a stricter setting lowers the confidence: it is a function of the measurement, not a constant
    strict = EllipseSettings(log_ratio_mid=e.log_ratio)
    assert elliptical_probability(e, strict) < elliptical_probability(e)
    assert math.isfinite(e.rel_rms) and math.isfinite(e.log_ratio)
