"""The public entry points: one jitted program grounds a whole object, and thin wrappers use it for a
single polygon or a single plane."""

from __future__ import annotations

import functools
from dataclasses import fields

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Bool, Float, Int

from ._cache import call_saved
from ._confidence import Confidences, Floors, confidences
from ._joint import edge_distances, edge_mask, geometry, solve
from ._plane import OFFSET_UNIT_M, TILT_UNIT
from ._problem import ObjectProblem, Settings, pack_object
from ._uncertainty import Quantities, param_covariance, propagate


class Grounding(eqx.Module):
    """Refined geometry of one object with its uncertainty and the probability of every predicate."""

    vertices: Float[Array, "U 2"]     # refined union vertices, pixels
    vertex_cov: Float[Array, "U 2 2"]  # their covariance, pixels^2
    planes: Float[Array, "F 4"]        # refined planes (n, d), camera frame, metres
    plane_std: Float[Array, "F 3"]     # spread of each plane's update: two normal tilts (radians), offset (metres)
    status: Int[Array, ""]             # 0 converged (or not asked to refine), 1 stopped at the step limit / failed
    scale2: Float[Array, " 3"]         # variance factors s^2 of the edge, depth and link blocks
    quantities: Quantities
    std: Quantities                    # Laplace standard deviations, before the model-error floor
    conf: Confidences


def ground_object(prob: ObjectProblem, field: Float[Array, "H W"], refine: bool = True,
                  settings: Settings = Settings(), floors: Floors = Floors()) -> Grounding:
    """Refine one object (when ``refine``), then compute covariances and predicate probabilities.

    ``field``: edge-distance field (pixels), e.g. :func:`grounding.edge_distance_field` of the colour
    image. With ``refine=False`` the first guess is kept and its uncertainty is computed all the same.
    One compiled program per field size serves every object; it is traced once and kept on disk when
    :func:`grounding.enable_cache` is on.
    """
    leaves = call_saved("ground_object", _ground_object, (prob, jnp.asarray(field, jnp.float32), bool(refine),
                                                          settings, floors))
    return jax.tree.unflatten(_out_structure(), leaves)


def ground_objects(probs: list[ObjectProblem], field: Float[Array, "H W"], refine: bool = True,
                   settings: Settings = Settings(), floors: Floors = Floors()) -> list[Grounding]:
    """:func:`ground_object` for each object of one frame; results hold numpy arrays. (One call per
    object: a vmapped batch was measured slower on the CPU, as the batched solver runs every member for
    as many steps as the slowest needs.)"""
    field = jnp.asarray(field, jnp.float32)
    return [jax.tree.map(np.asarray, ground_object(p, field, refine, settings, floors)) for p in probs]


@functools.cache
def _out_structure():
    """The pytree structure of a :class:`Grounding`, built without tracing anything."""
    q = Quantities(*[0] * len(fields(Quantities)))
    c = Confidences(*[0] * len(fields(Confidences)))
    return jax.tree.structure(Grounding(*[0] * 6, q, q, c))


def _ground_object(prob: ObjectProblem, field: Float[Array, "H W"], refine: Bool[Array, ""],
                   settings: Settings, floors: Floors) -> Grounding:
    params, status = solve(prob, field, settings, jnp.asarray(refine))
    cov, scale2 = param_covariance(params, prob, field, settings)
    q, jq, std = propagate(params, prob, cov)
    verts, planes = geometry(params, prob)
    dist = edge_distances(verts, prob, field)
    m = edge_mask(prob)
    near = jnp.sum((jnp.abs(dist) < settings.support_px) * m, axis=(1, 2)) / \
        jnp.maximum(jnp.sum(m, axis=(1, 2)) * dist.shape[2], 1)
    support = jnp.where(prob.use_edges, near, prob.edge_support_prior)
    conf = confidences(q, std, jq, cov, prob.face_vmask, prob.face_mask, prob.has_plane, prob.has_support,
                       prob.adjacency, support, floors)
    u = prob.vertices.shape[0]
    vcov = cov[: 2 * u, : 2 * u].reshape(u, 2, u, 2)[jnp.arange(u), :, jnp.arange(u), :]
    f = prob.planes.shape[0]
    plane_std = jnp.sqrt(jnp.diagonal(cov)[2 * u:].reshape(f, 3)) * jnp.array([TILT_UNIT, TILT_UNIT, OFFSET_UNIT_M])
    return Grounding(verts, vcov, planes, plane_std, status, scale2, q, std, conf)


def refine_polygon(polygon: np.ndarray, field: np.ndarray, *, intrinsics=(600.0, 600.0, 320.0, 240.0),
                   settings: Settings = Settings()) -> tuple[np.ndarray, np.ndarray, int]:
    """Move the vertices of one image polygon ((n, 2) pixels, in order) onto the edges of ``field``.
    Returns the refined polygon (n, 2), each vertex's covariance (n, 2, 2) in pixels^2, and the status."""
    prob, index = pack_object([polygon], intrinsics=intrinsics, merge_px=0.0)
    g = ground_object(prob, jnp.asarray(field), True, settings)
    n = len(polygon)
    ids = index[0, :n]
    return np.asarray(g.vertices)[ids], np.asarray(g.vertex_cov)[ids], int(g.status)


def fit_plane(points: np.ndarray, plane0: np.ndarray, *, settings: Settings = Settings(),
              image_size: tuple[int, int] = (480, 640)) -> tuple[np.ndarray, np.ndarray, int]:
    """Robust, depth-noise-weighted plane through camera-frame points ((m, 3) metres) from a first guess
    ``plane0`` = (n, d); at most ``MAX_POINTS`` of them (an even random subset) are used. Returns the
    plane (4,), the standard deviations of its update (two normal tilts in radians, the shift along the
    normal at the points' centre in metres)
    and the status. ``image_size`` (H, W) only picks which compiled program runs (the one of your frames)."""
    pts = np.asarray(points, np.float64)
    # a dummy triangle around the points' image position keeps the padded problem well formed
    tri = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]) + 300.0
    prob, _ = pack_object([tri], intrinsics=(600.0, 600.0, 320.0, 240.0), planes=[plane0],
                          points=[pts], use_edges=[False])
    g = ground_object(prob, jnp.zeros(image_size, jnp.float32), True, settings)
    return np.asarray(g.planes[0]), np.asarray(g.plane_std[0]), int(g.status)
