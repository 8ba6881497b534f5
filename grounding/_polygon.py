"""Polygons in the image: padded vertex rings, edge-field sampling, side lengths and corner angles.

A face is a ring of ``S`` vertex slots of which the first ``k`` are real (``vmask``); slot ``j`` is
joined to slot ``(j + 1) mod k``. Pixels: u right, v down, pixel centres at integers.
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array, Bool, Float, Int

_EPS = 1e-9


def ring(vmask: Bool[Array, " S"]) -> tuple[Int[Array, " S"], Int[Array, " S"]]:
    """Next and previous slot of each slot in a ring whose first ``k = vmask.sum()`` slots are real."""
    s = vmask.shape[0]
    k = jnp.maximum(jnp.sum(vmask), 1)
    j = jnp.arange(s)
    nxt = jnp.where(j + 1 < k, j + 1, 0)
    prv = jnp.where(j == 0, k - 1, j - 1)
    return nxt, prv


def safe_norm(x: Float[Array, "... d"]) -> Float[Array, "..."]:
    """Euclidean norm along the last axis with a finite gradient at zero."""
    return jnp.sqrt(jnp.sum(x * x, axis=-1) + _EPS)


def angle_deg(a: Float[Array, "... d"], b: Float[Array, "... d"]) -> Float[Array, "..."]:
    """Unsigned angle between vectors (degrees, in [0, 180]); atan2 keeps precision near 0 and 180."""
    dot = jnp.sum(a * b, axis=-1)
    if a.shape[-1] == 2:
        cross = jnp.sqrt((a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]) ** 2 + _EPS)
    else:
        cross = safe_norm(jnp.cross(a, b))
    return jnp.degrees(jnp.arctan2(cross, dot))


def bilinear(field: Float[Array, "H W"], uv: Float[Array, "n 2"]) -> Float[Array, " n"]:
    """Bilinear sample of ``field`` at pixel positions ``uv`` (u, v); positions are clamped to the image."""
    h, w = field.shape
    u = jnp.clip(uv[:, 0], 0.0, w - 1.001)
    v = jnp.clip(uv[:, 1], 0.0, h - 1.001)
    u0 = jnp.floor(u)
    v0 = jnp.floor(v)
    fu, fv = u - u0, v - v0
    iu, iv = u0.astype(jnp.int32), v0.astype(jnp.int32)
    f00 = field[iv, iu]
    f01 = field[iv, iu + 1]
    f10 = field[iv + 1, iu]
    f11 = field[iv + 1, iu + 1]
    return (f00 * (1 - fu) + f01 * fu) * (1 - fv) + (f10 * (1 - fu) + f11 * fu) * fv


def edge_samples(verts: Float[Array, "S 2"], vmask: Bool[Array, " S"], n: int) -> Float[Array, "S n 2"]:
    """``n`` points spread evenly along each side (slot j to its next), strictly inside the side."""
    nxt, _ = ring(vmask)
    t = (jnp.arange(n) + 0.5) / n
    a, b = verts, verts[nxt]
    return a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]


def cauchy_residual(r: Float[Array, "..."], c: float) -> Float[Array, "..."]:
    """Residual whose square is the Cauchy loss ``c^2 log(1 + (r/c)^2)``: least squares on it is a robust fit.
    Written as ``r * sqrt(g)`` with ``g -> 1`` at 0 so that the gradient stays finite there."""
    s = (r / c) ** 2
    small = s < 1e-4
    s_safe = jnp.where(small, 1.0, s)
    g = jnp.where(small, 1.0 - 0.5 * s, jnp.log1p(s_safe) / s_safe)
    return r * jnp.sqrt(g)


def side_lengths_px(verts: Float[Array, "S 2"], vmask: Bool[Array, " S"]) -> Float[Array, " S"]:
    """Length of each side (slot j to its next), pixels."""
    nxt, _ = ring(vmask)
    return safe_norm(verts[nxt] - verts)


def corner_angles_deg(verts: Float[Array, "S d"], vmask: Bool[Array, " S"]) -> Float[Array, " S"]:
    """Interior angle at each vertex (degrees) of a convex ring, 2D (pixels) or 3D (metres)."""
    nxt, prv = ring(vmask)
    return angle_deg(verts[prv] - verts, verts[nxt] - verts)


def opposite_side_deviation_deg(verts: Float[Array, "S 2"], vmask: Bool[Array, " S"]) -> Float[Array, " 2"]:
    """For a quadrilateral: how far sides 0/2 and 1/3 are from parallel (degrees, 0 = parallel)."""
    nxt, _ = ring(vmask)
    e = verts[nxt] - verts
    # opposite sides of a parallelogram run antiparallel around the ring
    return jnp.stack([180.0 - angle_deg(e[0], e[2]), 180.0 - angle_deg(e[1], e[3])])
