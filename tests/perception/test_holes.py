import cv2
import numpy as np
import pytest

from lv3d.perception.edges import channel_edges, channels, edge_distance
from lv3d.perception.depth.holes import hole_faces, hole_sizes
from lv3d.perception.polygons import rasterize

from .conftest import mask_iou as _iou

SHAPE = (200, 240)
# the object's faces that depth saw, and beside them a strip seen nearly edge-on, with no depth reading
OBJECT = np.array([(80, 40), (180, 50), (175, 160), (85, 150)], float)
STRIP = np.array([(62, 45), (80, 40), (85, 150), (70, 148)], float)
AREA = hole_sizes(SHAPE)[0]  # the least hole area in an image of SHAPE


def _dist(strip_colour=(60, 20, 20)) -> np.ndarray:
    img = np.full(SHAPE + (3,), (200, 190, 170), np.uint8)
    cv2.fillPoly(img, [OBJECT.astype(np.int32)], (160, 60, 60))
    cv2.fillPoly(img, [STRIP.astype(np.int32)], strip_colour)
    img = np.clip(img + np.random.default_rng(0).normal(0.0, 2.0, img.shape), 0, 255).astype(np.uint8)
    return edge_distance(np.maximum.reduce([channel_edges(c).edges for c in channels(img)]))


def test_hole_sizes_are_fractions_of_the_image_diagonal():
    assert hole_sizes((480, 640)) == (150.0, 30, 4)
    area, rim, touch = hole_sizes((960, 1280))
    assert area == 600.0 and rim == 60 and touch == 8


def test_hole_beside_the_object_on_colour_edges_is_a_face():
    obj = rasterize(OBJECT, SHAPE)
    hole = rasterize(STRIP, SHAPE) & ~obj
    polys = hole_faces(hole, obj, _dist(), AREA)
    assert len(polys) == 1
    assert len(polys[0]) == 4
    assert _iou(rasterize(polys[0], SHAPE), rasterize(STRIP, SHAPE)) >= 0.8


def test_hole_is_no_face_without_colour_edges_apart_from_the_object_or_when_cut():
    obj = rasterize(OBJECT, SHAPE)
    hole = rasterize(STRIP, SHAPE) & ~obj
    # the same colour as the table: only the side along the object is on an edge
    assert hole_faces(hole, obj, _dist(strip_colour=(200, 190, 170)), AREA) == []
    # away from the object (a hole in the table's readings)
    away = np.roll(hole, -40, axis=1)
    assert hole_faces(away, obj, _dist(), AREA) == []
    # cut by the crop's border: the strip's top end lies outside the searched box
    dist = _dist()
    assert hole_faces(hole[50:], obj[50:], dist[50:], AREA) == []


def test_hole_that_is_not_convex_is_no_face():
    obj = rasterize(OBJECT, SHAPE)
    hole = rasterize(STRIP, SHAPE) & ~obj
    hole[60:80, 40:75] = True  # an arm out into the table: two regions without readings run together
    assert hole_faces(hole, obj, _dist(), AREA) == []



def _frame_and_object():
    from lv3d.camera import Intrinsics
    from lv3d.rgbd import RGBD

    h, w = SHAPE
    obj = rasterize(OBJECT, SHAPE)
    depth = np.where(rasterize(STRIP, SHAPE) & ~obj, 0.0, 0.8).astype(np.float32)
    return RGBD(np.zeros(SHAPE + (3,), np.uint8), depth, Intrinsics(200.0, 200.0, w / 2, h / 2, w, h)), obj


def test_hole_face_is_added_as_a_colour_face_and_neighbour_of_the_face_it_touches():
    from lv3d.perception.depth.holes import add_hole_faces
    from lv3d.scene import Face

    frame, obj = _frame_and_object()
    faces, pairs = [Face("", OBJECT, "depth")], set()
    # searched in a box: the offset is added back to the new face's outline
    box = (10, 20, SHAPE[1], SHAPE[0])
    added = add_hole_faces(faces, pairs, [0], frame, box, obj[20:, 10:], _dist()[20:, 10:])
    assert added == [1] and pairs == {(0, 1)}
    assert faces[1].provenance == "rgb" and faces[1].plane is None
    assert _iou(rasterize(faces[1].polygon, SHAPE), rasterize(STRIP, SHAPE)) >= 0.8


def test_a_hole_a_face_covers_already_adds_nothing():
    from lv3d.perception.depth.holes import add_hole_faces
    from lv3d.scene import Face

    frame, obj = _frame_and_object()
    box = (0, 0, SHAPE[1], SHAPE[0])
    faces = [Face("", OBJECT, "depth"), Face("", STRIP, "depth")]
    assert add_hole_faces(faces, set(), [0, 1], frame, box, obj, _dist()) == []
    assert np.array_equal(faces[1].polygon, STRIP)


