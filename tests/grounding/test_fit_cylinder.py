"""Cylinder refinement: a robust, depth-noise-weighted fit recovers a can's side from a rough first guess, with an
honest spread."""

import numpy as np
import pytest

import grounding

INTR = (600.0, 600.0, 320.0, 240.0)


def _can_side(rng, n=3000, radius=0.033, noise_m=0.002, arc_deg=150.0):
    """Points on the side of a can 0.9 m away that the camera sees (``arc_deg`` around its axis), depth noise
    ``noise_m``; its axis, a point on it, its radius."""
    axis = np.array([0.05, -0.99, 0.1])
    axis /= np.linalg.norm(axis)
    centre = np.array([0.02, 0.0, 0.9])
    towards = -centre - (-centre @ axis) * axis
    towards /= np.linalg.norm(towards)
    across = np.cross(axis, towards)
    th = np.radians(rng.uniform(-arc_deg / 2, arc_deg / 2, n))
    h = rng.uniform(-0.05, 0.05, n)
    pts = centre + h[:, None] * axis + radius * (np.cos(th)[:, None] * towards + np.sin(th)[:, None] * across)
    pts[:, 2] += rng.normal(0.0, noise_m, n)
    return pts, axis, centre, radius


def _angle_deg(a, b):
    return np.degrees(np.arccos(np.clip(abs(a @ b), -1, 1)))


def test_recovers_a_can_side_from_a_rough_first_guess():
    pts, axis, centre, radius = _can_side(np.random.default_rng(0))
    guess = axis + np.array([0.05, 0.0, 0.05])  # about 4 degrees off, 5 mm away, radius 10 % short
    fit = grounding.fit_cylinder(pts, guess, centre + np.array([0.005, 0.0, 0.005]), 0.9 * radius, intrinsics=INTR)
    assert int(fit.status) == 0
    assert _angle_deg(fit.axis, axis) < 1.0
    assert abs(float(fit.radius) - radius) < 0.03 * radius
    # the axis passes through the true axis: the true centre is within a millimetre of it
    d = centre - fit.point
    assert np.linalg.norm(d - (d @ fit.axis) * fit.axis) < 0.001
    # honest spreads: the error within a few of them, none tiny
    assert _angle_deg(fit.axis, axis) < 5 * np.degrees(fit.axis_std.max()) + 0.2
    assert np.all(fit.axis_std > 1e-5) and float(fit.radius_std) > 1e-6


def test_more_noise_a_wider_spread():
    stds = []
    for noise in (0.001, 0.006):
        pts, axis, centre, radius = _can_side(np.random.default_rng(1), noise_m=noise)
        fit = grounding.fit_cylinder(pts, axis, centre, radius, intrinsics=INTR)
        stds.append(float(fit.axis_std.max()))
    assert stds[1] > 2 * stds[0]


def test_stray_readings_do_not_pull_the_fit():
    rng = np.random.default_rng(2)
    pts, axis, centre, radius = _can_side(rng)
    stray = pts[:300] + np.array([0.0, 0.0, 0.05])  # a tenth of the readings 5 cm behind the surface
    fit = grounding.fit_cylinder(np.vstack([pts, stray]), axis, centre, radius, intrinsics=INTR)
    assert abs(float(fit.radius) - radius) < 0.05 * radius and _angle_deg(fit.axis, axis) < 2.0


def test_too_few_points_is_refused():
    with pytest.raises(ValueError, match="at least 6 points"):
        grounding.fit_cylinder(np.zeros((3, 3)), np.array([0.0, 1.0, 0.0]), np.zeros(3), 0.03, intrinsics=INTR)


def test_points_no_cylinder_can_fit_keep_the_first_guess():
    # a straight line of readings and readings that are not numbers: status 1 and the first guess, no exception
    line = np.zeros((50, 3))
    line[:, 0] = np.linspace(0.0, 0.1, 50)
    line[:, 2] = 1.0
    for pts in (line, np.full((20, 3), np.nan)):
        fit = grounding.fit_cylinder(pts, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.05]), 0.05,
                                     intrinsics=INTR)
        assert int(fit.status) == 1
        assert float(fit.radius) == pytest.approx(0.05) and np.allclose(fit.axis, [0.0, 1.0, 0.0])
