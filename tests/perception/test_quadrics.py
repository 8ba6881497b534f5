"""Spheres and cones in depth (lv3d/perception/depth/quadrics.py): noisy synthetic surfaces fitted, their
lookalikes (a cylinder's side, a pyramid's faces, a flat face) refused, and rendered balls and cones read as one
face of their kind."""

import numpy as np
import pytest

from lv3d.cone import Cone
from lv3d.describe import quadric_candidates
from lv3d.perception import perceive
from lv3d.perception.depth.quadrics import (QuadricSettings, cone_evidence, cone_from_normals, cone_readings,
                                            object_quadrics, refine_cone, refine_sphere, sample_sphere, sphere_evidence)
from lv3d.plane import Plane
from lv3d.render import render_scene
from lv3d.scene import Face
from lv3d.sphere import Sphere

CENTRE = np.array([0.01, -0.02, 0.7])


def _noisy(pts, nrm, rng, sigma_m=0.001, normal_sd=0.05):
    """Points moved along the line of sight by ``sigma_m`` (a depth sensor's noise) and normals turned by about
    ``normal_sd`` radians."""
    rays = pts / np.linalg.norm(pts, axis=-1, keepdims=True)
    pts = pts + rays * rng.normal(0, sigma_m, pts.shape[:-1] + (1,))
    nrm = nrm + rng.normal(0, normal_sd, nrm.shape)
    return pts, nrm / np.linalg.norm(nrm, axis=-1, keepdims=True)


def _sphere_cap(rng, radius=0.05, n=60):
    """A grid (n, n) of points and outward normals on the half of a sphere that faces the camera."""
    th, ph = np.meshgrid(np.radians(np.linspace(-75, 75, n)), np.radians(np.linspace(-75, 75, n)), indexing="ij")
    nrm = np.stack([np.sin(ph) * np.cos(th), np.sin(th), -np.cos(ph) * np.cos(th)], axis=-1)
    return _noisy(CENTRE + radius * nrm, nrm, rng)


def _cone_side(rng, alpha_deg=30.0, height=0.09, n=60):
    """A grid (n, n) of points and outward normals on the front of a cone standing apex up (camera y is down)."""
    a = np.array([0.0, 1.0, 0.0])
    t = np.radians(alpha_deg)
    h, ph = np.meshgrid(np.linspace(0.01, height, n), np.radians(np.linspace(-80, 80, n)), indexing="ij")
    u = np.stack([np.sin(ph), 0 * ph, -np.cos(ph)], axis=-1)
    apex = CENTRE - height / 2 * a
    pts = apex + h[..., None] * a + (h * np.tan(t))[..., None] * u
    return _noisy(pts, np.cos(t) * u - np.sin(t) * a, rng), apex, a


def _cylinder_side(rng, radius=0.04, n=60):
    y, ph = np.meshgrid(np.linspace(-0.05, 0.05, n), np.radians(np.linspace(-80, 80, n)), indexing="ij")
    nrm = np.stack([np.sin(ph), 0 * ph, -np.cos(ph)], axis=-1)
    pts = CENTRE + radius * nrm + y[..., None] * np.array([0.0, 1.0, 0.0])
    return _noisy(pts, nrm, rng)


def _search(pts, nrm, plane_of=None, planes=(), settings=QuadricSettings()):
    box = np.ones(pts.shape[:2], bool)
    p, n = pts.reshape(-1, 3), nrm.reshape(-1, 3)
    po = np.full(len(p), -1) if plane_of is None else plane_of.reshape(-1)
    return object_quadrics(p, n, box, po, list(planes), dist_m=0.005, extent_m=0.15, cell_m=0.0015, min_cells=60,
                           seed=0, settings=settings)


def test_a_noisy_sphere_is_one_spherical_face():
    pts, nrm = _sphere_cap(np.random.default_rng(0))
    res = _search(pts, nrm)
    assert [f[0] for f in res.faces] == ["sphere"]
    s = res.faces[0][1]
    assert abs(s.radius - 0.05) < 0.05 * 0.03
    assert np.linalg.norm(np.asarray(s.centre) - CENTRE) < 0.002
    assert res.faces[0][2].mean() > 0.9