def test_unread_face_in_rgbd_needs_colour_edges_beyond_the_object_side_and_comes_before_colour():
    from lv3d.perception.depth.holes import UnreadFace, add_hole_faces
    from lv3d.plane import Plane
    from lv3d.scene import Face

    frame, obj = _frame_and_object()
    box = (0, 0, SHAPE[1], SHAPE[0])
    unread = [UnreadFace(STRIP.copy(), Plane.from_arrays((1.0, 0.0, 0.2), -0.1), np.zeros((3, 3)), 0.001, [0])]
    # a band of the table's colour (an occlusion shadow): an edge along the object's side only
    faces = [Face("", OBJECT, "depth")]
    assert add_hole_faces(faces, set(), [0], frame, box, obj, _dist((200, 190, 170)), unread=unread) == []
    # a strip of a colour of its own: the unread face, with its plane, comes first, and colour's hole face there
    # adds nothing
    faces = [Face("", OBJECT, "depth")]
    assert add_hole_faces(faces, set(), [0], frame, box, obj, _dist(), unread=unread) == [1]
    assert faces[1].provenance == "rgbd" and faces[1].plane == unread[0].plane


def test_a_hole_that_is_the_unread_rest_of_a_grazing_face_extends_it():
    from lv3d.perception.depth.holes import add_hole_faces
    from lv3d.plane import Plane
    from lv3d.scene import Face

    frame, obj = _frame_and_object()
    box = (0, 0, SHAPE[1], SHAPE[0])
    # the face beside the strip, read on its right part only: seen at 80 degrees from face-on, the strip is the
    # rest of it; seen face-on, the strip is a face of its own
    read_part = np.array([(40, 50), (62, 45), (70, 148), (48, 150)], float)
    pts = np.array([[0.0, 0.0, 0.8], [0.01, 0.0, 0.8], [0.0, 0.01, 0.8]])
    for normal, extended in (((np.cos(np.radians(10)), 0.0, np.sin(np.radians(10))), True), ((0.0, 0.0, 1.0), False)):
        n = np.asarray(normal)
        faces = [Face("", OBJECT, "depth"), Face("", read_part, "depth", plane=Plane.from_arrays(n, -0.8 * n[2]),
                                                 points=pts)]
        added = add_hole_faces(faces, set(), [0, 1], frame, box, obj, _dist())
        if extended:
            assert added == [] and _iou(rasterize(faces[1].polygon, SHAPE),
                                        rasterize(read_part, SHAPE) | rasterize(STRIP, SHAPE)) >= 0.9
        else:
            assert added == [2] and np.array_equal(faces[1].polygon, read_part)


def _grazing_cuboid(grazing_deg: float = 78.0):
    """A cuboid one of whose faces (truth id 5, 4254 px) is seen beyond 78 degrees from face-on: a sensor that
    reads no further leaves it without a reading. Returns the frame and its face-id mask (k = truth face k - 1)."""
    from lv3d.render import render_scene
    from lv3d.render.noise import noise_config

    return render_scene("cuboid", 2001, noise=noise_config("clean", grazing_deg=grazing_deg))


def test_face_depth_did_not_read_is_found_from_its_rim_with_its_plane_and_neighbours():
    from lv3d.perception import perceive

    frame, faces = _grazing_cuboid()
    unread = faces == 6
    assert not np.any(frame.depth[unread] > 0)
    normal = np.asarray(frame.meta["truth"]["faces"][2]["plane"]["normal"])
    (obj,) = [o for o in perceive(frame, "depth").objects if o.faces]
    ious = [_iou(rasterize(f.polygon, unread.shape), unread) for f in obj.faces]
    face = obj.faces[int(np.argmax(ious))]
    assert max(ious) >= 0.85 and face.sides == 4 and face.provenance == "depth"
    assert np.degrees(np.arccos(min(1.0, abs(face.plane.n @ normal)))) < 3.0
    # it meets both faces depth read
    assert sum(face.id in pair for pair in obj.adjacency) == 2


def _unread(frame, reach=None, **checks) -> list:
    """holes.unread_faces beside the largest depth object of ``frame``, ``checks`` overriding its UnreadSettings."""
    from dataclasses import replace

    from lv3d.perception.boundary import grid_to_pixels
    from lv3d.perception.depth import depth_scene
    from lv3d.perception.depth.holes import UNREAD, unread_faces

    dres = depth_scene(frame)
    o = dres.objects[0]
    (h, w), (u0, v0, u1, v1) = frame.shape, o.box_px
    box = (max(0, u0 - 14), max(0, v0 - 14), min(w, u1 + 14), min(h, v1 + 14))
    known = [p.plane for p in o.planes] + [dres.support]
    return unread_faces(frame.depth, dres.grid, grid_to_pixels(o.obj.mask, dres.grid.stride, box),
                        [p.mask for p in o.planes], known, box, reach=reach, settings=replace(UNREAD, **checks))


