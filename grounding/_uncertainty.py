"""Laplace (Gauss-Newton) covariance of the refined geometry and its push-forward to the quantities
facts speak of.

At the optimum, ``Cov(theta) = (sum_b J_b^T J_b / s_b^2 + J_prior^T J_prior)^-1`` where ``J_b`` is the
Jacobian of residual block ``b`` (edges, depth, links; already whitened by its a priori noise) and
``s_b^2 = chi2_b / dof_b`` rescales a block whose residuals are larger than its noise model says
(never below ``MIN_SCALE2``). For edges, ``J`` is that of the point-to-line distance of each sample
across its side (unit gradient along the side's normal, weighted by the sample's robust weight): an
edge-distance field is flat at its minimum, so its own Jacobian vanishes exactly where the fit is best. A
derived quantity ``q(theta)`` gets ``Cov(q) = J_q Cov(theta) J_q^T`` with ``J_q`` from ``jax.jacfwd``.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jax.flatten_util import ravel_pytree
from jaxtyping import Array, Float

from ._joint import Params, edge_distances, edge_mask, face_vertices, geometry, residual_blocks
from ._plane import backproject
from ._polygon import (angle_deg, corner_angles_deg, edge_samples, opposite_side_deviation_deg, ring, safe_norm,
                       side_lengths_px)
from ._problem import EDGE_SAMPLES, ObjectProblem, Settings

MIN_SCALE2 = 0.25  # a block may claim at most half its a priori noise (spread), however small its residuals


class Quantities(eqx.Module):
    """What facts are read from. F faces, S vertex slots; angles in degrees."""

    side_px: Float[Array, "F S"]       # image side lengths, pixels
    corner_deg: Float[Array, "F S"]    # image interior angles
    para_dev_deg: Float[Array, "F 2"]  # image: opposite sides' deviation from parallel (quadrilaterals)
    log_side_m: Float[Array, "F S"]    # log of side lengths on the face plane (log metres)
    corner3d_deg: Float[Array, "F S"]  # interior angles on the face plane
    tilt_deg: Float[Array, " F"]       # angle between face plane and support plane, folded to [0, 90]
    dihedral_deg: Float[Array, "F F"]  # interior dihedral 180 - angle(n_a, n_b) (normals are outward for visible faces)
    parallel_deg: Float[Array, "F F"]  # angle between the planes, folded to [0, 90]


def quantities(params: Params, prob: ObjectProblem) -> Quantities:
    verts, planes = geometry(params, prob)
    fv = face_vertices(verts, prob)
    side_px = jax.vmap(side_lengths_px)(fv, prob.face_vmask)
    corner = jax.vmap(corner_angles_deg)(fv, prob.face_vmask)
    para = jax.vmap(opposite_side_deviation_deg)(fv, prob.face_vmask)

    def on_plane(v, m, plane):
        x = backproject(v, plane, prob.intrinsics)
        nxt, _ = ring(m)
        return jnp.log(safe_norm(x[nxt] - x)), corner_angles_deg(x, m)

    log_side_m, corner3d = jax.vmap(on_plane)(fv, prob.face_vmask, planes)
    n = planes[:, :3]
    tilt = angle_deg(n, prob.support_plane[:3][None, :])
    tilt = jnp.minimum(tilt, 180.0 - tilt)
    between = angle_deg(n[:, None, :], n[None, :, :])
    return Quantities(side_px, corner, para, log_side_m, corner3d, tilt, 180.0 - between,
                      jnp.minimum(between, 180.0 - between))


def _dof(prob: ObjectProblem):
    """Unknowns each data block pins: two per vertex an edge-guided face uses, three per fitted plane."""
    used = jnp.zeros(prob.vertices.shape[0], bool).at[prob.face_index].max(
        prob.face_vmask & (prob.face_mask & prob.use_edges)[:, None])
    return 2 * jnp.sum(used), 3 * jnp.sum(prob.has_plane & prob.face_mask)


def param_covariance(params: Params, prob: ObjectProblem, field: Float[Array, "H W"], cfg: Settings):
    """Covariance of the flattened unknowns (K, K) and each data block's variance factor s^2."""
    flat, unravel = ravel_pytree(params)

    def blocks(x):
        return residual_blocks(unravel(x), prob, field, cfg)

    b = blocks(flat)
    dist = edge_distances(geometry(params, prob)[0], prob, field)
    # robust weight of each edge sample (Cauchy): outliers carry no information
    c = cfg.edge_cauchy_px
    w_edge = jax.lax.stop_gradient(edge_mask(prob) / (1.0 + (dist / c) ** 2))
    v0 = face_vertices(geometry(params, prob)[0], prob)
    nxt = jax.vmap(lambda m: ring(m)[0])(prob.face_vmask)
    side = jnp.take_along_axis(v0, nxt[..., None], axis=1) - v0
    normal = jax.lax.stop_gradient(jnp.stack([-side[..., 1], side[..., 0]], -1) / safe_norm(side)[..., None])
    s0 = jax.lax.stop_gradient(jax.vmap(edge_samples, in_axes=(0, 0, None))(v0, prob.face_vmask, EDGE_SAMPLES))

    def line_residuals(x):
        v = face_vertices(geometry(unravel(x), prob)[0], prob)
        s = jax.vmap(edge_samples, in_axes=(0, 0, None))(v, prob.face_vmask, EDGE_SAMPLES)
        return jnp.sum((s - s0) * normal[:, :, None, :], -1) * jnp.sqrt(w_edge) / cfg.edge_sigma_px

    jac = jax.jacfwd(blocks)(flat)
    jac = eqx.tree_at(lambda j: j.edge, jac, jax.jacfwd(line_residuals)(flat))
    p_edge, p_plane = _dof(prob)
    n_edge = jnp.sum(edge_mask(prob)) * EDGE_SAMPLES
    n_depth = jnp.sum((prob.point_weight > 0) * (prob.has_plane & prob.face_mask)[:, None])  # cells, not readings

    def scale2(r, n, p):
        return jnp.maximum(jnp.sum(r * r) / jnp.maximum(n - p, 1.0), MIN_SCALE2)

    s_edge = scale2(b.edge, n_edge, p_edge)
    s_depth = scale2(b.depth, n_depth, p_plane)
    s_link = scale2(b.link, jnp.sum(prob.link_mask), 0.0)

    def gram(j):
        j = j.reshape(-1, flat.shape[0])
        return j.T @ j

    h = gram(jac.edge) / s_edge + gram(jac.depth) / s_depth + gram(jac.link) / s_link + gram(jac.prior)
    h = 0.5 * (h + h.T)
    cov = jnp.linalg.inv(h)
    return 0.5 * (cov + cov.T), jnp.stack([s_edge, s_depth, s_link])


def propagate(params: Params, prob: ObjectProblem, cov: Float[Array, "K K"]):
    """Quantities at ``params``, their Jacobian map and per-quantity standard deviations.

    Returns ``(q, jq, std)``: ``q`` a :class:`Quantities`, ``jq`` (Q, K) the Jacobian of the flattened
    quantities, ``std`` a :class:`Quantities` of standard deviations (no model-error floor yet).
    """
    flat, unravel = ravel_pytree(params)
    q = quantities(params, prob)
    q_flat, unravel_q = ravel_pytree(q)
    jq = jax.jacfwd(lambda x: ravel_pytree(quantities(unravel(x), prob))[0])(flat)
    var = jnp.einsum("qk,kl,ql->q", jq, cov, jq)
    return q, jq, unravel_q(jnp.sqrt(jnp.maximum(var, 1e-12)))  # finite gradient where a quantity is certain
