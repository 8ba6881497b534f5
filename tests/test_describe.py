"""describe(): a hand-built Scene and frame -> facts with confidences, per modality."""

import dataclasses

import cv2
import numpy as np
import pytest

from lv3d.camera import Intrinsics
from lv3d.describe import describe
from lv3d.facts import PREDICATES
from lv3d.plane import Plane
from lv3d.rgbd import RGBD
from lv3d.scene import Face, Scene, SceneObject

K = Intrinsics(fx=600.0, fy=600.0, cx=319.5, cy=239.5, width=640, height=480)


def _wedge():
    """Two faces of a box meeting at 90 degrees, both facing the camera: 3D corners (4, 3) each, metres."""
    e0, e1 = np.array([-0.06, 0, 0]), np.array([0.06, 0, 0])
    up, back = np.array([0, -0.1, 0]), np.array([0, 0, 0.1])
    top = np.array([e0, e1, e1 + back, e0 + back])      # horizontal, on top
    front = np.array([e1, e0, e0 - up, e1 - up])  # vertical, in front, hanging down
    a = np.radians(40)
    rot = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    shift = np.array([0.0, -0.02, 0.7])
    return [f @ rot.T + shift for f in (top, front)], rot


def _project(x):
    return np.stack([K.fx * x[:, 0] / x[:, 2] + K.cx, K.fy * x[:, 1] / x[:, 2] + K.cy], 1)


def _mask(poly, ss=8):
    """Pixels whose centre lies inside the polygon (supersampled, so the outline is where the polygon is)."""
    big = np.zeros((480 * ss, 640 * ss), np.uint8)
    p = (np.asarray(poly) + 0.5) * ss - 0.5
    cv2.fillPoly(big, [np.round(p * 16).astype(np.int32)], 255, shift=4)
    return cv2.resize(big, (640, 480), interpolation=cv2.INTER_AREA) > 127


def _frame_and_faces(rng):
    faces3d, rot = _wedge()
    polys = [_project(f) for f in faces3d]
    color = np.full((480, 640, 3), 40, np.uint8)
    depth = np.zeros((480, 640), np.float32)
    v, u = np.mgrid[0:480, 0:640]
    rays = np.stack([(u - K.cx) / K.fx, (v - K.cy) / K.fy, np.ones_like(u, float)], -1)
    out = []
    for poly, f3, col in zip(polys, faces3d, [(210, 160, 90), (70, 150, 220)]):
        mask = _mask(poly)
        color[mask] = col
        plane = Plane.from_arrays(np.cross(f3[1] - f3[0], f3[2] - f3[0]), 0.0)
        plane = Plane.from_arrays(plane.n, -plane.n @ f3[0])
        t = -plane.offset / (rays @ plane.n)
        z = (t * (1 + rng.normal(0, 0.002, t.shape))).astype(np.float32)
        depth[mask] = z[mask]
        pts = rays[mask] * z[mask][:, None]
        out.append((poly + rng.normal(0, 1.0, poly.shape), plane, pts))
    support = Plane.from_arrays(rot @ np.array([0, -1.0, 0]), 0.0)
    support = Plane.from_arrays(support.n, -support.n @ (faces3d[1][2]))
    return RGBD(color, depth, K, "synthetic"), out, support


def _scene(modality, rng, with_extra_rgb_face=False):
    frame, faces, support = _frame_and_faces(rng)
    # shared corners: the second face's first two vertices are the first face's second and first
    faces[1] = (np.vstack([faces[0][0][1], faces[0][0][0], faces[1][0][2:]]), faces[1][1], faces[1][2])
    objs = []
    fl = []
    for j, (poly, plane, pts) in enumerate(faces, start=1):
        if modality == "rgb":
            fl.append(Face(f"s1_o1_f{j}", poly, "rgb"))
        else:
            fl.append(Face(f"s1_o1_f{j}", poly, modality, plane=plane, points=pts))
    if with_extra_rgb_face:
        tri = np.array([[100.0, 100], [160, 100], [130, 150]])
        frame.color[_mask(tri)] = (230, 230, 230)
        fl.append(Face("s1_o1_f3", tri, "rgb"))
    objs.append(SceneObject("s1_o1", fl, [("s1_o1_f1", "s1_o1_f2")], pixel_count=5000, centroid_px=(320, 240)))
    return Scene("s1", modality, K, objs, support_plane=None if modality == "rgb" else support), frame


