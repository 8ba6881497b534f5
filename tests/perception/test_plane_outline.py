import numpy as np

from lv3d.camera import Intrinsics
from lv3d.perception.depth.plane_outline import lift, simplify_on_plane
from lv3d.perception.depth.snap import add_triple_corners
from lv3d.plane import Plane

K = Intrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)


def _strip(plane_normal, corners_3d):
    plane = Plane.from_arrays(plane_normal, -float(np.asarray(plane_normal) @ corners_3d[0]))
    return plane, K.project(corners_3d)


def test_lift_recovers_in_plane_lengths_of_an_edge_on_face():
    # a 10 cm x 2 cm strip on a plane turned 80 degrees away from the camera: squeezed to a few pixels wide
    t = np.radians(80.0)
    n = np.array([np.sin(t), 0.0, -np.cos(t)])
    a = np.array([np.cos(t), 0.0, np.sin(t)])                  # in-plane, across the strip
    c = np.array([0.0, 0.0, 0.6])
    corners = np.array([c, c + 0.02 * a, c + 0.02 * a + [0, 0.1, 0], c + [0, 0.1, 0]])
    plane, img = _strip(n, corners)
    width_px = np.linalg.norm(img[1] - img[0])
    assert width_px < 6.0                                     # squeezed in the image
    uv = lift(img, plane, K)
    sides = np.linalg.norm(np.roll(uv, -1, axis=0) - uv, axis=1)
    np.testing.assert_allclose(sorted(sides), [0.02, 0.02, 0.1, 0.1], atol=1e-6)


def test_simplify_on_plane_drops_a_bend_but_keeps_the_short_sides_of_a_strip():
    t = np.radians(75.0)
    n = np.array([np.sin(t), 0.0, -np.cos(t)])
    a = np.array([np.cos(t), 0.0, np.sin(t)])
    c = np.array([0.0, -0.05, 0.6])
    y = np.array([0.0, 1.0, 0.0])
    # a 2 cm x 10 cm strip traced with a spurious vertex 0.5 mm off the middle of one long side
    corners = np.array([c, c + 0.05 * y + 0.0005 * a, c + 0.1 * y, c + 0.1 * y + 0.02 * a, c + 0.02 * a])
    plane, img = _strip(n, corners)
    out = simplify_on_plane(img, plane, K)
    assert len(out) == 4
    truth = K.project(corners[[0, 2, 3, 4]])
    d = np.linalg.norm(out[:, None, :] - truth[None, :, :], axis=2)
    assert d.min(axis=1).max() < 1e-6
    # a true quadrilateral is left as it is
    assert simplify_on_plane(truth, plane, K) is truth


def test_triple_corner_puts_back_a_corner_cut_off_a_thin_face():
    # a box corner at (-0.1, -0.1, 1) m: faces x = -0.1, y = -0.1 and z = 1 (pixel (270, 190))
    px = Plane.from_arrays([1.0, 0.0, 0.0], 0.1)
    py = Plane.from_arrays([0.0, 1.0, 0.0], 0.1)
    pz = Plane.from_arrays([0.0, 0.0, -1.0], 1.0)
    corner = K.project(np.array([[-0.1, -0.1, 1.0]]))[0]
    np.testing.assert_allclose(corner, [270.0, 190.0])
    # the thin front face (10 px wide) traced as a triangle: its hull cut the corner off
    tri = np.array([[280.0, 190.0], [280.0, 290.0], [270.0, 290.0]])
    polys = add_triple_corners([tri, None, None], [pz, px, py], [(0, 1), (0, 2), (1, 2)], K)
    assert len(polys[0]) == 4
    assert np.min(np.linalg.norm(polys[0] - corner, axis=1)) < 1e-6
    # without the two neighbours being adjacent there is no corner to put back
    same = add_triple_corners([tri, None, None], [pz, px, py], [(0, 1), (0, 2)], K)
    np.testing.assert_allclose(same[0], tri)
    # nor when the corner lies far outside the outline (another face's corner)
    far = tri + [40.0, 0.0]
    np.testing.assert_allclose(add_triple_corners([far, None, None], [pz, px, py], [(0, 1), (0, 2), (1, 2)], K)[0], far)
