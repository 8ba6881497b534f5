"""A depth plane's mask as an image polygon, and a polygon grown outward (boundary.py)."""
import numpy as np

from lv3d.perception.boundary import grow_convex, mask_polygon
from lv3d.perception.polygons import area, rasterize

from .conftest import mask_iou as _iou


def test_an_edge_on_face_keeps_the_corners_that_hold_its_area():
    # pentagonal prism 1007's end seen at 78 degrees (clean dev seed 1000): a lens 3100 px in area, 12 px wide, whose
    # outer corners lie 7 px off the chord of their neighbours and turn by under 12 degrees
    end = np.array([[245.0, 155.0], [269.0, 302.0], [267.0, 386.0], [252.0, 323.0], [238.0, 179.0]])
    mask = rasterize(end, (480, 640))
    poly = mask_polygon(mask, 1, (480, 640))
    assert len(poly) == 5                       # image-space simplification alone left a triangle (IoU 0.42)
    assert _iou(rasterize(poly, mask.shape), mask) > 0.85


def test_a_face_seen_square_on_gives_its_corners_only():
    square = np.array([[100.0, 100.0], [200.0, 104.0], [196.0, 204.0], [96.0, 200.0]])
    mask = rasterize(square, (480, 640))
    poly = mask_polygon(mask, 1, (480, 640))
    assert len(poly) == 4
    assert np.abs(poly[:, None, :] - square[None]).sum(-1).min(axis=0).max() < 2.5


def test_grow_convex_moves_every_side_outward():
    sq = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    grown = grow_convex(sq, 1.0)
    assert np.allclose(np.sort(grown, axis=0), np.sort(np.array([[-1, -1], [11, -1], [11, 11], [-1, 11]]), axis=0))
    assert abs(area(grown) - 144) < 1e-9


def test_grow_convex_keeps_a_sharp_corner_near_its_place():
    from lv3d.perception.polygons import clockwise

    sliver = clockwise(np.array([[0, 0], [100, 2], [0, 4]], float))  # a 2-degree tip at (100, 2)
    grown = grow_convex(sliver, 1.0)
    assert area(grown) > area(sliver)  # grown outward, not inward
    assert np.linalg.norm(grown - sliver, axis=1).max() <= 2.0 + 1e-9
