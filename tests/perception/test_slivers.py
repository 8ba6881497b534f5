"""Faces seen edge-on in the colour graph: corners that turn little, no diagonal cut, halves joined; small faces
cut along an image edge kept apart."""
import cv2
import numpy as np

from lv3d.perception.rgb.faces import bounded_faces, build_graph
from lv3d.perception.polygons import area, clockwise, simplify
from lv3d.perception.rgb import rgb_faces
from lv3d.perception.rgb.stage import _join_on_graph_edges, _join_thin_to_traced
from lv3d.perception.rgb.split import split_by_diagonal

# a face seen edge-on: a quadrilateral 10 px wide whose corners turn by a few degrees, traced with a vertex more
SLIVER = np.array([[0.0, 0.0], [50.0, 4.1], [100.0, 8.0], [200.0, 0.0], [100.0, -2.0]])


def test_simplify_keeps_a_sliver_corner_that_holds_its_area():
    plain = simplify(SLIVER)                   # the inner corner lies 2 px off its chord and turns by 2 degrees
    assert len(plain) == 3 and not any(np.allclose(v, [100.0, -2.0]) for v in plain)
    kept = simplify(SLIVER, keep_area_frac=0.1)  # but it holds a fifth of the face
    assert len(kept) == 4 and any(np.allclose(v, [100.0, -2.0]) for v in kept)
    # a point a pixel off a long side of a large face still goes
    square = np.array([[0.0, 0.0], [50.0, 1.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]])
    assert len(simplify(square, keep_area_frac=0.1)) == 4


def test_split_by_diagonal_leaves_a_sliver_without_interior_whole():
    quad = np.array([[0.0, 0.0], [100.0, 3.0], [200.0, 0.0], [100.0, -2.0]])
    # strong everywhere, as near a thin face's own edges: there the gradient cannot tell a missed diagonal
    grad = np.full((40, 240), 100.0, np.float32)
    shifted = quad + [20.0, 20.0]
    assert len(split_by_diagonal(shifted, grad, 50.0)) == 1


def _sliver_graph(edge_dist: np.ndarray):
    # long side (0,0)-(210,0), a side turning by 5.7 degrees that LSD stopped 30 px short of the corner it
    # converges into, and a crossing side closing the face
    segs = np.array([[0.0, 0.0, 210.0, 0.0], [0.0, 20.0, 170.0, 3.0], [0.0, -5.0, 0.0, 25.0]]) + [20, 20, 20, 20]
    return build_graph(segs, edge_dist=edge_dist)


def test_nearly_parallel_segments_meet_where_the_edge_leads_to_their_crossing():
    on_edges = np.zeros((60, 260), np.float32)
    faces = bounded_faces(_sliver_graph(on_edges))
    assert len(faces) == 1
    assert np.allclose(sorted(map(tuple, np.round(faces[0].polygon))), [(20, 20), (20, 40), (220, 20)], atol=1)
    # without edge pixels on the way to the crossing they do not meet, and no face closes
    assert bounded_faces(_sliver_graph(np.full((60, 260), 50.0, np.float32))) == []


def test_join_on_graph_edges_joins_two_halves_but_not_two_strips_side_by_side():
    vertices = np.array([[0.0, 0.0], [200.0, 0.0], [100.0, 8.0], [100.0, -2.0], [0.0, 8.0], [200.0, 8.0]])
    half1 = clockwise(vertices[[0, 2, 3]])
    half2 = clockwise(vertices[[3, 2, 1]])
    cands = [(half1, frozenset({(0, 2), (2, 3), (0, 3)}), 1.0, area(half1)),
             (half2, frozenset({(2, 3), (1, 2), (1, 3)}), 1.0, area(half2))]
    joined = _join_on_graph_edges(cands, vertices, np.zeros((20, 220), np.float32))
    assert len(joined) == 1 and len(joined[0][0]) == 4
    assert abs(joined[0][3] - (area(half1) + area(half2))) < 1e-6
    # two strips 4 px wide sharing a 200 px side stay two faces
    a = np.array([[0.0, 0.0], [200.0, 0.0], [200.0, 4.0], [0.0, 4.0]])
    b = a + [0.0, 4.0]
    strips = [(a, frozenset({(10, 11), (0, 1)}), 1.0, area(a)), (b, frozenset({(10, 11), (2, 3)}), 1.0, area(b))]
    verts = np.zeros((12, 2))
    verts[10], verts[11] = [0.0, 4.0], [200.0, 4.0]
    assert len(_join_on_graph_edges(strips, verts, np.zeros((20, 220), np.float32))) == 2


def test_a_thin_pass_sliver_joins_the_traced_part_it_touches_without_a_shared_graph_edge():
    vertices = np.array([[0.0, 0.0], [200.0, 0.0], [100.0, 8.0], [100.0, -2.0]])
    traced = clockwise(vertices[[0, 2, 3]])
    closed = clockwise(vertices[[3, 2, 1]])     # from thin.py: its made-up key is no graph edge of the other
    cands = [(traced, frozenset({(0, 2), (2, 3), (0, 3)}), 1.0, area(traced)),
             (closed, frozenset({(-10_000, -10_000)}), 1.0, area(closed))]
    dist = np.zeros((20, 220), np.float32)
    assert len(_join_on_graph_edges(cands, vertices, dist)) == 2
    joined = _join_thin_to_traced(cands, 1, dist)
    assert len(joined) == 1 and len(joined[0][0]) == 4
    # two strips side by side along a 200 px side stay two faces
    a = np.array([[0.0, 0.0], [200.0, 0.0], [200.0, 4.0], [0.0, 4.0]])
    b = a + [0.0, 4.0]
    strips = [(a, frozenset({(0, 1)}), 1.0, area(a)), (b, frozenset({(-10_000, -10_000)}), 1.0, area(b))]
    assert len(_join_thin_to_traced(strips, 1, dist)) == 2


def test_two_small_faces_cut_along_an_image_edge_stay_apart():
    # a far pyramid seen from above: two triangles of ~330 px whose shared edge is a few grey levels of shading
    # that the line detector misses; split_by_diagonal cuts the traced quad there, and though each half is
    # "thin" (7 px mean width) the halves must not be joined back as the two parts of one sliver
    img = np.full((80, 100, 3), (110, 80, 50), np.uint8)
    top, right, bottom, left = (50, 20), (71, 38), (50, 49), (29, 38)
    cv2.fillPoly(img, [np.array([top, bottom, left], np.int32)], (178, 171, 91))
    cv2.fillPoly(img, [np.array([top, right, bottom], np.int32)], (190, 183, 98))
    res = rgb_faces(img)
    assert len(res.faces) == 2 and res.adjacency == [(0, 1)] and res.groups == [[0, 1]]
    for f in res.faces:
        assert len(f.polygon) == 3 and 300 < f.area_px < 360
        assert np.min(np.abs(f.polygon[:, 0] - 50)) < 1.5  # both have the shading edge u = 50 as a side
