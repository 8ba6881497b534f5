"""Depth-only objects replaced by colour's view of the same solid, only where depth is at its noise limit."""

import numpy as np

from lv3d.perception.confirm import renumber, replace_unconfirmed, unconfirmed
from lv3d.perception.support import noise_threshold
from lv3d.scene import Face, SceneObject

SHAPE = (120, 160)
Z = 0.6


def _square(u0, v0, u1, v1):
    return np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]], float)


def _depth_object(oid, polys, fit_ratio):
    pts = np.random.default_rng(0).normal([0, 0, Z], 0.01, (50, 3))
    rms = fit_ratio * noise_threshold(Z)
    faces = [Face(f"{oid}_f{j}", p, "depth", points=pts, plane_rms_m=rms) for j, p in enumerate(polys, 1)]
    return SceneObject(oid, faces, [], int(sum(np.prod(p.max(0) - p.min(0)) for p in polys)), (0.0, 0.0))


def _colour_object(oid, polys):
    faces = [Face(f"{oid}_f{j}", p, "rgb", edge_support=1.0) for j, p in enumerate(polys, 1)]
    return SceneObject(oid, faces, [(faces[0].id, faces[1].id)] if len(faces) > 1 else [], 5000, (80.0, 60.0))


def test_noisy_fragments_give_way_to_the_colour_view():
    # depth broke one solid into two noisy fragments; colour sees two faces over both
    frags = [_depth_object("s_o1", [_square(40, 30, 80, 90)], 0.8), _depth_object("s_o2", [_square(80, 30, 120, 90)], 0.7)]
    colour = [_colour_object("s_o1", [_square(40, 30, 82, 90), _square(82, 30, 120, 90)])]
    assert unconfirmed(frags) == [0, 1]
    out = replace_unconfirmed(frags, unconfirmed(frags), colour, SHAPE, "s")
    assert len(out) == 1
    assert [f.provenance for f in out[0].faces] == ["rgb", "rgb"]
    assert [f.id for f in out[0].faces] == ["s_o1_f1", "s_o1_f2"] and out[0].adjacency == [("s_o1_f1", "s_o1_f2")]


def test_depth_that_fits_its_noise_model_is_kept():
    frags = [_depth_object("s_o1", [_square(40, 30, 80, 90)], 0.2), _depth_object("s_o2", [_square(80, 30, 120, 90)], 0.25)]
    colour = [_colour_object("s_o1", [_square(40, 30, 82, 90), _square(82, 30, 120, 90)])]
    assert unconfirmed(frags) == []
    assert replace_unconfirmed(frags, unconfirmed(frags), colour, SHAPE, "s") is frags


def test_implausible_colour_objects_and_confirmed_objects_are_not_replaced():
    frags = [_depth_object("s_o1", [_square(40, 30, 80, 90)], 0.8)]
    many = [_colour_object("s_o1", [_square(40 + 6 * k, 30, 46 + 6 * k, 90) for k in range(6)])]  # six faces
    assert replace_unconfirmed(frags, unconfirmed(frags), many, SHAPE, "s") is frags
    fused = SceneObject("s_o2", [Face("s_o2_f1", _square(80, 30, 120, 90), "rgbd")], [], 2400, (100.0, 60.0))
    over_both = [_colour_object("s_o1", [_square(40, 30, 82, 90), _square(82, 30, 120, 90)])]
    # colour lies on a fragment and on an object colour and depth agree on: both stay as they are
    assert replace_unconfirmed(frags + [fused], unconfirmed(frags + [fused]), over_both, SHAPE, "s") == frags + [fused]


def test_renumber_orders_largest_first():
    a = SceneObject("x_o1", [Face("x_o1_f1", _square(0, 0, 10, 10), "rgb")], [], 100, (5.0, 5.0))
    b = SceneObject("x_o2", [Face("x_o2_f1", _square(0, 0, 30, 30), "rgb")], [], 900, (15.0, 15.0))
    out = renumber([a, b], "x")
    assert [o.id for o in out] == ["x_o1", "x_o2"] and out[0].pixel_count == 900
    assert out[0].faces[0].id == "x_o1_f1"
