"""Confidences: the probability that each predicate holds under the Gaussian of the refined geometry.

Each quantity's variance is its Laplace variance plus a model-error floor (``Floors``): the part of a
perception step's error that the residuals cannot see (edges found a fraction of a pixel off, depth
biased along a face, corners rounded by the renderer or the lens). A single-interval predicate gets
``P(lo < q < hi)`` in closed form; a predicate that needs several quantities at once (a square's four
corners and sides) is evaluated on ``MC_DRAWS`` fixed draws from the joint linearised Gaussian, so its
probability accounts for their correlations. Tolerances are the constants below (docs/facts.md).
"""

from __future__ import annotations

import dataclasses
import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.flatten_util import ravel_pytree
from jax.scipy.special import ndtr
from jaxtyping import Array, Float, Int

from ._uncertainty import Quantities

# tolerances (degrees, or a ratio)
CORNER_TURN_MIN_DEG = 15.0   # a vertex is a corner when the image outline turns by more than this
CORNER_TURN_MIN_PLANE_DEG = 35.0  # ... or, on a face with a plane, the outline on the plane turns by more than this
PARALLEL_SIDES_DEG = 8.0     # parallelogram: opposite image sides parallel within this
RIGHT_ANGLE_DEG = 10.0       # square / rectangle corners: 90 +- this
PERPENDICULAR_DEG = 7.0      # perpendicular planes: interior dihedral 90 +- this
EQUAL_SIDES_RATIO = 1.12     # square / regular: longest side / shortest side at most this
EQUAL_CORNERS_DEG = 10.0     # regular: largest corner - smallest corner at most this
PLANE_ANGLE_DEG = 10.0       # horizontal, vertical, parallel: within this of the ideal
ACUTE_BELOW_DEG = 83.0       # acute: interior dihedral below this
OBTUSE_ABOVE_DEG = 97.0     # obtuse: interior dihedral above this
SUPPORT_FULL = 0.75          # side-count facts: edge support at or above this costs no confidence
MC_DRAWS = 256


class Floors(eqx.Module):
    """Model-error standard deviations added in quadrature to each quantity's Laplace spread.

    Calibrated with ``benchmarks/bench_grounding.py`` on rendered realsense scenes: each is about the
    floor that makes |error| / spread have the median of a unit Gaussian (the benchmark prints it), taken
    over true-geometry scenes (grounding alone) and perceived ones (end to end), rounded up."""

    corner_deg: float = 1.2      # image corner angles, degrees
    para_dev_deg: float = 1.2    # image parallelism of opposite sides, degrees
    log_side: float = 0.02       # log side length on the plane (2 %)
    corner3d_deg: float = 1.5    # corner angles on the plane, degrees
    tilt_deg: float = 0.5        # face plane vs support plane, degrees
    dihedral_deg: float = 1.0    # interior dihedral and plane-to-plane angles, degrees
    side_px: float = 0.5         # image side lengths, pixels


class Confidences(eqx.Module):
    """Probabilities per face (F,) and per ordered pair of faces (F, F), with the measured values behind them."""

    sides: Int[Array, " F"]
    p_sides: Float[Array, " F"]            # P(the polygon has exactly `sides` sides)
    # P(exactly one of its vertices is no corner: `sides` - 1 sides); 0 without a plane
    p_fewer: Float[Array, " F"]
    p_parallelogram: Float[Array, " F"]
    p_rectangle: Float[Array, " F"]
    p_square: Float[Array, " F"]
    p_regular: Float[Array, " F"]
    p_horizontal: Float[Array, " F"]
    p_vertical: Float[Array, " F"]
    p_perpendicular: Float[Array, "F F"]
    p_parallel: Float[Array, "F F"]
    p_acute: Float[Array, "F F"]
    p_obtuse: Float[Array, "F F"]
    edge_support: Float[Array, " F"]
    side_ratio: Float[Array, " F"]          # longest / shortest side on the plane
    corner_spread_deg: Float[Array, " F"]   # largest - smallest corner on the plane
    right_dev_deg: Float[Array, " F"]       # largest |corner - 90| on the plane
    para_dev_deg: Float[Array, " F"]        # largest image deviation of opposite sides from parallel
    # per vertex slot: its turn past the corner limit in units of its spread, on the face's plane where it has one
    # (in the image without); P(corner) = Phi(corner_z)
    corner_z: Float[Array, "F S"]


