import cv2
import numpy as np

from lv3d.perception.edges import channel_edges, channels, edge_distance
from lv3d.perception.polygons import rasterize
from lv3d.perception.rgb.thin import thin_faces

from .conftest import B, C, F, F2, FRONT, SLIVER, TOP, mask_iou
from .conftest import sliver_box as _image


def _dist(img: np.ndarray) -> np.ndarray:
    return edge_distance(np.maximum.reduce([channel_edges(c).edges for c in channels(img)]))


def test_sliver_beside_found_faces_is_closed_from_their_corners():
    dist = _dist(_image())
    # the silhouette as the line detector sees it: stopping well short of the corner the sliver narrows into
    b, f2 = np.array(B, float), np.array(F2, float)
    outer = np.concatenate([b + 0.2 * (f2 - b), f2])[None]
    polys = thin_faces(outer, dist, [TOP, FRONT])
    assert len(polys) == 1
    truth = rasterize(SLIVER, dist.shape)
    found = rasterize(polys[0], dist.shape)
    assert mask_iou(truth, found) >= 0.5
    assert len(polys[0]) == 4


def test_no_sliver_without_a_segment_beside_the_faces_or_on_their_own_sides():
    dist = _dist(_image(with_sliver=False))
    own_side = np.concatenate([np.array(C, float), np.array(F, float)])[None]  # the front face's right side
    assert thin_faces(own_side, dist, [TOP, FRONT]) == []
    assert thin_faces(np.zeros((0, 4)), dist, [TOP, FRONT]) == []


def test_no_sliver_where_no_edge_bounds_it():
    # the same segment over a plain background: the strip's outer side lies on no image edge
    dist = _dist(_image(with_sliver=False))
    b, f2 = np.array(B, float), np.array(F2, float)
    outer = np.concatenate([b + 0.2 * (f2 - b), f2])[None]
    assert thin_faces(outer, dist, [TOP, FRONT]) == []


def test_sliver_whose_outer_edge_kinks_at_its_own_corner_is_a_triangle():
    # a tetrahedron's face seen nearly edge-on: a triangle 7 px wide beside a large one, its outer edge two
    # segments meeting at a slight turn (the sliver's third corner), each stopping short of the far corners
    p, q, r = np.array([100.0, 40.0]), np.array([60.0, 200.0]), np.array([200.0, 200.0])
    k = 0.5 * (p + r) + 7.0 * np.array([0.848, -0.53])
    big, sliver = np.array([p, q, r]), np.array([p, k, r])
    img = np.full((240, 320, 3), (120, 80, 60), np.uint8)
    cv2.fillPoly(img, [np.round(big).astype(np.int32)], (190, 200, 130))
    cv2.fillPoly(img, [np.round(sliver).astype(np.int32)], (120, 130, 80))
    img = np.clip(img + np.random.default_rng(1).normal(0.0, 2.0, img.shape), 0, 255).astype(np.uint8)
    dist = _dist(img)
    segs = np.array([np.concatenate([p + 0.15 * (k - p), k - 0.05 * (k - p)]),
                     np.concatenate([k + 0.05 * (r - k), r - 0.15 * (r - k)])])
    polys = thin_faces(segs, dist, [big])
    assert len(polys) == 1 and len(polys[0]) == 3
    truth, found = rasterize(sliver, dist.shape), rasterize(polys[0], dist.shape)
    assert mask_iou(truth, found) >= 0.5
