"""Colour outlines that went on across an edge without contrast (perceive._swallows_plane, _spans_planes)."""

from types import SimpleNamespace

import numpy as np

from lv3d.perception.perceive import _spans_planes, _swallows_plane
from lv3d.plane import Plane


def _object(*normals):
    return SimpleNamespace(planes=[SimpleNamespace(plane=Plane.from_arrays(n, -0.5)) for n in normals])


def _cols(c0, c1, shape=(20, 40)):
    m = np.zeros(shape, bool)
    m[:, c0:c1] = True
    return m


# two planes side by side in a 20 x 40 crop: plane 0 on columns 0-19, plane 1 on columns 20-39
LEFT, RIGHT = _cols(0, 20), _cols(20, 40)


def test_an_outline_round_two_faces_turned_apart_spans_them():
    o = _object([0, 0, -1], [1, 0, -1])  # 45 deg apart
    assert _spans_planes(_cols(0, 40), o, [LEFT, RIGHT])
    assert not _spans_planes(_cols(0, 27), o, [LEFT, RIGHT])  # a third of the second plane: not most of it
    assert not _spans_planes(_cols(0, 40), _object([0, 0, -1], [0.05, 0, -1]), [LEFT, RIGHT])  # one face in two


def test_a_matched_outline_swallows_a_quarter_of_a_plane_turned_away():
    o = _object([0, 0, -1], [1, 0, -1])
    assert _swallows_plane(_cols(0, 26), 0, o, [LEFT, RIGHT])       # 30% of plane 1
    assert not _swallows_plane(_cols(0, 22), 0, o, [LEFT, RIGHT])   # 10%: an outline that strays over the edge
    assert not _swallows_plane(_cols(0, 26), 0, _object([0, 0, -1], [0.05, 0, -1]), [LEFT, RIGHT])  # same plane