def _by_atom(sf):
    return {f.atom(): f for f in sf.facts}


def test_rgbd_scene_gets_shape_orientation_and_relation_facts():
    scene, frame = _scene("rgbd", np.random.default_rng(0), with_extra_rgb_face=True)
    sf = describe(scene, frame)
    facts = _by_atom(sf)
    assert sf.target == "s1_o1" and sf.modality == "rgbd"
    for atom in ("object(s1_o1)", "quadrilateral(s1_o1_f1)", "quadrilateral(s1_o1_f2)",
                 "perpendicular(s1_o1_f1,s1_o1_f2)", "perpendicular(s1_o1_f2,s1_o1_f1)",
                 "adjacent(s1_o1_f1,s1_o1_f2)", "adjacent(s1_o1_f2,s1_o1_f1)",
                 "horizontal(s1_o1_f1)", "vertical(s1_o1_f2)", "rectangle(s1_o1_f1)"):
        assert atom in facts and facts[atom].conf > 0.8, (atom, facts.get(atom))
    assert abs(facts["perpendicular(s1_o1_f1,s1_o1_f2)"].value - 90.0) < 3.0
    assert "acute(s1_o1_f1,s1_o1_f2)" not in facts and "parallel(s1_o1_f1,s1_o1_f2)" not in facts
    # the rgb-only face gets 2D facts but nothing that needs a plane
    assert "triangle(s1_o1_f3)" in facts
    assert not any(a.endswith("(s1_o1_f3)") and a.split("(")[0] in ("horizontal", "vertical", "regular")
                   for a in facts)
    assert all(0.05 <= f.conf <= 1.0 for f in sf.facts)


def test_rgb_scene_has_no_plane_facts():
    scene, frame = _scene("rgb", np.random.default_rng(1))
    sf = describe(scene, frame)
    preds = {f.pred for f in sf.facts}
    assert preds <= {p for p, (_, mods) in PREDICATES.items() if "rgb" in mods}
    assert {"quadrilateral", "adjacent", "object", "face_of"} <= preds


@pytest.mark.parametrize("modality", ["rgbd", "rgb"])
def test_a_vertex_on_a_straight_side_gives_a_face_with_a_plane_its_true_side_count(modality):
    scene, frame = _scene(modality, np.random.default_rng(1))
    face = scene.objects[0].faces[1]
    p = face.polygon
    face.polygon = np.insert(p, 3, (p[2] + p[3]) / 2, axis=0)  # a fifth vertex half way along an outer side
    facts = _by_atom(describe(scene, frame))
    pentagon = facts.get("pentagon(s1_o1_f2)")
    assert pentagon is None or pentagon.conf < 0.2
    if modality == "rgbd":
        assert facts["quadrilateral(s1_o1_f2)"].conf > 0.8 and facts["quadrilateral(s1_o1_f2)"].value == 4.0
    else:  # without a plane the image turn cannot tell such a vertex from a true corner seen obliquely
        assert "quadrilateral(s1_o1_f2)" not in facts


def test_depth_scene_uses_depth_edges_and_unrefined_facts_keep_confidences():
    scene, frame = _scene("depth", np.random.default_rng(2))
    for refine in (True, False):
        facts = _by_atom(describe(scene, frame, refine=refine))
        assert "parallelogram(s1_o1_f1)" not in facts  # an image-shape fact, not for depth
        assert facts["perpendicular(s1_o1_f1,s1_o1_f2)"].conf > 0.8
        assert 0.05 < facts["quadrilateral(s1_o1_f1)"].conf <= 1.0