def test_missing_readings_on_the_table_or_inside_a_face_are_no_face():
    from dataclasses import replace

    frame, faces = _grazing_cuboid(grazing_deg=90.0)  # every face read
    solid = faces > 0
    depth = frame.depth.copy()
    # a blob on the table against the object's left side: its rim is mostly the table
    outside = cv2.distanceTransform((~solid).astype(np.uint8), cv2.DIST_L2, 5)
    vs, us = np.nonzero(solid)
    band = np.argwhere((outside > 4.5) & (outside < 5.5))
    band = band[band[:, 1] < us.mean()]
    v, u = band[np.argmin(np.abs(band[:, 0] - vs.mean()))]
    cv2.circle(depth, (int(u), int(v)), 9, 0.0, -1)
    # a blob inside the largest face: the object surrounds it
    inside = cv2.distanceTransform((faces == 3).astype(np.uint8), cv2.DIST_L2, 5)
    v, u = np.unravel_index(int(np.argmax(inside)), inside.shape)
    cv2.circle(depth, (int(u), int(v)), 8, 0.0, -1)
    blotted = replace(frame, depth=depth)
    assert _unread(blotted) == []
    # both are holes beside the object: the plane of their rims tells them from faces, and the object around the
    # second does on its own
    (table,) = _unread(blotted, min_graze_deg=0.0, min_apart_deg=0.0)
    assert solid[int(table.polygon[:, 1].mean()), int(table.polygon[:, 0].mean())] == 0
    assert len(_unread(blotted, min_graze_deg=0.0, min_apart_deg=0.0, max_on_object=1.0)) == 2


def test_unread_face_is_found_where_missing_readings_on_the_table_run_into_it():
    from dataclasses import replace

    frame, faces = _grazing_cuboid()
    unread = faces == 6
    # a blob of missing readings on the table against the unread face, away from the faces depth read
    to_unread = cv2.distanceTransform((~unread).astype(np.uint8), cv2.DIST_L2, 5)
    to_read = cv2.distanceTransform(((faces == 0) | unread).astype(np.uint8), cv2.DIST_L2, 5)
    band = np.argwhere((to_unread > 4.5) & (to_unread < 5.5) & (faces == 0))
    v, u = band[np.argmax(to_read[band[:, 0], band[:, 1]])]
    depth = frame.depth.copy()
    cv2.circle(depth, (int(u), int(v)), 10, 0.0, -1)
    blotted = replace(frame, depth=depth)
    # the hole is no longer convex: only the planes peeled off its rim find the face in it
    assert _unread(blotted, max_planes=0) == []
    ious = [_iou(rasterize(f.polygon, unread.shape), unread) for f in _unread(blotted)]
    assert max(ious, default=0.0) >= 0.8


def test_a_rim_far_behind_the_object_is_no_face_of_it():
    from lv3d.perception.depth import depth_scene

    frame, _ = _grazing_cuboid()
    dres = depth_scene(frame)
    xyz = dres.grid.xyz[dres.objects[0].obj.mask].astype(np.float64)
    z, extent = float(np.median(xyz[:, 2])), float(np.linalg.norm(np.percentile(xyz, 95, 0) - np.percentile(xyz, 5, 0)))
    assert dres.objects[0].scale == pytest.approx((z, extent))  # the reach perceive passes
    # the face depth did not read lies within the object's reach
    assert len(_unread(frame, reach=(z, extent))) == 1
    # the same rim behind an object that ends two of its extents nearer (a veil of mixed pixels from its edge to
    # the background) is none
    assert _unread(frame, reach=(z - 2 * extent, extent)) == []
    assert len(_unread(frame, reach=(z - 2 * extent, extent), max_behind=3.0)) == 1


def test_unread_settings_are_checked_and_perceive_takes_them_from_the_depth_settings():
    from dataclasses import replace

    from lv3d.perception import perceive
    from lv3d.perception.depth import DEFAULT
    from lv3d.perception.depth.holes import UnreadSettings

    for bad in ({"min_graze_deg": 95.0}, {"min_on_plane": 1.5}, {"max_planes": -1}, {"max_behind": 0.0}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            UnreadSettings(**bad)
    frame, _ = _grazing_cuboid()
    assert len(perceive(frame, "depth").objects[0].faces) == 3  # two faces read, one inferred from its hole
    # the depth stage's settings, as its result carries them, decide the unread faces too
    strict = replace(DEFAULT, unread=UnreadSettings(max_planes=0, min_on_plane=1.0))
    assert len(perceive(frame, "depth", depth_settings=strict).objects[0].faces) == 2
