"""Joint refinement of one object: polygon vertices against the edge field, face planes against their
depth points, and shared vertices against both planes they sit on, in one robust least-squares problem.

Unknowns are updates from the first guess: ``dverts`` (U, 2) pixels and ``dplanes`` (F, 3), see
:func:`grounding._plane.moved_plane`. Every residual block is whitened by its a priori noise, so blocks
in pixels and in metres add up; weak priors keep the problem well posed where data say nothing
(padding, faces without depth, vertices that no edge guides).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Bool, Float

from ._plane import backproject, depth_residuals, depth_sigma, moved_plane
from ._polygon import bilinear, cauchy_residual, edge_samples
from ._problem import EDGE_SAMPLES, ObjectProblem, Settings

PLANE_PRIOR = jnp.array([50.0, 50.0, 100.0])  # spread of a plane update in its units: 0.5 rad, 0.5 rad, 0.1 m
HELD = 1e-3  # spread that pins an unknown the data cannot see (a padded slot, a face without a plane)


class Params(eqx.Module):
    dverts: Float[Array, "U 2"]
    dplanes: Float[Array, "F 3"]


class Blocks(eqx.Module):
    """Whitened residuals by source; padding is zero."""

    edge: Float[Array, "F S N"]
    depth: Float[Array, "F P"]
    link: Float[Array, " L"]
    prior: Float[Array, " K"]


def zero_params(prob: ObjectProblem) -> Params:
    return Params(jnp.zeros_like(prob.vertices), jnp.zeros((prob.planes.shape[0], 3), prob.vertices.dtype))


def geometry(params: Params, prob: ObjectProblem) -> tuple[Float[Array, "U 2"], Float[Array, "F 4"]]:
    """Vertices (pixels) and planes (camera frame) after the update ``params``."""
    planes = jax.vmap(moved_plane)(prob.planes, params.dplanes, prob.pivots)
    return prob.vertices + params.dverts, planes


def face_vertices(verts: Float[Array, "U 2"], prob: ObjectProblem) -> Float[Array, "F S 2"]:
    return verts[prob.face_index]


def edge_distances(verts: Float[Array, "U 2"], prob: ObjectProblem,
                   field: Float[Array, "H W"]) -> Float[Array, "F S N"]:
    """Edge-field value (pixels to the nearest image edge) at the samples along every side."""
    fv = face_vertices(verts, prob)
    samples = jax.vmap(edge_samples, in_axes=(0, 0, None))(fv, prob.face_vmask, EDGE_SAMPLES)
    return bilinear(field, samples.reshape(-1, 2)).reshape(samples.shape[:3])


def edge_mask(prob: ObjectProblem) -> Bool[Array, "F S 1"]:
    return (prob.face_vmask & (prob.face_mask & prob.use_edges)[:, None])[..., None]


def residual_blocks(params: Params, prob: ObjectProblem, field: Float[Array, "H W"], cfg: Settings) -> Blocks:
    verts, planes = geometry(params, prob)
    dist = edge_distances(verts, prob, field)
    edge = cauchy_residual(dist / cfg.edge_sigma_px, cfg.edge_cauchy_px / cfg.edge_sigma_px) * edge_mask(prob)
    depth = jax.vmap(depth_residuals, in_axes=(0, 0, 0, 0, None, None, None))(
        planes, prob.planes, prob.points, prob.point_weight,
        cfg.depth_sigma_a_m, cfg.depth_sigma_b_per_m, cfg.depth_cauchy)
    depth = depth * (prob.has_plane & prob.face_mask)[:, None]

    u, fa, fb = prob.links[:, 0], prob.links[:, 1], prob.links[:, 2]

    def link(ui, a, b):
        x = backproject(verts[ui][None], planes[a], prob.intrinsics)[0]
        return (x @ planes[b, :3] + planes[b, 3]) / (
            cfg.link_sigma_factor * depth_sigma(x[2], cfg.depth_sigma_a_m, cfg.depth_sigma_b_per_m))

    links = cauchy_residual(jax.vmap(link)(u, fa, fb), cfg.link_cauchy) * prob.link_mask

    vsig = jnp.where(prob.vertex_mask, prob.vertex_sigma_px, HELD)
    psig = jnp.where((prob.has_plane & prob.face_mask)[:, None], PLANE_PRIOR, HELD)
    prior = jnp.concatenate([(params.dverts / vsig[:, None]).ravel(), (params.dplanes / psig).ravel()])
    return Blocks(edge, depth, links, prior)


def _flat_residuals(params: Params, args) -> Float[Array, " R"]:
    prob, field, cfg = args
    b = residual_blocks(params, prob, field, cfg)
    return jnp.concatenate([b.edge.ravel(), b.depth.ravel(), b.link, b.prior])


def solve(prob: ObjectProblem, field: Float[Array, "H W"], cfg: Settings, refine: Bool[Array, ""],
          max_steps: int = 24) -> tuple[Params, Array]:
    """Refined updates (zero when ``refine`` is False) and a status: 0 converged or not asked, 1 step limit
    or failure (the last iterate is kept: it is never worse than the first guess by much)."""
    # imported here, not at the top: only tracing needs them, and a process that loads a saved program
    # (grounding._cache) skips their import time
    import lineax as lx
    import optimistix as optx

    y0 = zero_params(prob)

    def run(_):
        # normal equations by Cholesky: the unknowns are few (under 70) and the residuals many
        # tolerances in the unknowns' units: 0.05 px, 5e-4 rad, 0.05 mm; tighter ones cost steps, not accuracy
        solver = optx.LevenbergMarquardt(rtol=1e-2, atol=5e-2, linear_solver=lx.Normal(lx.Cholesky()))
        sol = optx.least_squares(_flat_residuals, solver, y0, args=(prob, field, cfg),
                                 max_steps=max_steps, throw=False)
        ok = sol.result == optx.RESULTS.successful
        return sol.value, jnp.where(ok, 0, 1).astype(jnp.int32)

    return jax.lax.cond(refine, run, lambda _: (y0, jnp.int32(0)), None)