@pytest.mark.parametrize("modality", ["rgb", "depth", "rgbd"])
def test_every_emitted_predicate_is_allowed_for_the_modality(modality):
    scene, frame = _scene(modality, np.random.default_rng(3))
    sf = describe(scene, frame)
    assert sf.facts and all(modality in PREDICATES[f.pred][1] for f in sf.facts)


def test_objects_with_many_vertices_are_split_into_problems_that_fit():
    import grounding
    from lv3d.describe import _chunks
    from lv3d.scene import Face

    octagon = np.stack([np.cos(np.arange(8) * np.pi / 4), np.sin(np.arange(8) * np.pi / 4)], 1) * 20 + 100
    faces = [Face(f"s_o1_f{i}", octagon + 50 * i, "rgb") for i in range(5)]  # 40 vertices, none shared
    chunks = _chunks(faces, grounding.MAX_FACES, grounding.MAX_VERTICES, grounding.MAX_SIDES)
    assert [f for c in chunks for f in c] == faces
    for c in chunks:
        grounding.pack_object([f.polygon for f in c], intrinsics=(600.0, 600.0, 320.0, 240.0))


def test_dense_face_points_take_every_reading_inside_the_shrunk_outline():
    from lv3d.describe import dense_face_points

    rng = np.random.default_rng(5)
    frame, faces, _ = _frame_and_faces(rng)
    poly, plane, pts = faces[0]
    sparse = pts[::4]  # perception's points: a strided grid
    face = Face("f", poly, "rgbd", plane=plane, points=sparse)
    dense = dense_face_points(face, frame, margin_px=3)
    assert dense is not None and len(dense) > 2 * len(sparse)
    # on the face's plane, within the depth noise (0.2 % of 0.7 m)
    assert np.abs(dense @ plane.n + plane.offset).max() < 0.01
    # nothing within the margin of the outline: every point projects well inside the polygon
    uv = _project(dense)
    inside = np.array([cv2.pointPolygonTest(np.float32(poly), (float(u), float(v)), True) for u, v in uv])
    assert inside.min() > 1.5
    # a face without a plane, or whose outline holds fewer readings than perception found, keeps its points
    assert dense_face_points(Face("f", poly, "rgb"), frame) is None
    assert dense_face_points(Face("f", poly, "rgbd", plane=plane, points=np.zeros((10 ** 6, 3))), frame) is None


def test_rgbd_judges_a_face_depth_found_against_depth_edges_where_colour_has_none():
    from lv3d.describe import edge_field

    scene, frame = _scene("rgbd", np.random.default_rng(6))
    f1, f2 = scene.objects[0].faces
    top = np.all(frame.color == (210, 160, 90), axis=-1)
    frame.color[~top] = 40  # the front face in the floor's colour: colour sees none of its sides
    outer = (f2.polygon[2] + f2.polygon[3]) / 2  # its lower side, against the floor
    u, v = np.round(outer).astype(int)
    colour_only = edge_field(frame, "rgbd", scene)
    assert np.abs(colour_only[v - 1:v + 2, u - 1:u + 2]).min() > 3.0  # every face colour found: colour's edges only
    f2.provenance = "depth"
    filled = edge_field(frame, "rgbd", scene)
    assert np.abs(filled[v - 1:v + 2, u - 1:u + 2]).min() < 1.5  # depth's edge where colour has none
    # colour's edges stand where colour has one: along the side the two faces share, and away from the face
    shared = np.round((f1.polygon[0] + f1.polygon[1]) / 2).astype(int)
    near = (slice(shared[1] - 2, shared[1] + 3), slice(shared[0] - 2, shared[0] + 3))
    np.testing.assert_array_equal(filled[near], colour_only[near])
    assert np.array_equal(filled[:20], colour_only[:20])


