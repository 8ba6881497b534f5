"""benchmarks/corner_turns: how far a closed outline turns at each vertex, in the image (2D) and on a plane (3D)."""

import numpy as np

from benchmarks.corner_turns import turns_deg


def test_a_square_turns_90_degrees_at_every_corner_and_a_point_on_a_side_not_at_all():
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    np.testing.assert_allclose(turns_deg(square), 90.0)
    with_point = np.insert(square, 1, [1.0, 0.0], axis=0)
    np.testing.assert_allclose(turns_deg(with_point), [90.0, 0.0, 90.0, 90.0, 90.0], atol=1e-9)


def test_turns_on_a_plane_are_those_of_the_shape_whatever_its_orientation():
    hexagon = np.stack([np.cos(np.arange(6) * np.pi / 3), np.sin(np.arange(6) * np.pi / 3), np.zeros(6)], 1)
    a = np.radians(50)
    tilt = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    np.testing.assert_allclose(turns_deg(hexagon @ tilt.T + [0.1, 0.2, 0.7]), 60.0)
