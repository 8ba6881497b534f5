"""Planes in the camera frame and the depth residuals that fit them.

A plane is ``(n, d)``, ``n . X + d = 0``, ``n`` a unit normal towards the camera, metres. Refinement
moves a plane by a local update ``delta = (a, b, c)`` about a pivot ``p`` on it (the centre of the face's
points): ``n = normalise(n0 + 0.01 (a t1 + b t2))`` with ``t1, t2`` spanning the plane's tangent space (a, b
in units of about 0.01 rad), and the plane shifted by ``0.001 c`` metres along ``n`` at the pivot. Tilting
about the face rather than the camera centre keeps tilt and shift nearly independent, and the units make
a solver's step tolerance mean the same for vertices (pixels) and planes.
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array, Float

from ._polygon import cauchy_residual, safe_norm

TILT_UNIT = 0.01       # radians per unit of a plane's tilt update
OFFSET_UNIT_M = 0.001  # metres per unit of a plane's offset update


def tangent_basis(n: Float[Array, " 3"]) -> tuple[Float[Array, " 3"], Float[Array, " 3"]]:
    """Two unit vectors orthogonal to ``n`` and to each other (stable for any unit ``n``)."""
    helper = jnp.where(jnp.abs(n[0]) < 0.9, jnp.array([1.0, 0.0, 0.0]), jnp.array([0.0, 1.0, 0.0]))
    t1 = jnp.cross(n, helper)
    t1 = t1 / safe_norm(t1)
    return t1, jnp.cross(n, t1)


def moved_plane(plane0: Float[Array, " 4"], delta: Float[Array, " 3"], pivot: Float[Array, " 3"]) -> Float[Array, " 4"]:
    """The plane ``plane0`` after the local update ``delta = (a, b, c)`` about ``pivot`` (camera frame,
    metres; see the module docstring)."""
    n0 = plane0[:3]
    t1, t2 = tangent_basis(n0)
    on_plane = pivot - (pivot @ n0 + plane0[3]) * n0
    n = n0 + TILT_UNIT * (delta[0] * t1 + delta[1] * t2)
    n = n / safe_norm(n)
    return jnp.concatenate([n, (-(n @ on_plane) - OFFSET_UNIT_M * delta[2])[None]])


def depth_sigma(z: Float[Array, "..."], a: float, b: float) -> Float[Array, "..."]:
    """Depth noise of a reading at depth ``z``: ``a + b z^2`` (metres), as for structured-light / stereo sensors."""
    return a + b * z * z


def pixel_rays(uv: Float[Array, "n 2"], intrinsics: Float[Array, " 4"]) -> Float[Array, "n 3"]:
    """Camera rays through pixels, scaled to z = 1."""
    fx, fy, cx, cy = intrinsics
    return jnp.stack([(uv[:, 0] - cx) / fx, (uv[:, 1] - cy) / fy, jnp.ones(uv.shape[0])], axis=1)


def backproject(uv: Float[Array, "n 2"], plane: Float[Array, " 4"],
                intrinsics: Float[Array, " 4"]) -> Float[Array, "n 3"]:
    """Where the rays through pixels ``uv`` meet ``plane``: camera-frame points (metres)."""
    r = pixel_rays(uv, intrinsics)
    nr = r @ plane[:3]
    nr = jnp.where(jnp.abs(nr) < 1e-6, -1e-6, nr)  # a ray grazing the plane: far away, but finite
    return r * (-plane[3] / nr)[:, None]


def depth_residuals(plane: Float[Array, " 4"], plane0: Float[Array, " 4"], points: Float[Array, "P 3"],
                    weight: Float[Array, " P"], sigma_a: float, sigma_b: float, cauchy: float) -> Float[Array, " P"]:
    """Robust, whitened depth residuals of points against ``plane``.

    The point-to-plane distance ``e = n . X + d`` of a reading with depth error ``dz`` changes by
    ``(n . r) dz`` (``r`` the ray with z = 1), so ``e / (sigma(z) |n0 . r|)`` is the depth error in
    units of its noise; the first-guess normal ``n0`` fixes the weights so they do not move with the fit.
    """
    z = points[:, 2]
    r = points / jnp.where(jnp.abs(z) < 1e-6, 1e-6, z)[:, None]
    slant = jnp.maximum(jnp.abs(r @ plane0[:3]), 0.2)
    e = points @ plane[:3] + plane[3]
    white = e / (depth_sigma(z, sigma_a, sigma_b) * slant)
    return cauchy_residual(white, cauchy) * jnp.sqrt(weight)