def _bowl_inside(rng, radius=0.07, n=60):
    """A grid (n, n) of points on the inside of a bowl seen from above it (the far half of a sphere about CENTRE,
    the camera looking down its axis z), with the normals of that side: towards the centre, to the camera."""
    th, ph = np.meshgrid(np.radians(np.linspace(-60, 60, n)), np.radians(np.linspace(-60, 60, n)), indexing="ij")
    out = np.stack([np.sin(ph) * np.cos(th), np.sin(th), np.cos(ph) * np.cos(th)], axis=-1)  # away from the camera
    return _noisy(CENTRE + radius * out, -out, rng)


def test_a_bowls_inside_is_one_spherical_face_seen_from_within():
    pts, nrm = _bowl_inside(np.random.default_rng(2))
    res = _search(pts, nrm)
    assert [f[0] for f in res.faces] == ["sphere"]
    s = res.faces[0][1]
    assert s.side == -1.0 and abs(s.radius - 0.07) < 0.07 * 0.03
    assert np.linalg.norm(np.asarray(s.centre) - CENTRE) < 0.003
    assert res.faces[0][2].mean() > 0.9
    # a ball's outside is still one (side 1), and the normals each side shows point to the camera
    ball = _search(*_sphere_cap(np.random.default_rng(0))).faces[0][1]
    assert ball.side == 1.0
    assert np.all(s.normals(pts.reshape(-1, 3))[:, 2] < 0)


def test_a_sphere_from_pairs_of_oriented_points_then_least_squares():
    rng = np.random.default_rng(1)
    pts, nrm = _sphere_cap(rng)
    p, n = pts.reshape(-1, 3), nrm.reshape(-1, 3)
    first = sample_sphere(p, n, 0.005, np.cos(np.radians(25)), 0.005, 0.5, np.random.default_rng(0))
    assert first is not None and abs(first.radius - 0.05) < 0.01
    fine = refine_sphere(p, first)
    assert fine is not None and abs(fine.radius - 0.05) < 0.001


def test_a_noisy_cone_is_one_conical_face():
    (pts, nrm), apex, axis = _cone_side(np.random.default_rng(2))
    res = _search(pts, nrm)
    assert [f[0] for f in res.faces] == ["cone"]
    c = res.faces[0][1]
    assert abs(c.half_angle_deg - 30.0) < 1.5
    assert np.degrees(np.arccos(np.clip(np.dot(c.axis, axis), -1, 1))) < 3.0
    assert np.linalg.norm(np.asarray(c.apex) - apex) < 0.005
    assert np.isfinite(c.height) and 0.07 < c.height < 0.1


def test_a_cone_from_its_normals_then_least_squares():
    (pts, nrm), apex, axis = _cone_side(np.random.default_rng(3), alpha_deg=22.0)
    p, n = pts.reshape(-1, 3), nrm.reshape(-1, 3)
    start = cone_from_normals(p, n)
    assert start is not None and abs(start.half_angle_deg - 22.0) < 3.0
    fine = refine_cone(p, start)
    assert fine is not None and abs(fine.half_angle_deg - 22.0) < 1.0


def test_a_cylinder_side_is_neither_sphere_nor_cone():
    pts, nrm = _cylinder_side(np.random.default_rng(4))
    res = _search(pts, nrm)
    assert res.faces == []
    assert res.unconverged >= 0
    # the cone its normals give closes to a half-angle near 0 (or none at all)
    c = cone_from_normals(pts.reshape(-1, 3), nrm.reshape(-1, 3))
    assert c is None or c.half_angle_deg < 5.0


