"""Colour faces seen edge-on that rgbd fusion keeps without a plane of their own (perception/edge_on.py): points
dropped as flying, or a sliver on a depth plane no colour face claimed."""
import numpy as np

from lv3d.perception.cloud import PointGrid
from lv3d.perception.edge_on import on_unclaimed_plane, points_dropped
from lv3d.perception.perceive import _reliable
from lv3d.perception.polygons import rasterize
from lv3d.perception.rgb import RGBFace
from lv3d.scene import Face

STRIP = np.array([[20.0, 10.0], [26.0, 10.0], [26.0, 90.0], [20.0, 90.0]])   # 6 px wide, 80 px long
SQUARE = np.array([[40.0, 10.0], [80.0, 10.0], [80.0, 50.0], [40.0, 50.0]])  # 40 px wide
DEPTH = np.full((100, 100), 1.0)                                              # every pixel read, metres
OBJECT = np.ones((50, 50), bool)


def _grid(points: np.ndarray) -> PointGrid:
    """A 50 x 50 grid of stride 2 over the 100 x 100 px image, with points where ``points`` (50, 50) is True."""
    xyz = np.zeros((50, 50, 3), np.float32)
    xyz[..., 2] = 1.0
    return PointGrid(xyz, np.zeros_like(xyz), points, 2)


def _dropped_strip() -> np.ndarray:
    points = np.ones((50, 50), bool)
    points[:, 10:13] = False                  # pixels u = 20..25 read, their points dropped as flying
    return points


def test_a_sliver_read_but_without_points_on_the_object_is_seen_edge_on():
    assert points_dropped(STRIP, DEPTH, _grid(_dropped_strip()), OBJECT)
    assert not points_dropped(STRIP, DEPTH, _grid(np.ones((50, 50), bool)), OBJECT)   # points: print or shading
    assert not points_dropped(STRIP, DEPTH, _grid(_dropped_strip()), ~OBJECT)         # off the object
    unread = DEPTH.copy()
    unread[:, 20:26] = 0.0                    # no reading at all: a sensor's grazing-angle hole (holes.py's)
    assert not points_dropped(STRIP, unread, _grid(_dropped_strip()), OBJECT)


def test_a_wide_face_or_a_hairline_is_not_a_face_seenpoints_dropped():
    none = _grid(np.zeros((50, 50), bool))
    assert not points_dropped(SQUARE, DEPTH, none, OBJECT)
    hair = np.array([[20.0, 10.0], [21.5, 10.0], [21.5, 90.0], [20.0, 90.0]])
    assert not points_dropped(hair, DEPTH, none, OBJECT)


def test_the_colour_only_floor_spares_exempt_faces():
    big = Face("", SQUARE * 4, "rgbd")
    small = Face("", STRIP, "rgb")
    assert _reliable([big, small]) == [0]
    assert _reliable([big, small], {1}) == [0, 1]


def test_a_sliver_on_a_plane_no_colour_face_has_is_a_face_not_print():
    strip_px = rasterize(STRIP, (100, 100))
    plane_px = [rasterize(SQUARE, (100, 100)), rasterize(STRIP * [1.0, 1.0] + [-2.0, 0.0], (100, 100))]
    sliver = RGBFace(STRIP, frozenset(), 0.95, 480.0)
    assert on_unclaimed_plane(sliver, strip_px, plane_px, claimed={0})      # the plane under it: unclaimed
    assert not on_unclaimed_plane(sliver, strip_px, plane_px, claimed={1})  # a colour face has it: print
    weak = RGBFace(STRIP, frozenset(), 0.7, 480.0)                             # outline off the image edges
    assert not on_unclaimed_plane(weak, strip_px, plane_px, claimed=set())
    wide = RGBFace(SQUARE, frozenset(), 0.95, 1600.0)
    assert not on_unclaimed_plane(wide, rasterize(SQUARE, (100, 100)), plane_px, claimed={1})