def test_curved_evidence_tells_a_can_side_from_a_flat_face():
    from lv3d.cylinder import Cylinder
    from lv3d.describe import curved_evidence

    rng = np.random.default_rng(0)
    cyl = Cylinder((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), 0.04)
    ang = rng.uniform(-1.2, 1.2, 2000)  # the front 140 deg of a can of radius 4 cm, 1 mm noise
    side = np.stack([0.04 * np.sin(ang), rng.uniform(-0.05, 0.05, 2000), 1.0 - 0.04 * np.cos(ang)], 1)
    side += rng.normal(0, 0.001, side.shape)
    flat = np.stack([rng.uniform(-0.04, 0.04, 2000), rng.uniform(-0.05, 0.05, 2000), np.full(2000, 0.96)], 1)
    flat += rng.normal(0, 0.001, flat.shape)
    assert curved_evidence(side, cyl) > 0.9
    assert curved_evidence(flat, Cylinder((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), 0.04)) < 0.05
    assert curved_evidence(side[:5], cyl) is None


def _cylinder_fit(axis, std_deg):
    import grounding

    return grounding.CylinderFit(np.asarray(axis, float), np.zeros(3), np.float32(0.04),
                                 np.radians([std_deg, std_deg]), np.float32(1e-4), np.float32(1e-3),
                                 np.int32(0), np.float32(1.0))


def _face_result(face, plane=None, tilt_std_deg=None, fit=None):
    from lv3d.describe import CylinderReading, FaceResult, refined_cylinder

    tilt = None if tilt_std_deg is None else np.radians([tilt_std_deg, tilt_std_deg])
    reading = None if fit is None else CylinderReading(fit, refined_cylinder(face, fit), None)
    return FaceResult(face, face.polygon, None if plane is None else np.asarray(plane, float), np.zeros(len(face.polygon)),
                      {}, tilt, reading)