def interval(mu, sigma, lo, hi):
    """P(lo < x < hi) for x ~ N(mu, sigma^2)."""
    return ndtr((hi - mu) / sigma) - ndtr((lo - mu) / sigma)


def floored(std: Quantities, floors: Floors) -> Quantities:
    def add(s, f):
        return jnp.sqrt(s * s + f * f)

    return Quantities(add(std.side_px, floors.side_px), add(std.corner_deg, floors.corner_deg),
                      add(std.para_dev_deg, floors.para_dev_deg), add(std.log_side_m, floors.log_side),
                      add(std.corner3d_deg, floors.corner3d_deg), add(std.tilt_deg, floors.tilt_deg),
                      add(std.dihedral_deg, floors.dihedral_deg), add(std.parallel_deg, floors.dihedral_deg))


@functools.cache
def _normals(k: int, q: int, dtype) -> tuple[np.ndarray, np.ndarray]:
    """The fixed standard-normal draws ((MC_DRAWS, k) for the unknowns, (MC_DRAWS, q) for the floors), made
    once outside any trace: generated inside the program they cost more than the rest of the confidences."""
    with jax.ensure_compile_time_eval():
        key_a, key_b = jax.random.split(jax.random.key(0))
        return (np.asarray(jax.random.normal(key_a, (MC_DRAWS, k), dtype)),
                np.asarray(jax.random.normal(key_b, (MC_DRAWS, q), dtype)))


class Drawn(eqx.Module):
    """``MC_DRAWS`` samples of the quantities that the many-quantity predicates read."""

    para_dev_deg: Float[Array, "M F 2"]
    log_side_m: Float[Array, "M F S"]
    corner3d_deg: Float[Array, "M F S"]


def draws(q: Quantities, jq: Float[Array, "Q K"], cov: Float[Array, "K K"], floors: Floors) -> Drawn:
    """``MC_DRAWS`` samples of the quantities from their linearised Gaussian plus independent floors; only
    the quantities of :class:`Drawn` are sampled (the draws are those of the whole vector, so which are
    kept does not change them)."""
    q_flat, _ = ravel_pytree(q)
    k = cov.shape[0]
    chol = jnp.linalg.cholesky(cov + 1e-9 * jnp.eye(k, dtype=cov.dtype))
    z, zf = _normals(k, q_flat.shape[0], jnp.dtype(cov.dtype))
    floor_flat = ravel_pytree(floored(jax.tree.map(jnp.zeros_like, q), floors))[0]
    # positions of the sampled quantities in the flat vector (fields flatten in their declared order)
    sizes = {f.name: int(np.size(getattr(q, f.name))) for f in dataclasses.fields(Quantities)}
    start = dict(zip(sizes, np.cumsum([0, *sizes.values()])))
    drawn = [f.name for f in dataclasses.fields(Drawn)]
    sel = np.concatenate([np.arange(start[name], start[name] + sizes[name]) for name in drawn])
    samples = q_flat[sel][None] + (z @ chol.T) @ jq[sel].T + zf[:, sel] * floor_flat[sel][None]
    parts = jnp.split(samples, np.cumsum([sizes[name] for name in drawn])[:-1], axis=1)
    return Drawn(*(x.reshape((MC_DRAWS, *np.shape(getattr(q, name)))) for x, name in zip(parts, drawn)))


