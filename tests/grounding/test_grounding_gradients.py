"""Every residual, quantity and confidence has finite gradients, also at degenerate points
(a fit that is exact, a face without a plane, padded slots)."""

import jax
import jax.numpy as jnp
import numpy as np

import grounding
from grounding import _confidence, _joint, _uncertainty

from grounding_synth import INTR, plane_through, project, render_polygons, sample_face, wedge


def _setup():
    faces3d, adj = wedge(90.0)
    polys = [project(f) for f in faces3d]
    field = jnp.asarray(grounding.edge_distance_field(render_polygons(polys, [(200, 120, 60), (60, 140, 210)])))
    rng = np.random.default_rng(0)
    prob, _ = grounding.pack_object(
        polys, intrinsics=INTR, planes=[plane_through(*f[:3]) for f in faces3d],
        points=[sample_face(faces3d[0], 100, rng), None], adjacency=adj, support_plane=np.array([0.0, -0.8, -0.6, 0.5]))
    return prob, field


def test_residual_and_quantity_gradients_are_finite():
    prob, field = _setup()
    params = _joint.zero_params(prob)
    cfg = grounding.Settings()

    def loss(p):
        r = _joint._flat_residuals(p, (prob, field, cfg))
        q = jax.flatten_util.ravel_pytree(_uncertainty.quantities(p, prob))[0]
        return jnp.sum(r * r) + jnp.sum(q)

    g = jax.jit(jax.grad(loss))(params)
    for leaf in jax.tree.leaves(g):
        assert np.all(np.isfinite(np.asarray(leaf)))


def test_confidence_gradients_are_finite():
    prob, field = _setup()
    params = _joint.zero_params(prob)
    cov, _ = jax.jit(_uncertainty.param_covariance)(params, prob, field, grounding.Settings())
    q, jq, std = jax.jit(_uncertainty.propagate)(params, prob, cov)

    def total(corners, tilt):
        qq = q.__class__(**{**q.__dict__, "corner_deg": corners, "tilt_deg": tilt})
        c = _confidence.confidences(qq, std, jq, cov, prob.face_vmask, prob.face_mask, prob.has_plane,
                                    prob.has_support, prob.adjacency, jnp.ones(prob.face_mask.shape),
                                    grounding.Floors())
        return jnp.sum(c.p_sides) + jnp.sum(c.p_horizontal) + jnp.sum(c.p_vertical)

    # corners that turn by about the corner threshold: side-count confidences are far from saturated
    g = jax.jit(jax.grad(total, argnums=(0, 1)))(jnp.full_like(q.corner_deg, 166.0), q.tilt_deg)
    assert all(np.all(np.isfinite(np.asarray(x))) for x in g)
    assert np.any(np.asarray(g[0]) != 0.0)


def test_interval_probability():
    assert abs(float(grounding.interval(90.0, 1.0, 80.0, 100.0)) - 1.0) < 1e-6
    assert abs(float(grounding.interval(80.0, 2.0, 80.0, 100.0)) - 0.5) < 1e-3
    assert float(_confidence.interval(50.0, 2.0, 80.0, 100.0)) < 1e-6