def test_a_lid_along_a_cylinder_axis_is_circular_and_a_side_face_is_not():
    from lv3d.cylinder import Cylinder
    from lv3d.describe import cap_candidates
    from lv3d.plane import Plane
    from lv3d.scene import Face, SceneObject

    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    side = Face("o_f1", square, "depth", surface="cylinder", cylinder=Cylinder((0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 0.04))
    lid = Face("o_f2", square, "depth", plane=Plane((0.0, -0.9986, -0.0523), 0.1))   # 3 deg off the axis
    wall = Face("o_f3", square, "depth", plane=Plane((1.0, 0.0, 0.0), 0.1))          # 90 deg off it
    obj = SceneObject("o", [side, lid, wall], [("o_f1", "o_f2"), ("o_f1", "o_f3")])
    faces = [_face_result(side, fit=_cylinder_fit((0.0, -1.0, 0.0), 0.5)),
             _face_result(lid, (0.0, -0.9986, -0.0523, 0.1), 0.5), _face_result(wall, (1.0, 0.0, 0.0, 0.1), 0.5)]
    got = {c[1][0]: c for c in cap_candidates(obj, faces, 1.0)}
    assert set(got) == {"o_f2"} and got["o_f2"][0] == "circular"
    assert got["o_f2"][2] > 0.9 and abs(got["o_f2"][3] - 3.0) < 0.1


def test_a_cap_reading_is_as_sure_as_its_measured_spreads():
    # 8 deg off the axis, inside the 10 deg tolerance: sure with tight spreads, doubtful with loose ones
    from lv3d.cylinder import Cylinder
    from lv3d.describe import cap_candidates
    from lv3d.scene import Face, SceneObject

    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    side = Face("o_f1", square, "depth", surface="cylinder", cylinder=Cylinder((0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 0.04))
    lid = Face("o_f2", square, "depth")
    obj = SceneObject("o", [side, lid], [("o_f1", "o_f2")])
    n = (0.0, -np.cos(np.radians(8.0)), -np.sin(np.radians(8.0)), 0.1)
    p = {}
    for std in (0.2, 4.0):
        faces = [_face_result(side, fit=_cylinder_fit((0.0, -1.0, 0.0), std)), _face_result(lid, n, std)]
        (c,) = cap_candidates(obj, faces, 1.0)
        p[std] = c[2]
    assert p[0.2] > 0.9 and p[4.0] < 0.75


def test_a_refinement_without_spreads_gives_no_cap_reading():
    # a cylinder refinement whose spreads are not finite (a degenerate face) says nothing about its cap
    from lv3d.cylinder import Cylinder
    from lv3d.describe import cap_candidates
    from lv3d.scene import Face, SceneObject

    square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    side = Face("o_f1", square, "depth", surface="cylinder", cylinder=Cylinder((0.0, -1.0, 0.0), (0.0, 0.0, 1.0), 0.04))
    lid = Face("o_f2", square, "depth")
    obj = SceneObject("o", [side, lid], [("o_f1", "o_f2")])
    faces = [_face_result(side, fit=_cylinder_fit((0.0, -1.0, 0.0), np.nan)),
             _face_result(lid, (0.0, -1.0, 0.0, 0.1), 0.5)]
    assert cap_candidates(obj, faces, 1.0) == []


def test_a_round_face_keeps_its_polygon_facts_only_as_far_as_it_may_be_a_polygon():
    # a can's lid read as a hexagon and as circular, a can's side as a quadrilateral and cylindrical, a box face
    # with no round reading: each polygon fact times (1 - the face's strongest round reading); others unchanged
    from lv3d.describe import POLYGON_PREDS, ROUND_PREDS, polygon_given_round

    cands = [("hexagon", ("lid",), 0.96, 6.0), ("circular", ("lid",), 0.75, 3.0), ("regular", ("lid",), 0.8, 1.1),
             ("quadrilateral", ("side",), 0.9, 4.0), ("cylindrical", ("side",), 0.99, 0.04),
             ("conical", ("side",), 0.2, 5.0), ("rectangle", ("box",), 0.95, 1.5),
             ("perpendicular", ("side", "lid"), 0.3, 80.0), ("face_of", ("o", "lid"), 0.9, None)]
    got = {(c[0], c[1]): c for c in polygon_given_round(cands)}
    assert got[("hexagon", ("lid",))][2] == pytest.approx(0.96 * 0.25)
    assert got[("regular", ("lid",))][2] == pytest.approx(0.8 * 0.25)
    assert got[("quadrilateral", ("side",))][2] == pytest.approx(0.9 * 0.01)
    assert got[("quadrilateral", ("side",))][3] == 4.0  # the measured value stays
    for key in [("circular", ("lid",)), ("cylindrical", ("side",)), ("conical", ("side",)), ("rectangle", ("box",)),
                ("perpendicular", ("side", "lid")), ("face_of", ("o", "lid"))]:
        assert got[key] == next(c for c in cands if (c[0], c[1]) == key)
    assert polygon_given_round([("hexagon", ("f",), 0.9, 6.0)]) == [("hexagon", ("f",), 0.9, 6.0)]
    # the two vocabularies are the contract's predicates about one face, and they do not overlap
    assert POLYGON_PREDS <= set(PREDICATES) and ROUND_PREDS <= set(PREDICATES)
    assert not POLYGON_PREDS & ROUND_PREDS
    assert all(PREDICATES[p][0] == 1 for p in POLYGON_PREDS | ROUND_PREDS)


ANGLES = ("perpendicular", "parallel", "acute", "obtuse")


def _angle_readings(scene, frame, refine):
    from lv3d.describe import calibration_features, ground

    cands, results = ground(scene, frame, refine=refine, calibrate=False)
    angle = [c for c in cands if c[0] in ANGLES]
    return angle, calibration_features(angle, results), cands, results


@pytest.mark.parametrize("refine", [False, True])
def test_rgbd_reads_the_angle_between_two_planes_as_depth_does_whatever_the_print(refine):
    # print on the faces (stripes of another colour) moves colour's edges and every outline measurement read
    # against them; the angle facts of an rgbd scene, and the measurements their calibration reads, are depth's
    scene, frame = _scene("rgbd", np.random.default_rng(7))
    plain = _angle_readings(scene, frame, refine)
    printed = dataclasses.replace(frame, color=frame.color.copy())
    printed.color[::9] = (250, 250, 250)
    printed.color[:, ::13] = (0, 0, 0)
    striped = _angle_readings(scene, printed, refine)
    assert plain[0] and [c[0] for c in plain[0]] == [c[0] for c in striped[0]]
    for (_, args, p, value), (_, args2, p2, value2) in zip(plain[0], striped[0]):
        assert args == args2
        assert p == pytest.approx(p2, abs=0.02 if refine else 1e-6)
        assert value == pytest.approx(value2, abs=0.5 if refine else 1e-6)
    if not refine:  # the geometry is perception's in both: the angle's measurements are the same numbers
        for f, g in zip(plain[1], striped[1]):
            assert f.keys() == g.keys() and all(f[k] == pytest.approx(g[k], abs=1e-6) for k in f)
    # the faces' own facts still read colour: the print moves their outline measurements
    own = [[fr.features for res in r[3] for fr in res.faces] for r in (plain, striped)]
    assert any(f[k] != pytest.approx(g[k], rel=1e-3) for f, g in zip(*own) for k in ("edge_scale2", "min_turn_z"))
    faces = [fr for res in plain[3] for fr in res.faces]
    assert all(fr.angle_features is not None and fr.angle_features["sides"] == fr.features["sides"] for fr in faces)


def test_outside_rgbd_the_angle_facts_read_the_faces_own_measurements():
    from lv3d.describe import calibration_features, ground

    scene, frame = _scene("depth", np.random.default_rng(8))
    cands, results = ground(scene, frame, calibrate=False)
    faces = [fr for res in results for fr in res.faces]
    assert faces and all(fr.angle_features is None for fr in faces)
    perp = [c for c in cands if c[0] == "perpendicular"]
    side = [c for c in cands if c[0] == "face_of"]
    f_perp, f_side = calibration_features(perp, results), calibration_features(side, results)
    weakest = min(fr.features["support"] for fr in faces)
    assert f_perp[0]["support"] == pytest.approx(weakest)
    assert {f["support"] for f in f_side} == {fr.features["support"] for fr in faces}


def test_two_sides_meeting_at_a_regular_polygons_corner_angle_name_that_polygon():
    # a pentagonal prism's sides meet at 108 deg, a hexagonal one's at 120; a box's at 90 read as neither, and a
    # measurement halfway between two corners' angles is as likely one as the other
    from scipy.special import ndtr

    from lv3d.describe import regular_corner_candidates
    from lv3d.facts import REGULAR_CORNERS, regular_corner_range

    assert regular_corner_range(5) == pytest.approx((100.0, 114.545), abs=1e-3)
    assert regular_corner_range(6) == pytest.approx((114.545, 124.615), abs=1e-3)

    def read(dih, sd):
        return {c[0]: c for c in regular_corner_candidates(("f1", "f2"), dih, sd, 1.0)}

    pent, hexa = read(108.0, 0.5), read(120.0, 0.5)
    assert set(pent) == set(REGULAR_CORNERS)
    assert pent["pentagonal_dihedral"][2] > 0.99 and pent["hexagonal_dihedral"][2] < 0.01
    assert hexa["hexagonal_dihedral"][2] > 0.99 and hexa["pentagonal_dihedral"][2] < 0.01
    assert all(c[1] == ("f1", "f2") and c[3] == 120.0 for c in hexa.values())
    assert all(c[2] < 1e-6 for c in read(90.0, 0.5).values())
    mid = read(regular_corner_range(6)[0], 3.0)
    assert mid["pentagonal_dihedral"][2] == pytest.approx(mid["hexagonal_dihedral"][2], abs=0.02)
    # the spread is grounding's Laplace spread with the model-error floor (1 degree here) added in quadrature
    sd = np.hypot(2.0, 1.0)
    want = ndtr((114.545 - 112.0) / sd) - ndtr((100.0 - 112.0) / sd)
    assert read(112.0, 2.0)["pentagonal_dihedral"][2] == pytest.approx(want, abs=1e-3)
    assert regular_corner_candidates(("f1", "f2"), float("nan"), 1.0, 1.0) == []