def confidences(q: Quantities, std: Quantities, jq, cov, face_vmask, face_mask, has_plane, has_support,
                adjacency, edge_support, floors: Floors) -> Confidences:
    sd = floored(std, floors)
    sides = jnp.sum(face_vmask, axis=1)
    planar = has_plane & face_mask
    # a corner: the outline turns there. On a plane the turn is free of foreshortening, so true corners (60 deg and
    # more for the data set's solids) stand far from kinks of a traced outline (docs/grounding.md); without one, the
    # image turn
    z_image = (180.0 - q.corner_deg - CORNER_TURN_MIN_DEG) / sd.corner_deg
    z_plane = (180.0 - q.corner3d_deg - CORNER_TURN_MIN_PLANE_DEG) / sd.corner3d_deg
    corner_z = jnp.where(planar[:, None], z_plane, z_image)
    p_corner = ndtr(corner_z)
    support = jnp.clip(edge_support / SUPPORT_FULL, 0.0, 1.0)
    p_real = jnp.where(face_vmask, p_corner, 1.0)
    p_sides = jnp.prod(p_real, axis=1) * support
    # exactly one vertex is a point on a straight side: sum over i of (1 - p_i) * prod_{j != i} p_j. Only on a plane:
    # in the image a true corner seen obliquely turns little too, so there it would speak of true corners as often
    one_out = jnp.eye(p_real.shape[1], dtype=bool)[None]                                      # (1, i, j)
    each = jnp.prod(jnp.where(one_out, 1.0 - p_real[:, None, :], p_real[:, None, :]), -1)    # (F, i)
    p_fewer = jnp.sum(jnp.where(face_vmask, each, 0.0), -1) * support * planar

    mc = draws(q, jq, cov, floors)
    m = face_vmask[None]
    big = 1e9

    def spread(x):  # (M, F, S) -> (M, F): max - min over the real slots
        return jnp.max(jnp.where(m, x, -big), -1) - jnp.min(jnp.where(m, x, big), -1)

    quad = sides == 4
    right = jnp.all(jnp.where(m, jnp.abs(mc.corner3d_deg - 90.0) < RIGHT_ANGLE_DEG, True), -1)
    equal = spread(mc.log_side_m) < jnp.log(EQUAL_SIDES_RATIO)
    p_rect = jnp.mean(right, 0) * quad
    p_square = jnp.mean(right & equal, 0) * quad
    p_regular = jnp.mean(equal & (spread(mc.corner3d_deg) < EQUAL_CORNERS_DEG), 0)
    p_para = jnp.mean(jnp.all(mc.para_dev_deg < PARALLEL_SIDES_DEG, -1), 0) * quad

    p_rect, p_square, p_regular = (p * planar for p in (p_rect, p_square, p_regular))
    oriented = planar & has_support
    p_h = interval(q.tilt_deg, sd.tilt_deg, -PLANE_ANGLE_DEG, PLANE_ANGLE_DEG) * oriented
    p_v = interval(q.tilt_deg, sd.tilt_deg, 90.0 - PLANE_ANGLE_DEG, 90.0 + PLANE_ANGLE_DEG) * oriented

    pair = planar[:, None] & planar[None, :] & ~jnp.eye(planar.shape[0], dtype=bool)
    adj = adjacency & pair
    p_perp = interval(q.dihedral_deg, sd.dihedral_deg, 90.0 - PERPENDICULAR_DEG, 90.0 + PERPENDICULAR_DEG) * pair
    p_par = interval(q.parallel_deg, sd.parallel_deg, -PLANE_ANGLE_DEG, PLANE_ANGLE_DEG) * pair
    p_acute = ndtr((ACUTE_BELOW_DEG - q.dihedral_deg) / sd.dihedral_deg) * adj
    p_obtuse = ndtr((q.dihedral_deg - OBTUSE_ABOVE_DEG) / sd.dihedral_deg) * adj

    mf = face_vmask
    ls = jnp.where(mf, q.log_side_m, 0.0)
    side_ratio = jnp.exp(jnp.max(jnp.where(mf, ls, -big), -1) - jnp.min(jnp.where(mf, ls, big), -1))
    c3 = q.corner3d_deg
    corner_spread = jnp.max(jnp.where(mf, c3, -big), -1) - jnp.min(jnp.where(mf, c3, big), -1)
    right_dev = jnp.max(jnp.where(mf, jnp.abs(c3 - 90.0), 0.0), -1)
    return Confidences(sides, p_sides * face_mask, p_fewer * face_mask, p_para * face_mask, p_rect, p_square,
                       p_regular, p_h, p_v, p_perp, p_par, p_acute, p_obtuse, edge_support, side_ratio,
                       corner_spread, right_dev, jnp.max(q.para_dev_deg, -1), corner_z)