def test_a_pyramid_tangent_to_a_cone_is_no_cone():
    # a square pyramid's two front faces: planes through the apex, each tangent to a cone of 30 deg along a line
    rng = np.random.default_rng(5)
    a, t, apex = np.array([0.0, 1.0, 0.0]), np.radians(30), CENTRE - 0.045 * np.array([0.0, 1.0, 0.0])
    pts, nrm, plane_of, planes = [], [], [], []
    for k, ph in enumerate(np.radians([-45.0, 45.0])):
        u = np.array([np.sin(ph), 0.0, -np.cos(ph)])
        side = np.array([np.cos(ph), 0.0, np.sin(ph)])
        h, s = np.meshgrid(np.linspace(0.01, 0.09, 60), np.linspace(-1, 1, 30), indexing="ij")
        p = apex + h[..., None] * a + (h * np.tan(t))[..., None] * (u + s[..., None] * side)
        n = np.cos(t) * u - np.sin(t) * a
        pts.append(p)
        nrm.append(np.broadcast_to(n, p.shape))
        plane_of.append(np.full(h.shape, k))
        planes.append(Plane.from_arrays(n, -float(n @ apex)))
    p, n = _noisy(np.concatenate(pts, axis=1), np.concatenate(nrm, axis=1), rng)
    res = _search(p, n, np.concatenate(plane_of, axis=1), planes)
    assert res.faces == []


def test_a_flat_face_is_no_sphere():
    rng = np.random.default_rng(6)
    x, y = np.meshgrid(np.linspace(-0.05, 0.05, 60), np.linspace(-0.05, 0.05, 60), indexing="ij")
    pts = np.stack([x, y, 0.7 + 0.3 * x], axis=-1)
    n = np.array([-0.3, 0.0, 1.0])
    n = -n / np.linalg.norm(n)
    p, nrm = _noisy(pts, np.broadcast_to(n, pts.shape).copy(), rng)
    plane = Plane.from_arrays(n, -float(n @ pts[30, 30]))
    res = _search(p, nrm, np.zeros(x.shape, int), [plane])
    assert res.faces == []


def test_evidence_is_the_share_of_the_simpler_surface_residual_explained():
    rng = np.random.default_rng(7)
    pts, _ = _sphere_cap(rng)
    p = pts.reshape(-1, 3)
    assert sphere_evidence(p, Sphere(tuple(CENTRE), 0.05)) > 0.95
    flat = np.stack([rng.uniform(-0.05, 0.05, 500), rng.uniform(-0.05, 0.05, 500), 0.7 + rng.normal(0, 0.001, 500)], 1)
    assert sphere_evidence(flat, Sphere((0.0, 0.0, 0.7 + 5.0), 5.0)) < 0.2
    (cpts, _), apex, axis = _cone_side(rng)
    c = Cone(tuple(apex), tuple(axis), 30.0, 0.09)
    assert cone_evidence(cpts.reshape(-1, 3), c) > 0.8
    # a cylinder's side read as a narrow cone: the cylinder explains it as well, so little evidence of a cone
    ypts, _ = _cylinder_side(rng)
    narrow = Cone((CENTRE[0], CENTRE[1] - 2.0, CENTRE[2]), (0.0, 1.0, 0.0), float(np.degrees(np.arctan(0.04 / 2.0))),
                  2.05)
    assert cone_evidence(ypts.reshape(-1, 3), narrow) < 0.2
    assert sphere_evidence(p[:5], Sphere(tuple(CENTRE), 0.05)) is None


