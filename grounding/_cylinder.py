"""Cylinders in the camera frame: the least-squares refinement of a curved face's cylinder against its depth
points, and its Laplace uncertainty, as planes have theirs (grounding._plane, grounding._uncertainty).

A cylinder is ``(a, c, R)``: unit axis ``a``, a point ``c`` on the axis, radius ``R``, metres. Refinement moves a
first guess ``(a0, c0, R0)`` by a local update ``delta = (a1, a2, c1, c2, r)``:
``a = normalise(a0 + TILT_UNIT (a1 t1 + a2 t2))``, ``c = c0 + OFFSET_UNIT_M (c1 t1 + c2 t2)``,
``R = R0 + OFFSET_UNIT_M r``, with ``t1, t2`` spanning the plane normal to ``a0`` and ``c0`` the foot on the
axis of the points' centre (tilting about the face rather than about a far point keeps tilt and shift nearly
independent). The units are the planes', so a solver tolerance means the same for both.

Residuals. A reading with depth error ``dz`` moves off the surface by ``(u . r) dz`` (``u`` the outward radial
direction there, ``r`` the ray with z = 1), so ``(rho - R) / (sigma(z) |u0 . r|)`` is the depth error in units
of its noise (``u0`` of the first guess, so the weights do not move with the fit; slants under 0.2 count as 0.2,
as for planes), under the same Cauchy loss as the planes' depth residuals. Each point stands for ``weight``
readings (a cell mean of them; grounding._problem._compress) and is weighted by its square root.

Uncertainty. At the optimum ``Cov(delta) = (J^T J / s^2)^-1`` with ``s^2 = chi2 / (n - 5)`` (never below
``MIN_SCALE2``), ``n`` the points that count: a surface the cylinder fits worse than the noise model says is
that much less sure. The axis's spread is that of its two tilts.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float, Int

from ._cache import call_saved
from ._plane import OFFSET_UNIT_M, TILT_UNIT, depth_sigma, tangent_basis
from ._polygon import cauchy_residual, safe_norm
from ._problem import Settings, _compress
from ._uncertainty import MIN_SCALE2

CYLINDER_POINTS = 256  # points (cell means) one fit reads: the padded size of its one compiled program


class CylinderFit(eqx.Module):
    """A refined cylinder with its uncertainty (numpy arrays once returned by :func:`fit_cylinder`)."""

    axis: Float[Array, " 3"]       # unit axis
    point: Float[Array, " 3"]      # a point on the axis, metres
    radius: Float[Array, ""]       # metres
    axis_std: Float[Array, " 2"]   # spread of the axis's two tilts, radians
    radius_std: Float[Array, ""]   # metres
    rms: Float[Array, ""]          # weighted RMS radial distance of the points from the refined surface, metres
    status: Int[Array, ""]         # 0 converged, 1 stopped at the step limit or failed (the first guess is kept)
    scale2: Float[Array, ""]       # variance factor s^2 of the depth residuals


def _moved(delta, axis0, point0, radius0):
    t1, t2 = tangent_basis(axis0)
    a = axis0 + TILT_UNIT * (delta[0] * t1 + delta[1] * t2)
    a = a / safe_norm(a)
    c = point0 + OFFSET_UNIT_M * (delta[2] * t1 + delta[3] * t2)
    return a, c, radius0 + OFFSET_UNIT_M * delta[4]


def _radial(points, a, c):
    v = points - c
    w = v - (v @ a)[:, None] * a
    rho = safe_norm(w)
    return rho, w / rho[:, None]


def _residuals(delta, args):
    points, weight, axis0, point0, radius0, cfg = args
    a, c, radius = _moved(delta, axis0, point0, radius0)
    rho, _ = _radial(points, a, c)
    _, u0 = _radial(points, axis0, point0)
    z = points[:, 2]
    ray = points / jnp.where(jnp.abs(z) < 1e-6, 1e-6, z)[:, None]
    slant = jax.lax.stop_gradient(jnp.maximum(jnp.abs(jnp.sum(u0 * ray, axis=1)), 0.2))
    white = (rho - radius) / (depth_sigma(z, cfg.depth_sigma_a_m, cfg.depth_sigma_b_per_m) * slant)
    return cauchy_residual(white, cfg.depth_cauchy) * jnp.sqrt(weight)


def _fit(points, weight, axis0, point0, radius0, cfg: Settings, max_steps: int = 32) -> CylinderFit:
    import lineax as lx
    import optimistix as optx

    args = (points, weight, axis0, point0, radius0, cfg)
    y0 = jnp.zeros(5, points.dtype)
    solver = optx.LevenbergMarquardt(rtol=1e-3, atol=1e-2, linear_solver=lx.Normal(lx.Cholesky()))
    sol = optx.least_squares(_residuals, solver, y0, args=args, max_steps=max_steps, throw=False)
    ok = (sol.result == optx.RESULTS.successful) & jnp.all(jnp.isfinite(sol.value))
    delta = jnp.where(ok, sol.value, y0)
    r = _residuals(delta, args)
    n = jnp.sum(weight > 0)
    s2 = jnp.maximum(jnp.sum(r * r) / jnp.maximum(n - 5, 1), MIN_SCALE2)
    jac = jax.jacfwd(_residuals)(delta, args)
    h = jac.T @ jac / s2
    cov = jnp.linalg.inv(0.5 * (h + h.T))
    sd = jnp.sqrt(jnp.maximum(jnp.diagonal(cov), 0.0))
    a, c, radius = _moved(delta, axis0, point0, radius0)
    rho, _ = _radial(points, a, c)
    rms = jnp.sqrt(jnp.sum(weight * (rho - radius) ** 2) / jnp.maximum(jnp.sum(weight), 1e-12))
    return CylinderFit(a, c, radius, TILT_UNIT * sd[:2], OFFSET_UNIT_M * sd[4], rms,
                       jnp.where(ok, 0, 1).astype(jnp.int32), s2)


def fit_cylinder(points: np.ndarray, axis: np.ndarray, point: np.ndarray, radius: float, *,
                 intrinsics: tuple[float, float, float, float], settings: Settings = Settings()) -> CylinderFit:
    """Robust, depth-noise-weighted cylinder through camera-frame points ((m, 3) metres, m >= 6) from a first
    guess (unit ``axis``, a ``point`` on it, ``radius``, metres), with its Laplace uncertainty (module
    docstring). More than ``CYLINDER_POINTS`` points are merged into weighted cell means of an image-space grid
    (``intrinsics`` fx, fy, cx, cy in pixels place them). Returns a :class:`CylinderFit` of numpy values; where
    the solver fails, the first guess with status 1. One compiled program serves every face."""
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    if len(pts) < 6:
        raise ValueError(f"a cylinder fit needs at least 6 points, got {len(pts)}")
    p, w = _compress(pts, CYLINDER_POINTS, intrinsics)
    padded = np.zeros((CYLINDER_POINTS, 3))
    padded[:, 2] = 1.0  # padding in front of the camera: no division meets zero; its weight is 0
    padded[: len(p)] = p
    weight = np.zeros(CYLINDER_POINTS)
    weight[: len(p)] = w
    a0 = np.asarray(axis, np.float64)
    a0 = a0 / np.linalg.norm(a0)
    centre = (p * w[:, None]).sum(0) / w.sum()
    c0 = np.asarray(point, np.float64)
    c0 = c0 + ((centre - c0) @ a0) * a0  # the axis's point nearest the face: the pivot of its tilts
    leaves = call_saved("fit_cylinder", _fit, (jnp.asarray(padded, jnp.float32), jnp.asarray(weight, jnp.float32),
                                               jnp.asarray(a0, jnp.float32), jnp.asarray(c0, jnp.float32),
                                               jnp.float32(radius), settings))
    return CylinderFit(*[np.asarray(x) for x in leaves])
