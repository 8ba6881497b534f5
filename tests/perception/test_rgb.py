import cv2
import numpy as np

from lv3d.perception.rgb import stage as rgb
from lv3d.perception.polygons import rasterize
from lv3d.perception.rgb import rgb_faces

from .conftest import mask_iou


def _best_iou(res, poly, shape):
    """The best IoU of any face found in ``res`` with polygon ``poly``, both rasterised on an image of ``shape``."""
    want = rasterize(poly, shape)
    return max((mask_iou(rasterize(f.polygon, shape), want) for f in res.faces), default=0.0)


def _canvas():
    return np.full((240, 320, 3), (200, 200, 190), np.uint8)


def test_filled_pentagon_gives_one_five_sided_face():
    img = _canvas()
    ang = np.radians(np.arange(5) * 72 - 90)
    pts = np.stack([160 + 80 * np.cos(ang), 125 + 80 * np.sin(ang)], 1)
    cv2.fillPoly(img, [np.round(pts).astype(np.int32)], (40, 90, 160))
    res = rgb_faces(img)
    assert len(res.faces) == 1
    face = res.faces[0]
    assert len(face.polygon) == 5
    # every found corner is within 3 px of a true one
    d = np.linalg.norm(face.polygon[:, None, :] - pts[None, :, :], axis=2)
    assert d.min(axis=1).max() < 3.0
    assert face.edge_support > 0.9


def test_three_faces_of_a_drawn_cube_share_edges_and_form_one_object():
    img = _canvas()
    a, b, c, d, e, f, g = (160, 40), (230, 75), (160, 110), (90, 75), (90, 170), (160, 205), (230, 170)
    cv2.fillPoly(img, [np.array([a, b, c, d])], (200, 60, 60))  # hue edge only: same grey level as others
    cv2.fillPoly(img, [np.array([d, c, f, e])], (140, 40, 40))
    cv2.fillPoly(img, [np.array([c, b, g, f])], (90, 20, 20))
    res = rgb_faces(img)
    assert sorted(len(f.polygon) for f in res.faces) == [4, 4, 4]
    assert len(res.adjacency) == 3
    assert res.groups == [[0, 1, 2]]


def test_plain_image_has_no_face():
    assert rgb_faces(_canvas()).faces == []


def test_traced_part_keeps_the_traced_bends_between_outline_corners():
    from lv3d.perception.polygons import clockwise
    from lv3d.perception.rgb.stage import _traced_part

    # a wide face and a thin one merged: the bend at (104, 50) was simplified away from the merged outline,
    # which is cut along its diagonal a-c as the split functions cut (runs of the outline's corners)
    bend = (104.0, 50.0)
    traced = clockwise(np.array([(0.0, 0.0), (100.0, 0.0), bend, (110.0, 100.0), (0.0, 100.0)]))
    outline = clockwise(np.array([(0.0, 0.0), (100.0, 0.0), (110.0, 100.0), (0.0, 100.0)]))
    i, j = sorted(int(np.argmin(np.hypot(*(outline - v).T))) for v in ((0.0, 0.0), (110.0, 100.0)))
    pieces = [outline[i:j + 1], np.concatenate([outline[j:], outline[:i + 1]])]
    parts = [_traced_part(traced, outline, q) for q in pieces]
    # the part holding (100, 0) runs through the bend; the other is its piece
    for q, part in zip(pieces, parts):
        if any(np.allclose(v, (100.0, 0.0)) for v in q):
            assert len(part) == 4 and any(np.allclose(v, bend) for v in part)
        else:
            np.testing.assert_allclose(part, q)


def test_a_faint_edge_inside_a_concave_outline_is_cut_before_the_outline_is_split():
    # a box's top and front faces of one colour, 4 grey levels apart, and its dark left face: the graph traces top and
    # front as one concave outline, and their faint edge runs from its reflex corner (80, 80) to a point of its right
    # side, not to a corner, where no corner-to-corner cut can follow it (split_concave would cut the diagonal
    # (80, 80) to (160, 30)). Drawn in perspective: where front and left meet, their outline turns; it would run
    # straight on only for a line drawn across one face (solids.one_face_parts)
    img = np.full((240, 320, 3), (120, 80, 50), np.uint8)
    top = np.array([(40, 30), (160, 30), (160, 80), (80, 80), (40, 60)])
    front = np.array([(80, 80), (160, 80), (160, 170), (80, 170)])
    left = np.array([(40, 60), (80, 80), (80, 170), (40, 150)])
    for poly, colour in ((top, (192, 202, 142)), (front, (188, 198, 138)), (left, (93, 99, 69))):
        cv2.fillPoly(img, [poly.astype(np.int32)], colour)

    res = rgb_faces(img)
    assert min(_best_iou(res, p, img.shape[:2]) for p in (top, front, left)) > 0.9
    # with no step between top and front no cut is made along their line
    cv2.fillPoly(img, [front.astype(np.int32)], (192, 202, 142))
    assert _best_iou(rgb_faces(img), top, img.shape[:2]) < 0.8


def test_a_short_faint_edge_that_steps_clearly_cuts_a_small_face_off():
    # a triangular prism's 509 px side and 1316 px end, 5-6 grey levels apart, traced as one outline; their edge
    # keeps 10 clear samples, under step_cut's 15, but steps 89 times its control
    off = np.array([40.0, 20.0])
    small = np.array([(12.8, 56.4), (30.1, 37.0), (51.7, 74.0)]) + off
    large = np.array([(30.1, 37.0), (54.1, 10.2), (72.1, 44.7), (51.7, 74.0)]) + off
    img = np.full((140, 180, 3), (120, 80, 50), np.uint8)
    for poly, colour in ((large, (116, 125, 97)), (small, (111, 119, 93))):
        cv2.fillPoly(img, [np.round(poly).astype(np.int32)], colour)

    res = rgb_faces(img)
    assert len(res.faces) == 2 and min(_best_iou(res, p, img.shape[:2]) for p in (small, large)) > 0.8
    cv2.fillPoly(img, [np.round(small).astype(np.int32)], (116, 125, 97))  # one colour: no edge, no cut
    assert len(rgb_faces(img).faces) == 1


def test_a_faint_edge_from_side_to_side_cuts_two_faces_of_one_colour_apart(monkeypatch):
    # a cube's top and front faces, 10 grey levels apart, traced as one outline whose left sides and right sides run
    # on in one line each (its sides seen edge-on); their edge ends on those sides, at no corner
    top = np.array([(40, 30), (160, 30), (160, 75), (40, 85)])
    front = np.array([(40, 85), (160, 75), (160, 170), (40, 170)])
    img = np.full((240, 320, 3), (120, 80, 50), np.uint8)
    for poly, colour in ((top, (170, 165, 115)), (front, (160, 155, 105))):
        cv2.fillPoly(img, [poly.astype(np.int32)], colour)

    res = rgb_faces(img)
    assert len(res.faces) == 2 and min(_best_iou(res, p, img.shape[:2]) for p in (top, front)) > 0.95
    # the edge map and the corner cuts miss this edge: without the side-to-side cut the two faces are one
    monkeypatch.setattr(rgb, "side_cut", lambda *a, **k: None)
    assert len(rgb_faces(img).faces) == 1
