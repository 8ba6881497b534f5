import numpy as np

from lv3d.camera import Intrinsics
from lv3d.perception.depth.snap import snap_polygon
from lv3d.plane import Plane
from lv3d.scene import Face, Scene, SceneObject

K = Intrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)
FACE = Plane.from_arrays(np.array([0.0, 0.0, 1.0]), -1.0)      # z = 1 m: pixels u, v <-> x, y = (u - 320) / 500
SIDE = Plane.from_arrays(np.array([1.0, 0.0, 0.0]), -0.1)      # x = 0.1 m: meets FACE along image column u = 370


def test_side_along_a_neighbour_moves_onto_the_intersection_and_cut_corners_go():
    # traced outline: right side 6 px short of the shared edge, top-left corner rounded off by a short side
    traced = np.array([[276.0, 192.0], [364.0, 192.0], [364.0, 288.0], [272.0, 288.0], [272.0, 196.0]])
    out = snap_polygon(traced, FACE, [SIDE], K, near_m=0.02)
    assert len(out) == 4
    expect = np.array([[272.0, 192.0], [370.0, 192.0], [370.0, 288.0], [272.0, 288.0]])
    d = np.linalg.norm(out[:, None, :] - expect[None, :, :], axis=2)
    assert d.min(axis=1).max() < 1e-6


def test_far_planes_leave_the_outline_alone():
    traced = np.array([[272.0, 192.0], [364.0, 192.0], [364.0, 288.0], [272.0, 288.0]])
    far = Plane.from_arrays(np.array([1.0, 0.0, 0.0]), -0.5)
    out = snap_polygon(traced, FACE, [far], K, near_m=0.02)
    np.testing.assert_allclose(out, traced)


def test_target_is_the_object_at_the_image_centre_not_the_largest():
    big_aside = SceneObject("s_o1", pixel_count=40000, centroid_px=(150.0, 300.0))
    centred = SceneObject("s_o2", pixel_count=6000, centroid_px=(330.0, 236.0))
    for o in (big_aside, centred):
        o.faces = [Face(o.id + "_f1", np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]), "depth")]
    assert Scene("s", "depth", K, objects=[big_aside, centred]).target() is centred
    faceless = SceneObject("s_o3", pixel_count=6000, centroid_px=(320.0, 240.0))
    assert Scene("s", "depth", K, objects=[big_aside, faceless]).target() is big_aside
