"""Joint refinement of an object and the confidences of its facts, on a synthetic two-face wedge."""

import numpy as np
import pytest

import grounding
from grounding._confidence import ACUTE_BELOW_DEG

from grounding_synth import INTR, plane_through, project, render_polygons, sample_face, wedge

SUPPORT = np.array([0.0, -0.8, -0.6, 0.5])


def _problem(theta, rng, noise_px=1.5, plane_noise=0.03):
    faces3d, adj = wedge(theta)
    polys = [project(f) for f in faces3d]
    image = render_polygons(polys, [(200, 120, 60), (60, 140, 210)])
    field = grounding.edge_distance_field(image)
    truth_planes = [plane_through(*f[:3]) for f in faces3d]
    first = []
    for p in truth_planes:
        q = p.copy()
        q[:3] += rng.normal(0, plane_noise, 3)
        q[:3] /= np.linalg.norm(q[:3])
        first.append(q)
    start = [p + rng.normal(0, noise_px, p.shape) for p in polys]
    prob, index = grounding.pack_object(start, intrinsics=INTR, planes=first,
                                        points=[sample_face(f, 300, rng) for f in faces3d],
                                        adjacency=adj, support_plane=SUPPORT)
    return prob, index, field, polys, truth_planes


def test_joint_refinement_recovers_a_right_angled_wedge():
    rng = np.random.default_rng(3)
    prob, index, field, polys, planes = _problem(90.0, rng, noise_px=1.0)
    g = grounding.ground_object(prob, field, True)
    assert int(g.status) == 0
    verts = np.asarray(g.vertices)
    for f in range(2):
        assert np.abs(verts[index[f, :4]] - polys[f]).max() < 0.8
    # the two faces share their edge's two vertices: one unknown each, not two
    assert len(set(index[0, :4]) & set(index[1, :4])) == 2
    for f in range(2):
        n = np.asarray(g.planes[f, :3])
        assert np.degrees(np.arccos(min(1.0, abs(n @ planes[f][:3])))) < 1.0
    dihedral = float(g.quantities.dihedral_deg[0, 1])
    assert abs(dihedral - 90.0) < 1.5
    c = g.conf
    assert float(c.p_perpendicular[0, 1]) > 0.97
    assert float(c.p_acute[0, 1]) < 0.02 and float(c.p_obtuse[0, 1]) < 0.02
    assert float(c.p_parallel[0, 1]) < 0.02
    assert np.all(np.asarray(c.p_sides[:2]) > 0.9)
    assert np.all(np.asarray(c.sides[:2]) == 4)


def test_an_angle_at_the_edge_of_its_tolerance_is_uncertain():
    rng = np.random.default_rng(4)
    prob, _, field, _, _ = _problem(ACUTE_BELOW_DEG, rng)
    g = grounding.ground_object(prob, field, True)
    p = float(g.conf.p_perpendicular[0, 1])
    assert 0.15 < p < 0.85
    assert abs(p + float(g.conf.p_acute[0, 1]) - 1.0) < 0.05  # the two share the boundary


def test_refinement_reduces_vertex_error_and_unrefined_still_has_confidences():
    rng = np.random.default_rng(5)
    prob, index, field, polys, _ = _problem(90.0, rng, noise_px=2.5)
    raw = grounding.ground_object(prob, field, False)
    ref = grounding.ground_object(prob, field, True)

    def err(g):
        v = np.asarray(g.vertices)
        return np.mean([np.linalg.norm(v[index[f, :4]] - polys[f], axis=1).mean() for f in range(2)])

    assert err(ref) < 0.5 * err(raw)
    assert np.all(np.isfinite(np.asarray(raw.conf.p_perpendicular)))
    assert 0.0 <= float(raw.conf.p_perpendicular[0, 1]) <= 1.0


def test_faces_without_planes_get_no_metric_confidences():
    faces3d, adj = wedge(90.0)
    polys = [project(f) for f in faces3d]
    field = grounding.edge_distance_field(render_polygons(polys, [(200, 120, 60), (60, 140, 210)]))
    prob, _ = grounding.pack_object(polys, intrinsics=INTR, adjacency=adj)
    g = grounding.ground_object(prob, field, True)
    c = g.conf
    for name in ("p_square", "p_rectangle", "p_regular", "p_horizontal", "p_vertical"):
        assert np.all(np.asarray(getattr(c, name)) == 0.0), name
    assert np.all(np.asarray(c.p_perpendicular) == 0.0)
    assert float(c.p_sides[0]) > 0.9


@pytest.mark.parametrize("n", [3, 5, 6])
def test_side_count_confidence_falls_for_a_nearly_straight_corner(n):
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    poly = np.stack([320 + 120 * np.cos(ang), 240 + 120 * np.sin(ang)], 1)
    field = grounding.edge_distance_field(render_polygons([poly], [(220, 220, 220)]))
    clean, _ = grounding.pack_object([poly], intrinsics=INTR)
    # the same outline with a spurious vertex in the middle of its first side
    extra = np.insert(poly, 1, (poly[0] + poly[1]) / 2 + np.array([0.3, 0.0]), axis=0)
    spurious, _ = grounding.pack_object([extra], intrinsics=INTR)
    c_clean = grounding.ground_object(clean, field, True).conf
    c_spur = grounding.ground_object(spurious, field, True).conf
    assert float(c_clean.p_sides[0]) > 0.9
    assert float(c_spur.p_sides[0]) < 0.2
    # without a plane no (n - 1)-gon: in the image a true corner seen obliquely turns little too (tests/test_describe.py
    # has the face with a plane)
    assert float(c_spur.p_fewer[0]) == 0.0 and float(c_clean.p_fewer[0]) == 0.0



@pytest.mark.parametrize("with_planes", [True, False])
def test_corner_z_is_the_turn_past_the_corner_limit_that_the_side_count_reads(with_planes):
    """``corner_z``, which the calibration reads as the weakest corner's margin, is the corner test itself:
    (turn - limit) / floored spread, on the plane where the face has one (limit 35 deg) and in the image without
    (15 deg); P(sides) is the product of Phi(z) over the corners times the edge support."""
    from jax.scipy.special import ndtr

    from grounding._confidence import CORNER_TURN_MIN_DEG, CORNER_TURN_MIN_PLANE_DEG, SUPPORT_FULL, Floors

    prob, _, field, polys, _ = _problem(90.0, np.random.default_rng(7))
    if not with_planes:
        prob, _ = grounding.pack_object(polys, intrinsics=INTR, adjacency=wedge(90.0)[1])
    c = grounding.ground_object(prob, field, True)
    which, limit, floor = ("corner3d_deg", CORNER_TURN_MIN_PLANE_DEG, Floors().corner3d_deg) if with_planes \
        else ("corner_deg", CORNER_TURN_MIN_DEG, Floors().corner_deg)
    turn = 180.0 - np.asarray(getattr(c.quantities, which))[:2, :4]
    sd = np.hypot(np.asarray(getattr(c.std, which))[:2, :4], floor)
    z = np.asarray(c.conf.corner_z)[:2, :4]
    np.testing.assert_allclose(z, (turn - limit) / sd, rtol=1e-5)
    support = np.clip(np.asarray(c.conf.edge_support)[:2] / SUPPORT_FULL, 0, 1)
    np.testing.assert_allclose(np.asarray(c.conf.p_sides)[:2], np.prod(np.asarray(ndtr(z)), 1) * support, rtol=1e-5)
