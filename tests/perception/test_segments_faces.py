import numpy as np

from lv3d.perception.rgb.faces import PlanarGraph, bounded_faces, build_graph, planarize, prune
from lv3d.perception.polygons import signed_area
from lv3d.perception.rgb.segments import merge_collinear, union_find_labels


def test_merge_collinear_joins_pieces_of_one_edge():
    segs = np.array([[0, 0, 40, 0], [43, 0.5, 90, 0.5], [0, 10, 0, 60]], float)
    out = merge_collinear(segs)
    assert len(out) == 2
    long = out[np.argmax(np.hypot(out[:, 2] - out[:, 0], out[:, 3] - out[:, 1]))]
    assert abs(np.hypot(long[2] - long[0], long[3] - long[1]) - 90) < 1.5


def test_merge_collinear_keeps_parallel_lines_apart():
    segs = np.array([[0, 0, 50, 0], [0, 8, 50, 8]], float)
    assert len(merge_collinear(segs)) == 2


def test_union_find_labels_names_each_component_by_its_smallest_member():
    labels = union_find_labels(7, np.array([[4, 2], [2, 6], [5, 1]]))
    np.testing.assert_array_equal(labels, [0, 1, 2, 3, 2, 1, 2])
    np.testing.assert_array_equal(union_find_labels(3, np.zeros((0, 2), int)), [0, 1, 2])


def test_square_with_gaps_at_the_corners_is_one_face():
    # segments stop 3 px short of each corner, as a line detector does
    segs = np.array([[13, 10, 97, 10], [100, 13, 100, 97], [97, 100, 13, 100], [10, 97, 10, 13]], float)
    faces = bounded_faces(build_graph(segs))
    assert len(faces) == 1
    assert len(faces[0].cycle) == 4
    assert np.allclose(sorted(faces[0].polygon[:, 0]), [10, 10, 100, 100], atol=1)


def test_free_ended_segments_are_pruned_and_two_squares_share_an_edge():
    segs = np.array([[10, 10, 100, 10], [10, 100, 100, 100], [10, 10, 10, 100], [100, 10, 100, 100],
                     [100, 10, 190, 10], [100, 100, 190, 100], [190, 10, 190, 100],
                     [150, 150, 220, 220]], float)  # the last is a stray line
    g = build_graph(segs)
    faces = bounded_faces(g)
    assert len(faces) == 2
    assert len(faces[0].edges & faces[1].edges) == 1


def test_graph_is_deterministic():
    rng = np.random.default_rng(3)
    segs = rng.uniform(0, 200, (40, 4))
    a, b = build_graph(segs), build_graph(segs.copy())
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.edges, b.edges)


def _square_edge_distance(size: int = 120) -> np.ndarray:
    """Distance to the outline of the square (10, 10)-(100, 100), as edge_distance gives it."""
    import cv2

    from lv3d.perception.edges import edge_distance

    edges = np.zeros((size, size), np.uint8)
    cv2.rectangle(edges, (10, 10), (100, 100), 255, 1)
    return edge_distance(edges)


def test_segment_stopping_far_short_of_a_corner_reaches_it_along_the_edge_map():
    # the left side stops 20 px short of the bottom-left corner: beyond the plain reach (10 px)
    segs = np.array([[13, 10, 97, 10], [100, 13, 100, 97], [97, 100, 13, 100], [10, 80, 10, 13]], float)
    assert bounded_faces(build_graph(segs)) == []
    faces = bounded_faces(build_graph(segs, edge_dist=_square_edge_distance()))
    assert len(faces) == 1 and len(faces[0].cycle) == 4
    assert np.allclose(sorted(faces[0].polygon[:, 1]), [10, 10, 100, 100], atol=1)


def test_far_reach_needs_edge_pixels_all_along_the_extension():
    segs = np.array([[13, 10, 97, 10], [100, 13, 100, 97], [97, 100, 13, 100], [10, 80, 10, 13]], float)
    dist = _square_edge_distance()
    import cv2

    from lv3d.perception.edges import edge_distance

    edges = (dist == 0).astype(np.uint8) * 255
    cv2.line(edges, (10, 85), (10, 95), 0, 1)  # a 10 px hole in the edge along the gap
    assert bounded_faces(build_graph(segs, edge_dist=edge_distance(edges))) == []


def test_overlapping_pieces_of_one_side_meet_where_one_ends_beside_the_other():
    # the left side as two pieces a degree apart, side by side for 20 px (LSD splits an edge where a sliver
    # beside it converges on it): their lines cross far off, so only the end of one lying on the other joins them
    segs = np.array([[13, 10, 97, 10], [100, 13, 100, 97], [97, 100, 13, 100],
                     [10, 13, 11, 70], [10.5, 50, 10, 97]], float)
    assert bounded_faces(build_graph(segs, overlap_px=0.0)) == []
    faces = bounded_faces(build_graph(segs))
    assert len(faces) == 1
    from lv3d.perception.polygons import area

    assert abs(area(faces[0].polygon) - 90 * 90) < 150


def test_parallel_pieces_further_apart_than_the_overlap_tolerance_stay_apart():
    # two parallel lines 3 px apart (the two sides of a sliver) must not be joined
    segs = np.array([[13, 10, 97, 10], [100, 13, 100, 97], [97, 100, 13, 100],
                     [10, 13, 10, 70], [13, 50, 13, 97]], float)
    assert bounded_faces(build_graph(segs)) == []


def test_crossing_edges_are_split_where_they_cross():
    # a square with both diagonals: four triangles, whose common corner is the crossing
    v = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    e = np.array([[0, 1], [1, 2], [2, 3], [0, 3], [0, 2], [1, 3]])
    g = planarize(PlanarGraph(v, e))
    assert len(g.vertices) == 5
    np.testing.assert_allclose(g.vertices[4], [5.0, 5.0])
    faces = bounded_faces(g)
    assert len(faces) == 4
    assert all(len(f.cycle) == 3 for f in faces)
    np.testing.assert_allclose(sorted(abs(signed_area(f.polygon)) for f in faces), [25.0] * 4)
    # edges that only share a corner, or touch end to end, are left as they are
    tri = PlanarGraph(v[:3], np.array([[0, 1], [1, 2], [0, 2]]))
    assert planarize(tri) is tri


def test_a_hexagon_whose_graph_edges_cross_at_an_obtuse_corner_is_still_a_face():
    # the junction graph of a cuboid's silhouette on a clean render (dev seed 3003): at the right, the edges of two
    # overlapping pieces around an obtuse corner cross; unsplit, the face walk found no bounded face
    v = np.array([[268, 242], [266, 178], [272, 276], [358, 172], [362, 200], [367, 247], [364, 270], [367, 233]],
                 float)
    e = np.array([[0, 1], [0, 2], [1, 3], [2, 6], [3, 4], [4, 5], [4, 7], [5, 7], [6, 7]])
    assert bounded_faces(prune(PlanarGraph(v, e))) == []
    faces = bounded_faces(prune(planarize(PlanarGraph(v, e))))
    big = max(faces, key=lambda f: signed_area(f.polygon))
    assert signed_area(big.polygon) > 0.95 * 92 * 98
