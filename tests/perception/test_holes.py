import cv2
import numpy as np

from lv3d.perception.edges import channel_edges, channels, edge_distance
from lv3d.perception.holes import hole_faces
from lv3d.perception.polygons import rasterize

from .conftest import mask_iou as _iou

SHAPE = (200, 240)
# the object's faces that depth saw, and beside them a strip seen nearly edge-on, with no depth reading
OBJECT = np.array([(80, 40), (180, 50), (175, 160), (85, 150)], float)
STRIP = np.array([(62, 45), (80, 40), (85, 150), (70, 148)], float)


def _dist(strip_colour=(60, 20, 20)) -> np.ndarray:
    img = np.full(SHAPE + (3,), (200, 190, 170), np.uint8)
    cv2.fillPoly(img, [OBJECT.astype(np.int32)], (160, 60, 60))
    cv2.fillPoly(img, [STRIP.astype(np.int32)], strip_colour)
    img = np.clip(img + np.random.default_rng(0).normal(0.0, 2.0, img.shape), 0, 255).astype(np.uint8)
    return edge_distance(np.maximum.reduce([channel_edges(c).edges for c in channels(img)]))


def test_hole_beside_the_object_on_colour_edges_is_a_face():
    obj = rasterize(OBJECT, SHAPE)
    hole = rasterize(STRIP, SHAPE) & ~obj
    polys = hole_faces(hole, obj, _dist())
    assert len(polys) == 1
    assert len(polys[0]) == 4
    assert _iou(rasterize(polys[0], SHAPE), rasterize(STRIP, SHAPE)) >= 0.8


def test_hole_is_no_face_without_colour_edges_apart_from_the_object_or_when_cut():
    obj = rasterize(OBJECT, SHAPE)
    hole = rasterize(STRIP, SHAPE) & ~obj
    # the same colour as the table: only the side along the object is on an edge
    assert hole_faces(hole, obj, _dist(strip_colour=(200, 190, 170))) == []
    # away from the object (a hole in the table's readings)
    away = np.roll(hole, -40, axis=1)
    assert hole_faces(away, obj, _dist()) == []
    # cut by the crop's border: the strip's top end lies outside the searched box
    dist = _dist()
    assert hole_faces(hole[50:], obj[50:], dist[50:]) == []


def test_hole_that_is_not_convex_is_no_face():
    obj = rasterize(OBJECT, SHAPE)
    hole = rasterize(STRIP, SHAPE) & ~obj
    hole[60:80, 40:75] = True  # an arm out into the table: two regions without readings run together
    assert hole_faces(hole, obj, _dist()) == []



def _frame_and_object():
    from lv3d.camera import Intrinsics
    from lv3d.rgbd import RGBD

    h, w = SHAPE
    obj = rasterize(OBJECT, SHAPE)
    depth = np.where(rasterize(STRIP, SHAPE) & ~obj, 0.0, 0.8).astype(np.float32)
    return RGBD(np.zeros(SHAPE + (3,), np.uint8), depth, Intrinsics(200.0, 200.0, w / 2, h / 2, w, h)), obj


def test_hole_face_is_added_as_a_colour_face_and_neighbour_of_the_face_it_touches():
    from lv3d.perception.holes import add_hole_faces
    from lv3d.scene import Face

    frame, obj = _frame_and_object()
    faces, pairs = [Face("", OBJECT, "depth")], set()
    # searched in a box: the offset is added back to the new face's outline
    box = (10, 20, SHAPE[1], SHAPE[0])
    added = add_hole_faces(faces, pairs, [0], frame, box, obj[20:, 10:], _dist()[20:, 10:])
    assert added == [1] and pairs == {(0, 1)}
    assert faces[1].provenance == "rgb" and faces[1].plane is None
    assert _iou(rasterize(faces[1].polygon, SHAPE), rasterize(STRIP, SHAPE)) >= 0.8


def test_a_face_that_swallowed_the_hole_gives_it_up_and_one_that_is_the_hole_keeps_it():
    from lv3d.perception.holes import add_hole_faces
    from lv3d.scene import Face

    frame, obj = _frame_and_object()
    box = (0, 0, SHAPE[1], SHAPE[0])
    merged = np.array([(62, 45), (80, 40), (180, 50), (175, 160), (85, 150), (70, 148)], float)
    faces, pairs = [Face("", merged, "rgb")], set()
    assert add_hole_faces(faces, pairs, [0], frame, box, obj, _dist()) == [1]
    assert _iou(rasterize(faces[0].polygon, SHAPE), rasterize(OBJECT, SHAPE)) >= 0.9
    assert len(faces[0].polygon) == 4 and pairs == {(0, 1)}
    # colour found the strip itself: nothing is added
    faces = [Face("", OBJECT, "rgb"), Face("", STRIP, "rgb")]
    assert add_hole_faces(faces, set(), [0, 1], frame, box, obj, _dist()) == []
    assert np.array_equal(faces[1].polygon, STRIP)