def test_a_face_read_as_a_cone_is_also_read_as_the_cylinder_it_is_nested_in():
    rng = np.random.default_rng(9)
    # a cylinder's side taken for a narrow cone: little conical, mostly cylindrical, with the cylinder's radius
    ypts, _ = _cylinder_side(rng)
    narrow = Cone((CENTRE[0], CENTRE[1] - 2.0, CENTRE[2]), (0.0, 1.0, 0.0), float(np.degrees(np.arctan(0.04 / 2.0))),
                  2.05)
    conical, (cylindrical, radius) = cone_readings(ypts.reshape(-1, 3), narrow)
    assert conical < 0.2 and cylindrical > 0.7
    assert conical == pytest.approx(cone_evidence(ypts.reshape(-1, 3), narrow))
    assert radius == pytest.approx(0.04, rel=0.05)
    # a true cone's side: conical, and the cylinder reading is what the cone leaves over
    (cpts, _), apex, axis = _cone_side(rng)
    conical, (cylindrical, _) = cone_readings(cpts.reshape(-1, 3), Cone(tuple(apex), tuple(axis), 30.0, 0.09))
    assert conical > 0.8 and cylindrical < 1.0 - conical + 1e-9
    assert cone_readings(cpts.reshape(-1, 3)[:5], Cone(tuple(apex), tuple(axis), 30.0, 0.09)) is None


def test_facts_of_spherical_and_conical_faces_come_from_the_measurement():
    rng = np.random.default_rng(8)
    pts, _ = _sphere_cap(rng)
    poly = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    face = Face("s0_o1_f1", poly, "depth", points=pts.reshape(-1, 3), surface="sphere",
                sphere=Sphere(tuple(CENTRE), 0.05))
    [(pred, args, conf, value)] = quadric_candidates(face)
    assert pred == "spherical" and args == ("s0_o1_f1",) and 0.9 < conf <= 1.0 and value == pytest.approx(0.05)
    (cpts, _), apex, axis = _cone_side(rng)
    cface = Face("s0_o1_f2", poly, "depth", points=cpts.reshape(-1, 3), surface="cone",
                 cone=Cone(tuple(apex), tuple(axis), 30.0, 0.09))
    [(pred, _, conf, value), (pred2, args2, conf2, value2)] = quadric_candidates(cface)
    assert pred == "conical" and 0.5 < conf <= 1.0 and value == pytest.approx(30.0)
    # the cylinder it is nested in, with what the cone leaves of its probability
    assert pred2 == "cylindrical" and args2 == ("s0_o1_f2",) and 0.0 <= conf2 <= 1.0 - conf + 1e-9 and value2 > 0
    d = cface.to_dict()
    assert d["surface"] == "cone" and d["cone"]["half_angle_deg"] == 30.0 and d["sphere"] is None
    assert quadric_candidates(Face("s0_o1_f3", poly, "depth", points=cpts.reshape(-1, 3))) == []


@pytest.mark.parametrize("cls,preset,seed", [("sphere", "clean", 1000), ("cone", "clean", 1001),
                                             ("sphere", "realsense", 1002), ("cone", "realsense", 1003)])
def test_rendered_balls_and_cones_are_one_face_of_their_kind(cls, preset, seed):
    frame, faces = render_scene(cls, seed, noise=preset, width=320, height=240)
    scene = perceive(frame, "depth")
    target = scene.target()
    kinds = [f.surface for f in target.faces]
    assert kinds.count(cls) == 1, kinds
    assert "cylinder" not in kinds
    face = next(f for f in target.faces if f.surface == cls)
    truth = next(f["surface"] for f in frame.meta["truth"]["faces"] if f.get("surface", {}).get("type") == cls)
    if cls == "sphere":
        assert abs(face.sphere.radius - truth["radius"]) < 0.05 * truth["radius"]
    else:
        assert abs(face.cone.half_angle_deg - truth["half_angle_deg"]) < 3.0
    assert scene.unconverged_fits >= 0
    assert scene.to_dict()["objects"]


@pytest.mark.parametrize("cls,preset,seed", [("cube", "clean", 1000), ("cuboid", "realsense", 1001),
                                             ("square_pyramid", "realsense", 1002), ("cylinder", "realsense", 1003)])
def test_rendered_boxes_pyramids_and_cylinders_get_no_sphere_or_cone(cls, preset, seed):
    frame, _ = render_scene(cls, seed, noise=preset, width=320, height=240)
    scene = perceive(frame, "depth")
    assert not [f.surface for o in scene.objects for f in o.faces if f.surface in ("sphere", "cone")]
