import numpy as np

from lv3d.plane import Plane, angle_deg, dihedral_deg


def test_angle_between_planes_ignores_orientation():
    a = Plane.from_arrays([0, 0, -1], 1.0)
    b = Plane.from_arrays([0, np.sin(np.radians(30)), -np.cos(np.radians(30))], 1.0)
    flipped = Plane.from_arrays(-b.n, -b.offset)
    assert abs(angle_deg(a, b) - 30) < 1e-6 and abs(angle_deg(a, flipped) - 30) < 1e-6


def test_dihedral_of_adjacent_cube_faces_is_a_right_angle():
    assert abs(dihedral_deg(np.array([1.0, 0, 0]), np.array([0, 0, 2.0])) - 90) < 1e-9


def test_column_sums_and_means_are_numpys_bit_for_bit():
    """The einsum forms add each column in the order numpy's reduce does, at any length and either float width."""
    from lv3d.plane import column_means, column_sums

    rng = np.random.default_rng(0)
    for m in (1, 2, 7, 100, 1001, 8000, 33333):
        for dtype in (np.float64, np.float32):
            v = (rng.standard_normal((m, 3)) * [1e-3, 0.3, 50.0] + [0.0, -0.2, 0.9]).astype(dtype)
            assert column_sums(v).dtype == dtype and column_means(v).dtype == dtype
            assert column_sums(v).tobytes() == v.sum(axis=0).tobytes()
            assert column_means(v).tobytes() == v.mean(axis=0).tobytes()
    strided = rng.standard_normal((500, 6))[::2, 1:4]  # rows and columns taken from a larger array
    assert column_means(strided).tobytes() == strided.mean(axis=0).tobytes()
