import numpy as np

from lv3d.perception.boundary import grow_convex
from lv3d.perception.depth.cloud import point_grid
from lv3d.perception.depth.stage import _support
from lv3d.perception.depth.face_plane import angle_deg, fit_face_plane, polygon_cells
from lv3d.perception.depth.objects import support_band
from lv3d.perception.polygons import area
from lv3d.plane import Plane

from .conftest import box_on_table


def _roof_grid():
    """A 'roof' seen head-on: two planes meeting along the column u = 80 of a 160 x 120 depth image."""
    from lv3d.camera import Intrinsics

    k = Intrinsics(200, 200, 79.5, 59.5, 160, 120)
    u = np.arange(160)[None, :].repeat(120, axis=0).astype(np.float32)
    # metres; inverse depth linear in u makes each half a plane (tilted about the vertical axis)
    depth = 1.0 / (1.0 - 0.003 * np.abs(u - 80))
    return point_grid(depth, k, stride=2), k


def test_polygon_cells_lie_inside_the_shrunk_polygon():
    poly = np.array([[10, 10], [40, 10], [40, 30], [10, 30]], float)
    cells = polygon_cells(poly, (60, 80), stride=2, shrink_px=2)
    u, v = cells[:, 1] * 2, cells[:, 0] * 2
    assert len(cells) and u.min() >= 12 and u.max() <= 38 and v.min() >= 12 and v.max() <= 28


def test_a_polygon_on_one_half_of_the_roof_gets_that_half_as_its_plane():
    grid, k = _roof_grid()
    fit = fit_face_plane(np.array([[90, 20], [150, 20], [150, 100], [90, 100]], float), grid)
    assert fit is not None
    plane, pts, rms = fit
    xyz = grid.xyz[grid.valid]
    right = xyz[xyz[:, 0] > 0.02]
    assert np.abs(plane.distance(right)).max() < 1e-3 and rms < 1e-3 and len(pts) > 100


def test_a_polygon_across_the_ridge_has_no_plane_of_its_own():
    grid, _ = _roof_grid()
    assert fit_face_plane(np.array([[40, 20], [120, 20], [120, 100], [40, 100]], float), grid) is None


def test_a_polygon_off_the_given_mask_has_no_plane():
    grid, _ = _roof_grid()
    mask = np.zeros(grid.shape, bool)
    mask[:, :20] = True  # only the far left columns belong to "the object"
    poly = np.array([[90, 20], [150, 20], [150, 100], [90, 100]], float)
    assert fit_face_plane(poly, grid, on_mask=mask) is None


def test_angle_between_planes_ignores_orientation():
    a = Plane.from_arrays([0, 0, -1], 1.0)
    b = Plane.from_arrays([0, np.sin(np.radians(30)), -np.cos(np.radians(30))], 1.0)
    assert abs(angle_deg(a, b) - 30) < 1e-6


def test_support_band_is_narrow_on_clean_depth_and_wider_on_noisy_depth():
    clean, _ = box_on_table()
    noisy, _ = box_on_table(noise_m=0.004, seed=3)
    bands = []
    for frame in (clean, noisy):
        grid = point_grid(frame.depth, frame.intrinsics, 2, normals=False)
        bands.append(support_band(grid, _support(grid, 0)))
    assert bands[0] <= 0.005 and bands[1] > 2 * bands[0]


def test_grow_convex_moves_every_side_outward():
    sq = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    grown = grow_convex(sq, 1.0)
    assert np.allclose(np.sort(grown, axis=0), np.sort(np.array([[-1, -1], [11, -1], [11, 11], [-1, 11]]), axis=0))
    assert abs(area(grown) - 144) < 1e-9


def test_a_face_seen_edge_on_stays_with_its_object():
    from lv3d.camera import Intrinsics
    from lv3d.perception.depth.objects import segment_objects

    k = Intrinsics(200, 200, 79.5, 59.5, 160, 120)
    depth = np.zeros((120, 160), np.float32)
    depth[30:90, 40:100] = 1.0
    # 5 grid columns (10 px) whose depth steps by 2.5 % per column: a face nearly along the line of sight
    for c in range(5):
        depth[30:90, 100 + 2 * c:102 + 2 * c] = 1.0 * 1.025 ** (c + 1)
    grid = point_grid(depth, k, stride=2, normals=False)
    strip = np.zeros(grid.shape, bool)
    strip[16:44, 50:55] = True
    without = segment_objects(grid, None, regrow=0)
    with_regrow = segment_objects(grid, None)
    assert len(without) == len(with_regrow) == 1
    assert np.count_nonzero(without[0].mask & strip) < 0.5 * strip.sum()
    assert np.count_nonzero(with_regrow[0].mask & strip) > 0.8 * strip.sum()


def test_grow_convex_keeps_a_sharp_corner_near_its_place():
    from lv3d.perception.polygons import clockwise

    sliver = clockwise(np.array([[0, 0], [100, 2], [0, 4]], float))  # a 2-degree tip at (100, 2)
    grown = grow_convex(sliver, 1.0)
    assert area(grown) > area(sliver)  # grown outward, not inward
    assert np.linalg.norm(grown - sliver, axis=1).max() <= 2.0 + 1e-9
