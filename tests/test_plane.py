import numpy as np

from lv3d.plane import Plane, angle_deg, dihedral_deg


def test_angle_between_planes_ignores_orientation():
    a = Plane.from_arrays([0, 0, -1], 1.0)
    b = Plane.from_arrays([0, np.sin(np.radians(30)), -np.cos(np.radians(30))], 1.0)
    flipped = Plane.from_arrays(-b.n, -b.offset)
    assert abs(angle_deg(a, b) - 30) < 1e-6 and abs(angle_deg(a, flipped) - 30) < 1e-6


def test_dihedral_of_adjacent_cube_faces_is_a_right_angle():
    assert abs(dihedral_deg(np.array([1.0, 0, 0]), np.array([0, 0, 2.0])) - 90) < 1e-9
