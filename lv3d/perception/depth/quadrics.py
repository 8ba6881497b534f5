"""Spheres and cones in depth: a ball's surface or a cone's side as one face rather than a fan of planes.

The plane search cuts a sphere or a cone's side into facets (or, under heavy noise, into a few small planes and
cells of none); the cylinder search would read a cone's side as a cylinder. So before it, per object:

- a **sphere** from a seeded sample consensus over pairs of cells with their normals: the lines along two
  normals of a sphere meet at its centre, ``c = p1 - r n1 = p2 - r n2``, which gives r (least squares, one
  unknown) and c; behind the cells for its outside (a ball), in front of them for its inside (a bowl seen over
  its rim, whose normals point towards the centre);
- a **cone** from triples of cells with their normals: every tangent plane of a cone passes through its apex
  (``n . apex = n . p``: three cells give the apex) and every normal makes the same angle with its axis
  (``n . axis = -sin(alpha)``: three normals give the axis and alpha);

each scored on a seeded sample of the object's cells (within the inlier distance of the surface, the normal
within ``normal_deg`` of the surface's), then refitted by geometric least squares (scipy's Levenberg-Marquardt)
on every cell on the surface in one connected piece. A fit that does not converge, or gives numbers that are not
finite, is no face (and is counted: ``QuadricResult.unconverged``).

A surface stands (:func:`_stands`) when it holds enough cells, fits them within the inlier distance on average
and better than the object's planes do, explains most of the residual variance of its nearest simpler surface
(a sphere: a plane's; a cone: a cylinder's, which is what a cone with a small half-angle is, and which fits a
cone's cells at least as well as a plane does), and its normals fill their spread without the gaps planes leave
(a pyramid's faces are tangent to a cone too: their normals make four peaks around the axis). It then replaces
the planes with half their cells or more on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...cone import Cone
from ...plane import column_means, row_norms
from ...sphere import Sphere, algebraic_sphere
from .curved import axis_basis, axis_terms
from .curved import explained_share as _share
from .cloud import cell_rows
from .curved import plane_ms
from .planes import largest_piece_on
from .ranges import check_ranges
from .support import SENSOR, SensorNoise


@dataclass(frozen=True)
class QuadricSettings:
    """Thresholds of the sphere and cone search (scale-free: multiples of the inlier distance, itself the
    sensor's noise at the object's depth; fractions; angles; grid cells).

    ``inlier_dists`` (multiples of the inlier distance): how far from the surface a cell may lie and still be on
    it; the face's RMS residual must be within it too.
    ``normal_deg`` (degrees): how far a cell's normal may turn from the surface's (normals are averaged over 5x5
    cells, so they lag the turn of a small surface), as for cylinders.
    ``min_share`` (fraction): the share of a plane's residual variance over the face's cells that the fit must
    explain (sphere_evidence, the ``spherical`` fact's confidence; for a cone too); 0.5: the curved reading is
    the likelier one. A sphere must explain as much of a least-squares cylinder's (its axis started where the
    cells' normals are most nearly perpendicular to): on RealSense frames of YCB objects a sphere fits a cup's
    side seen from above or a bottle's shoulder within the noise, but no better than a cylinder does.
    ``min_cone_share`` (fraction): the share of a cylinder's residual variance over a cone's cells that the cone
    must explain (cone_evidence, the ``conical`` fact's confidence). Lower than ``min_share``: a cylinder with a
    tilted axis follows the half of a cone's side a camera sees to 2-3 mm, so RealSense's 1-2 mm of noise
    leaves the true cone of a small, far cone only 0.4-0.9 of it; the half-angle (``min_half_angle_deg``) is
    what tells a cylinder's side, whose fitted cone closes to a half-angle near 0.
    ``plane_ratio`` (fraction): on the face's cells that lie on one of the object's planes, the face's RMS
    residual must be at most this share of their RMS distance from their planes (it explains them at least as
    well as the fan of planes does, whose planes chose those cells as their inliers).
    ``min_radius_cells`` (grid cells at the object's depth): a smaller sphere turns its normals within the 5x5
    cells they are averaged over. ``max_radius_frac`` (fraction of the object's extent): a larger sphere is a
    plane's stand-in.
    ``min_half_angle_deg`` / ``max_half_angle_deg`` (degrees): a narrower cone is a cylinder (its normals all but
    perpendicular to one axis), a wider one a plane.
    ``normal_fit_deg`` (degrees): the median angle between the face's cells' normals and the surface's normals
    there must be within this: a surface's cells follow it to within their noise (4-9 deg on rendered RealSense
    frames, normals averaged over 5x5 cells; 11 deg on a 3 cm ball 1.5 m away), while planes a sphere or cone was
    fitted across keep their normals fixed as the surface's turn (13.5 deg on a prism's edge at 320x240).
    ``min_spread_deg`` (degrees): a sphere's normals turn by at least this much (their spread, the smaller of its
    two principal directions) across the face; a cylinder's turn in one direction only.
    ``min_arc_deg`` / ``bin_deg`` / ``min_dip`` (degrees / degrees / fraction): a cone's normals, binned every
    ``bin_deg`` around its axis, fill an arc of at least ``min_arc_deg``, its emptiest bin holding ``min_dip`` of
    its fullest: a pyramid's faces leave near-empty bins between their peaks, which RealSense's 7-10 deg of normal
    scatter does not fill.
    ``min_cover`` (fraction): of the object's cells with a normal, the share the face holds where the object has
    no plane it could replace.
    ``max_step_deg`` / ``free_share`` / ``max_flat_faces`` (degrees / fraction / planes): the search runs on an
    object only where its planes leave room for a curved surface: two touching planes turned from each other by
    less than ``max_step_deg`` (the facets of a curved surface turn by 15-40 deg at 640x480, the faces of the
    solids lv3d knows by 60 or more, as for cylinders), or ``free_share`` of its cells with a normal on no plane,
    or more planes than ``max_flat_faces`` (those solids show at most four faces at once; a small ball at 320x240
    comes out as six facets 50-62 deg apart), or no plane at all. A box's faces leave none, and cost no search.
    ``max_faces`` (faces): the most spheres and cones of one object.
    ``trials`` / ``score_cells`` / ``refits`` / ``fit_cells``: samples of the consensus, the seeded sample of
    cells each is scored on, least-squares refits on the cells on the surface, and the most cells (a seeded
    sample) one refit reads.
    """

    inlier_dists: float = 1.0
    normal_deg: float = 25.0
    min_share: float = 0.5
    min_cone_share: float = 0.25
    plane_ratio: float = 1.0
    min_radius_cells: float = 4.0
    max_radius_frac: float = 1.0
    min_half_angle_deg: float = 10.0
    max_half_angle_deg: float = 70.0
    normal_fit_deg: float = 12.0
    min_spread_deg: float = 12.0
    min_arc_deg: float = 60.0
    bin_deg: float = 10.0
    min_dip: float = 0.1
    min_cover: float = 0.5
    max_step_deg: float = 50.0
    free_share: float = 0.1
    max_flat_faces: int = 4
    max_faces: int = 2
    trials: int = 128
    score_cells: int = 400
    refits: int = 3
    fit_cells: int = 800

    def __post_init__(self) -> None:
        check_ranges(self, fractions=("min_share", "min_cone_share", "plane_ratio", "max_radius_frac", "min_dip",
                                      "min_cover", "free_share"),
                     acute=("normal_deg", "normal_fit_deg"), angles=("min_spread_deg", "max_step_deg"),
                     arcs=("min_arc_deg", "bin_deg"), positive=("inlier_dists", "min_radius_cells"),
                     counts={"max_flat_faces": 0, "max_faces": 1, "trials": 1, "score_cells": 1, "refits": 0,
                             "fit_cells": 1})
        if not 0 < self.min_half_angle_deg < self.max_half_angle_deg < 90:
            raise ValueError("half-angles must satisfy 0 < min_half_angle_deg < max_half_angle_deg < 90, got "
                             f"{self.min_half_angle_deg!r} and {self.max_half_angle_deg!r}")


DEFAULT = QuadricSettings()
# evaluations of the residuals a least-squares fit may take (analytic Jacobians): the fits of these surfaces that
# converge on rendered and RealSense frames take 4 to 60; one that needs more is running away (a cone fitted to a
# cylinder's side, its apex receding as its half-angle closes) and counts as not converged
MAX_EVALS = 80


def _last_call(fn):
    """``fn`` of one parameter vector, remembering its value at the last vector asked: Levenberg-Marquardt asks
    for the residuals and then the Jacobian at the same parameters, which share every intermediate."""
    memo: list = [None, None]

    def call(p: np.ndarray):
        key = p.tobytes()
        if memo[0] != key:
            memo[0], memo[1] = key, fn(p)
        return memo[1]

    return call


@dataclass(frozen=True)
class QuadricFace:
    """A sphere's or cone's face of an object: ``surface`` ('sphere' or 'cone'), the fitted ``sphere`` or
    ``cone``, grid ``mask`` (h, w) bool, ``points`` (m, 3) metres and ``rms_m``, the RMS of the points'
    distances from the surface."""

    surface: str
    mask: np.ndarray
    points: np.ndarray
    rms_m: float
    sphere: Sphere | None = None
    cone: Cone | None = None
    cylinder: None = None  # a quadric face is no cylinder (the depth stage's curved faces all answer this)


@dataclass
class QuadricResult:
    """What the search found on one object: per face (surface, model, its cells (m,) bool, the planes it
    replaces), and how many least-squares fits did not converge (no face came of them)."""

    faces: list[tuple[str, Sphere | Cone, np.ndarray, list[int]]] = field(default_factory=list)
    unconverged: int = 0


def surface_fields(c) -> dict:
    """The :class:`lv3d.scene.Face` fields of a curved face of the depth stage (a cylinder's CurvedFace or a
    QuadricFace): surface and its model."""
    if isinstance(c, QuadricFace):
        return {"surface": c.surface, "sphere": c.sphere, "cone": c.cone}
    return {"surface": "cylinder", "cylinder": c.cylinder}


# ---------------------------------------------------------------------------------------------------------------
# evidence: the share of a simpler surface's residual variance a fit explains


def sphere_evidence(points: np.ndarray, sphere: Sphere) -> float | None:
    """The probability a face is the sphere rather than flat: the share of a plane's residual variance over the
    face's points (m, 3) that the sphere explains, 1 - rms_sphere^2 / rms_plane^2 (a sphere of growing radius
    tends to a plane, its simpler nested surface). None for fewer than 10 points or numbers that are not finite."""
    pts = np.asarray(points, float)
    if len(pts) < 10:
        return None
    return _share(float(np.mean(sphere.residual(pts) ** 2)), plane_ms(pts))


def least_squares_cylinder(pts: np.ndarray, axis0: np.ndarray) -> tuple[float, float]:
    """Mean square distance of points (m, 3) from their least-squares cylinder (geometric distances,
    Levenberg-Marquardt), its axis started at ``axis0`` and its circle at Kasa's fit seen along it; and that
    cylinder's radius (metres). (nan, nan) where the fit fails."""
    from scipy.optimize import least_squares

    a0, b1, b2 = axis_basis(axis0)
    x, y = pts @ b1, pts @ b2
    sol, *_ = np.linalg.lstsq(np.stack([x, y, np.ones_like(x)], axis=1), x * x + y * y, rcond=None)
    cx, cy = sol[0] / 2, sol[1] / 2
    r0 = np.sqrt(max(sol[2] + cx * cx + cy * cy, 1e-12))
    c0 = cx * b1 + cy * b2

    def parts(p: np.ndarray):
        q = a0 + p[0] * b1 + p[1] * b2
        a = q / np.linalg.norm(q)
        v = pts - (c0 + p[2] * b1 + p[3] * b2)
        h = v @ a
        w = v - np.outer(h, a)
        rho = row_norms(w)
        return q, a, h, w / np.maximum(rho, 1e-12)[:, None], rho

    parts = _last_call(parts)

    def res(p: np.ndarray) -> np.ndarray:
        return parts(p)[4] - p[4]

    def jac(p: np.ndarray) -> np.ndarray:
        q, a, h, u, _ = parts(p)
        da = -h[:, None] * u                                   # d rho / d axis (unnormalised direction)
        proj = np.stack([b1 - a * (a @ b1), b2 - a * (a @ b2)], axis=1) / np.linalg.norm(q)
        return np.column_stack([da @ proj, -u @ b1, -u @ b2, -np.ones(len(pts))])

    try:
        fit = least_squares(res, np.array([0.0, 0.0, 0.0, 0.0, r0]), jac=jac, method="lm", max_nfev=MAX_EVALS)
    except (ValueError, np.linalg.LinAlgError):
        return float("nan"), float("nan")
    if fit.status <= 0 or not np.all(np.isfinite(fit.fun)) or not np.isfinite(fit.x[4]):
        return float("nan"), float("nan")
    return float(np.mean(fit.fun ** 2)), abs(float(fit.x[4]))


def cylinder_ms(pts: np.ndarray, axis0: np.ndarray) -> float:
    """Mean square distance of points (m, 3) from their least-squares cylinder (:func:`least_squares_cylinder`),
    nan where the fit fails."""
    return least_squares_cylinder(pts, axis0)[0]


def cone_evidence(points: np.ndarray, cone: Cone) -> float | None:
    """The probability a face is the cone rather than a cylinder: the share of a least-squares cylinder's
    residual variance over the face's points (m, 3) that the cone explains, 1 - rms_cone^2 / rms_cylinder^2. A
    cone of half-angle near 0 is a cylinder (and a cylinder fits a cone's cells at least as well as a plane), so
    it is the cylinder the cone must beat; a cylinder's side read as a cone gives near 0. None for fewer than 10
    points or numbers that are not finite."""
    pts = np.asarray(points, float)
    return None if len(pts) < 10 else _over_cylinder(pts, cone)[0]


def _over_cylinder(pts: np.ndarray, cone: Cone) -> tuple[float | None, float, float]:
    """:func:`cone_evidence` of points (m, 3), with the least-squares cylinder's mean square residual and radius
    (:func:`least_squares_cylinder`, its axis started along the cone's)."""
    cyl_ms, radius = least_squares_cylinder(pts, np.asarray(cone.axis, float))
    return _share(float(np.mean(cone.residual(pts) ** 2)), cyl_ms), cyl_ms, radius


def cone_readings(points: np.ndarray, cone: Cone) -> tuple[float, tuple[float, float] | None] | None:
    """How likely a face fitted as ``cone`` is a cone and how likely it is a cylinder's side, from its points
    (m, 3): (conical, (cylindrical, the cylinder's radius in metres) or None). The two surfaces are nested (a cone
    whose half-angle closes is a cylinder), so a face read as a cone is a cylinder's side with the probability
    the cone does not beat the cylinder and the cylinder beats a plane: conical = :func:`cone_evidence`,
    cylindrical = (1 - conical) x the share of a plane's residual variance the least-squares cylinder explains.
    A cylinder's side that the cone search took (its fitted cone explains little more than a cylinder does)
    thus reads cylindrical, as the cylinder search would have read it. None for fewer than 10 points or numbers
    that are not finite; the cylindrical part None where the cylinder's fit fails."""
    pts = np.asarray(points, float)
    if len(pts) < 10:
        return None
    conical, cyl_ms, radius = _over_cylinder(pts, cone)
    if conical is None:
        return None
    over_plane = _share(cyl_ms, plane_ms(pts))
    return conical, None if over_plane is None else ((1.0 - conical) * over_plane, radius)


# ---------------------------------------------------------------------------------------------------------------
# sample consensus


def sample_sphere(pts: np.ndarray, nrm: np.ndarray, dist_m: float, cos_min: float, r_min: float, r_max: float,
                  rng: np.random.Generator, trials: int = 192, score_points: int = 600,
                  min_pair_deg: float = 10.0) -> Sphere | None:
    """The sphere with most inliers (within ``dist_m`` of the surface, the normal within ``arccos(cos_min)`` of
    the direction of the side it shows) among ``trials`` seeded pairs of the oriented points (m, 3) with unit
    normals (m, 3) towards the camera, scored on a seeded sample of ``score_points``; its radius in [r_min,
    r_max]. None when no pair gives one. A pair fixes the sphere where the lines along its normals meet:
    ``p1 - r n1 = p2 - r n2``, behind the points (r > 0) for an outside, a ball's, and in front of them (r < 0) for
    an inside, a bowl's seen over its rim (``Sphere.side``)."""
    m = len(pts)
    if m < 20:
        return None
    score = rng.choice(m, min(m, score_points), replace=False)
    i, j = rng.integers(0, m, trials), rng.integers(0, m, trials)
    d, e = pts[i] - pts[j], nrm[i] - nrm[j]
    ee = np.einsum("ij,ij->i", e, e)
    ok = ee >= (2 * np.sin(np.radians(min_pair_deg) / 2)) ** 2
    r = np.einsum("ij,ij->i", d, e) / np.maximum(ee, 1e-12)
    miss = np.linalg.norm(d - r[:, None] * e, axis=1)  # how far the two lines pass from each other
    ok &= (np.abs(r) >= r_min) & (np.abs(r) <= r_max) & (miss <= 0.25 * np.abs(r))
    if not ok.any():
        return None
    r = r[ok]
    c = 0.5 * (pts[i][ok] - r[:, None] * nrm[i][ok] + pts[j][ok] - r[:, None] * nrm[j][ok])
    side, r = np.sign(r), np.abs(r)
    # each centre k against each scored point s in (k, s) products (coordinates about the points' mean):
    # |p - c|^2 = |p|^2 - 2 c . p + |c|^2, and the normal's dot with p - c
    sp, sn = pts[score], nrm[score]
    o = column_means(sp)
    q, co = sp - o, c - o
    cq = co @ q.T
    rr = np.sqrt(np.maximum(np.einsum("sj,sj->s", q, q)[None, :] - 2.0 * cq + np.einsum("kj,kj->k", co, co)[:, None],
                            0.0))
    dn = np.einsum("sj,sj->s", q, sn)[None, :] - co @ sn.T
    count = np.count_nonzero((np.abs(rr - r[:, None]) <= dist_m) & (side[:, None] * dn >= cos_min * rr), axis=1)
    b = int(np.argmax(count))
    return Sphere(tuple(float(x) for x in c[b]), float(r[b]), float(side[b]))


def sample_cone(pts: np.ndarray, nrm: np.ndarray, dist_m: float, cos_min: float, alpha_min: float,
                alpha_max: float, rng: np.random.Generator, trials: int = 192, score_points: int = 600,
                min_det: float = 0.02) -> Cone | None:
    """The cone with most inliers among ``trials`` seeded triples of the oriented points (m, 3) with outward unit
    normals (m, 3), scored on a seeded sample of ``score_points``; its half-angle in [alpha_min, alpha_max]
    (radians). A triple fixes the cone: its tangent planes meet at the apex, and its normals make one angle with
    the axis (``n . axis = -sin(alpha)`` for all three). Triples whose normals are near coplanar (determinant
    below ``min_det``: a cylinder's, or one face's) give none. None when no triple gives one."""
    m = len(pts)
    if m < 20:
        return None
    score = rng.choice(m, min(m, score_points), replace=False)
    idx = rng.integers(0, m, (trials, 3))
    nn, pp = nrm[idx], pts[idx]                                     # (k, 3, 3): rows are the triple's
    ok = np.abs(np.linalg.det(nn)) >= min_det
    if not ok.any():
        return None
    nn, pp = nn[ok], pp[ok]
    rhs = np.stack([np.einsum("kij,kij->ki", nn, pp), np.ones((len(nn), 3))], axis=2)  # (k, 3, 2)
    sol = np.linalg.solve(nn, rhs)
    apex, v = sol[:, :, 0], sol[:, :, 1]
    vn = np.linalg.norm(v, axis=1)
    axis = -v / vn[:, None]                                          # n . axis = -1/|v| = -sin(alpha)
    s = 1.0 / vn
    ok = (s >= np.sin(alpha_min)) & (s <= np.sin(alpha_max))
    ok &= (np.einsum("kij,kj->ki", pp - apex[:, None, :], axis) > 0).all(axis=1)  # the points lie down the axis
    if not ok.any():
        return None
    apex, axis, alpha = apex[ok], axis[ok], np.arcsin(s[ok])
    # each cone k against each scored point s in (k, s) products: h the distance along the axis from the apex,
    # rho from the axis, wn the dot of the normal with the point's offset from the axis (curved.axis_terms)
    sp, sn = pts[score], nrm[score]
    rho, wn, h = axis_terms(sp, sn, apex, axis)
    ca, sa = np.cos(alpha)[:, None], np.sin(alpha)[:, None]
    resid = rho * ca - h * sa
    cos = wn / np.maximum(rho, 1e-12) * ca - (axis @ sn.T) * sa
    count = np.count_nonzero((np.abs(resid) <= dist_m) & (cos >= cos_min) & (h > 0), axis=1)
    b = int(np.argmax(count))
    return Cone(tuple(float(x) for x in apex[b]), tuple(float(x) for x in axis[b]), float(np.degrees(alpha[b])),
                float(np.max(h[b], initial=0.0)))


# ---------------------------------------------------------------------------------------------------------------
# least-squares refinement


def refine_sphere(pts: np.ndarray, start: Sphere) -> Sphere | None:
    """The least-squares sphere (geometric distances, Levenberg-Marquardt) through points (m, 3), started at
    ``start``, showing its side; None when it does not converge or its numbers are not finite."""
    from scipy.optimize import least_squares

    @_last_call
    def parts(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = pts - p[:3]
        return d, row_norms(d)

    def res(p: np.ndarray) -> np.ndarray:
        return parts(p)[1] - p[3]

    def jac(p: np.ndarray) -> np.ndarray:
        d, r = parts(p)
        return np.column_stack([-d / np.maximum(r, 1e-12)[:, None], -np.ones(len(pts))])

    try:
        fit = least_squares(res, np.array([*start.centre, start.radius]), jac=jac, method="lm", max_nfev=MAX_EVALS)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if fit.status <= 0 or not np.all(np.isfinite(fit.x)) or fit.x[3] <= 0:
        return None
    return Sphere(tuple(float(x) for x in fit.x[:3]), float(fit.x[3]), start.side)


def cone_from_normals(pts: np.ndarray, nrm: np.ndarray) -> Cone | None:
    """The linear least-squares cone of oriented points (m, 3) with outward unit normals (m, 3): its axis the
    direction the normals make the most nearly constant angle with (the eigenvector of their covariance with the
    smallest eigenvalue), its half-angle from that angle (``n . axis = -sin(alpha)``), its apex the point nearest
    every tangent plane (``n . apex = n . p``). None where the normals do not fix one (a cylinder's turn in a
    plane, so their angle with its axis is 0)."""
    if len(pts) < 3:
        return None
    _, vecs = np.linalg.eigh(np.cov(nrm.T))
    a = vecs[:, 0]
    s = float(np.mean(nrm @ a))
    if s > 0:
        a, s = -a, -s
    if not 0 < -s < 1:
        return None
    apex, *_ = np.linalg.lstsq(nrm, np.einsum("ij,ij->i", nrm, pts), rcond=None)
    if not np.all(np.isfinite(apex)):
        return None
    h = (pts - apex) @ a
    return Cone(tuple(float(x) for x in apex), tuple(float(x) for x in a), float(np.degrees(np.arcsin(-s))),
                float(np.max(h, initial=0.0)))


def refine_cone(pts: np.ndarray, start: Cone) -> Cone | None:
    """The least-squares cone (distances from its side, Levenberg-Marquardt over apex, axis and half-angle)
    through points (m, 3), started at ``start``; its height the farthest of the points along the axis (99th
    percentile). None when it does not converge, its numbers are not finite or its half-angle leaves (0, 90)."""
    from scipy.optimize import least_squares

    a0, b1, b2 = axis_basis(start.axis)

    def unpack(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        a = a0 + p[3] * b1 + p[4] * b2
        return p[:3], a / np.linalg.norm(a), p[5]

    def parts(p: np.ndarray):
        apex, a, t = unpack(p)
        v = pts - apex
        h = v @ a
        w = v - np.outer(h, a)
        rho = row_norms(w)
        return a, t, v, h, w / np.maximum(rho, 1e-12)[:, None], rho

    parts = _last_call(parts)

    def res(p: np.ndarray) -> np.ndarray:
        _, t, _, h, _, rho = parts(p)
        return rho * np.cos(t) - h * np.sin(t)

    def jac(p: np.ndarray) -> np.ndarray:
        # d = rho cos t - h sin t; d rho / d apex = -u, d h / d apex = -a; d rho / d axis = -h u, d h / d axis = v
        a, t, v, h, u, rho = parts(p)
        ct, st = np.cos(t), np.sin(t)
        d_apex = -u * ct + a * st
        d_axis = -(h * ct)[:, None] * u - v * st
        q = np.linalg.norm(a0 + p[3] * b1 + p[4] * b2)
        proj = np.stack([b1 - a * (a @ b1), b2 - a * (a @ b2)], axis=1) / q
        return np.column_stack([d_apex, d_axis @ proj, -rho * st - h * ct])

    try:
        fit = least_squares(res, np.array([*start.apex, 0.0, 0.0, np.radians(start.half_angle_deg)]), jac=jac,
                            method="lm", max_nfev=MAX_EVALS)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if fit.status <= 0 or not np.all(np.isfinite(fit.x)):
        return None
    apex, a, t = unpack(fit.x)
    if not 0 < t < np.pi / 2:
        return None
    h = (pts - apex) @ a
    return Cone(tuple(float(x) for x in apex), tuple(float(x) for x in a), float(np.degrees(t)),
                float(np.percentile(h, 99)))


# ---------------------------------------------------------------------------------------------------------------
# the search on one object


def _residual_normal(model: Sphere | Cone, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(model, Sphere):
        r, _ = model.radial(pts)
        return r - model.radius, model.normals(pts)
    return model.residual(pts), model.normals(pts)


def _inliers(model: Sphere | Cone, pts: np.ndarray, nrm: np.ndarray, dist_m: float, cos_min: float) -> np.ndarray:
    res, out = _residual_normal(model, pts)
    ok = (np.abs(res) <= dist_m) & (np.einsum("ij,ij->i", out, nrm) >= cos_min)
    if isinstance(model, Cone):
        ok &= model.local(pts)[0] > 0
    return ok


def _azimuth_profile(axis, nrm: np.ndarray, bin_deg: float, edge_frac: float = 0.25) -> tuple[float, float]:
    """The arc (degrees) the normals (m, 3) fill around ``axis`` (from the first to the last bin of ``bin_deg``
    holding ``edge_frac`` of the fullest or more, the circle cut at its longest empty run) and its emptiest bin
    over its fullest."""
    _, b1, b2 = axis_basis(axis)
    phi = np.degrees(np.arctan2(nrm @ b2, nrm @ b1))
    nb = int(np.ceil(360.0 / bin_deg))
    counts = np.bincount(((phi + 180.0) // bin_deg).astype(int) % nb, minlength=nb)
    low = counts < edge_frac * counts.max()
    if low.any():
        run, best, best_end = 0, -1, 0
        for i in range(2 * nb):
            run = run + 1 if low[i % nb] else 0
            if run > best:
                best, best_end = run, i
        counts = np.roll(counts, -((best_end + 1) % nb))
    full = np.flatnonzero(counts >= edge_frac * counts.max())
    inside = counts[full[0]:full[-1] + 1]
    return float(len(inside) * bin_deg), float(inside.min() / counts.max())


def _spread_deg(nrm: np.ndarray) -> float:
    """How far unit normals (m, 3) turn across a face in the direction they turn least (of the two they can):
    the second principal standard deviation of the normals, as an angle in degrees."""
    sv = np.linalg.svd(nrm - nrm.mean(axis=0), compute_uv=False) / np.sqrt(len(nrm))
    return float(np.degrees(np.arcsin(min(1.0, sv[1]))))


def _stands(model: Sphere | Cone, pts: np.ndarray, nrm: np.ndarray, plane_res: np.ndarray, dist_m: float,
            min_cells: int, settings: QuadricSettings) -> bool:
    """Whether a sphere's or cone's cells (points and normals; ``plane_res`` each cell's distance from its own
    plane, nan for a cell on none) make a face of it: see the module's docstring."""
    if len(pts) < max(20, min_cells):
        return False
    res, out = _residual_normal(model, pts)
    rms = float(np.sqrt(np.mean(res ** 2)))
    if not np.isfinite(rms) or rms > dist_m:
        return False
    turn = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", out, nrm), -1.0, 1.0)))
    if float(np.median(turn)) > settings.normal_fit_deg:
        return False
    on_plane = np.isfinite(plane_res)
    if np.count_nonzero(on_plane) >= 20 and float(np.sqrt(np.mean(res[on_plane] ** 2))) > \
            settings.plane_ratio * float(np.sqrt(np.mean(plane_res[on_plane] ** 2))):
        return False
    if isinstance(model, Sphere):
        if _spread_deg(nrm) < settings.min_spread_deg:
            return False
        # a sphere must also beat the cylinder the cylinder search would read there (a cup's side seen from above)
        _, vecs = np.linalg.eigh(nrm.T @ nrm)
        # (a cylinder whose fit does not converge on the cells is no rival: a ball's cap fits none)
        over_cylinder = _share(float(np.mean(res ** 2)), cylinder_ms(pts, vecs[:, 0]))
        if over_cylinder is not None and over_cylinder < settings.min_share:
            return False
        share = sphere_evidence(pts, model)
    else:
        arc, dip = _azimuth_profile(model.axis, nrm, settings.bin_deg)
        if arc < settings.min_arc_deg or dip < settings.min_dip:
            return False
        plane = _share(float(np.mean(res ** 2)), plane_ms(pts))
        if plane is None or plane < settings.min_share:
            return False
        share = cone_evidence(pts, model)
        return share is not None and share >= settings.min_cone_share
    return share is not None and share >= settings.min_share


def object_quadrics(pts: np.ndarray, nrm: np.ndarray, box: np.ndarray, plane_of: np.ndarray, planes: list,
                    dist_m: float, extent_m: float, cell_m: float, min_cells: int, seed: int = 0,
                    settings: QuadricSettings = DEFAULT) -> QuadricResult:
    """The spherical and conical faces of an object: ``pts`` (m, 3) metres and outward unit ``nrm`` (m, 3) (zero
    where unknown) are its cells, in row-major order of ``box`` (the object's cells on its bounding box of the
    grid, bool); ``plane_of`` (m,) the index of each cell's plane (-1: none) among ``planes``
    (lv3d.plane.Plane); ``dist_m`` the inlier distance (the sensor's noise at the object's depth), ``extent_m``
    the object's size, ``cell_m`` one grid cell's width at its depth, ``min_cells`` the fewest cells of a face.

    Per round a sphere and a cone are sampled (:func:`sample_sphere`, :func:`sample_cone`) on the cells no face
    holds yet, each refitted ``settings.refits`` times on the largest connected piece of its inliers
    (:func:`refine_sphere`, :func:`refine_cone`); of those that stand (:func:`_stands`) and replace a plane (half
    its cells or more on the surface) or, on an object without planes there, hold ``min_cover`` of its cells, the
    one closer to the cells either holds (RMS) is a face. Rounds end when none is."""
    rng = np.random.default_rng(seed)
    out = QuadricResult()
    n_planes = len(planes)
    known = row_norms(nrm) > 0.5
    if np.count_nonzero(known) < max(20, min_cells):
        return out
    free = known.copy()
    cos_min = np.cos(np.radians(settings.normal_deg))
    dist = settings.inlier_dists * dist_m
    r_min, r_max = settings.min_radius_cells * cell_m, settings.max_radius_frac * extent_m
    a_min, a_max = np.radians(settings.min_half_angle_deg), np.radians(settings.max_half_angle_deg)
    plane_cells = np.bincount(plane_of[known & (plane_of >= 0)], minlength=n_planes)
    res = np.full(len(pts), np.nan)
    for k, p in enumerate(planes):
        res[plane_of == k] = p.distance(pts[plane_of == k])

    def fit(model, on: np.ndarray):
        """The refit on the cells ``on`` (a seeded sample of them), started from the linear fit (a sphere's
        algebraic fit, a cone's from its normals), which saves the least-squares fit where that fixes no valid
        surface: False then, None where the least-squares fit does not converge."""
        idx = np.flatnonzero(on)
        if len(idx) > settings.fit_cells:
            idx = np.sort(rng.choice(idx, settings.fit_cells, replace=False))
        if isinstance(model, Sphere):
            start = algebraic_sphere(pts[idx])
            if start is None or not valid(start):
                return False
            return refine_sphere(pts[idx], replace(start, side=model.side))
        start = cone_from_normals(pts[idx], nrm[idx])
        if start is None or not valid(start):
            return False
        return refine_cone(pts[idx], start)

    def on_surface(model) -> np.ndarray:
        """The largest connected piece of the free cells on the model's surface (m,) bool."""
        sel = np.zeros(len(pts), bool)
        idx = np.flatnonzero(free)
        sel[idx] = _inliers(model, pts[idx], nrm[idx], dist, cos_min)
        return largest_piece_on(sel, box)

    def valid(model) -> bool:
        if isinstance(model, Sphere):
            return r_min <= model.radius <= r_max
        return settings.min_half_angle_deg <= model.half_angle_deg <= settings.max_half_angle_deg

    for _ in range(settings.max_faces):
        idx = np.flatnonzero(free)
        if len(idx) < max(20, min_cells):
            break
        found = []
        for sample in (
                lambda: sample_sphere(pts[idx], nrm[idx], dist, cos_min, r_min, r_max, rng, settings.trials,
                                      settings.score_cells),
                lambda: sample_cone(pts[idx], nrm[idx], dist, cos_min, a_min, a_max, rng, settings.trials,
                                    settings.score_cells)):
            model = sample()
            if model is None:
                continue
            on = np.zeros(len(pts), bool)
            for _ in range(settings.refits):
                on = on_surface(model)
                if np.count_nonzero(on) < max(20, min_cells):
                    break
                again = fit(model, on)
                if again is False:
                    break
                if again is None:
                    out.unconverged += 1
                    model = None
                    break
                if not valid(again):
                    break
                model = again
            if model is None:
                continue
            on = on_surface(model)
            if isinstance(model, Cone) and on.any():  # its height: the farthest of its cells along the axis
                model = Cone(model.apex, model.axis, model.half_angle_deg,
                             float(np.percentile(model.local(pts[on])[0], 99)))
            got = np.bincount(plane_of[on & (plane_of >= 0)], minlength=n_planes)
            gone = [k for k in range(n_planes) if plane_cells[k] and got[k] >= 0.5 * plane_cells[k]]
            enough = bool(gone) or np.count_nonzero(on) >= settings.min_cover * np.count_nonzero(known)
            if enough and valid(model) and _stands(model, pts[on], nrm[on], res[on], dist, min_cells, settings):
                found.append(("sphere" if isinstance(model, Sphere) else "cone", model, on, gone))
        if not found:
            break
        # of a sphere and a cone that both stand (a cone tangent to a ball fits it within RealSense's noise), the
        # one closer to the cells either holds
        both = np.logical_or.reduce([f[2] for f in found])
        best = min(found, key=lambda f: (float(np.mean(_residual_normal(f[1], pts[both])[0] ** 2)),
                                         -np.count_nonzero(f[2])))
        out.faces.append(best)
        free &= ~best[2]
    return out


def leaves_room(mask: np.ndarray, nrm_box: np.ndarray, rows: np.ndarray, cols: np.ndarray, planes: list,
                adjacency: list[tuple[int, int]], settings: QuadricSettings) -> bool:
    """Whether an object's planes leave room for a curved surface (``max_step_deg``, ``free_share``,
    ``max_flat_faces``): the sample consensus of spheres, cones and cylinders runs only then."""
    if not planes or len(planes) > settings.max_flat_faces:
        return True
    cos_step = np.cos(np.radians(settings.max_step_deg))
    if any(float(planes[i].plane.n @ planes[j].plane.n) >= cos_step for i, j in adjacency):
        return True
    box = mask[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
    known = row_norms(nrm_box[box]) > 0.5
    on_plane = np.zeros_like(known)
    for p in planes:
        on_plane |= p.mask[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1][box]
    return np.count_nonzero(known & ~on_plane) >= settings.free_share * max(1, np.count_nonzero(known))


def quadric_faces(xyz: np.ndarray, mask: np.ndarray, nrm_box: np.ndarray, planes: list,
                  adjacency: list[tuple[int, int]], cell_rel: float, min_cells: int, seed: int,
                  scale: tuple[float, float], settings: QuadricSettings = DEFAULT, room: bool | None = None,
                  sensor: SensorNoise = SENSOR) -> tuple[list, list[tuple[int, int]], list[QuadricFace], int]:
    """The depth stage's view of :func:`object_quadrics` for one object: ``xyz`` (h, w, 3) the grid's points,
    ``mask`` (h, w) the object's cells, ``nrm_box`` its normals on its bounding box of the grid, ``planes`` its
    DepthPlanes (each with a grid ``mask`` and a ``plane``) touching in pairs ``adjacency``, ``cell_rel`` a grid
    cell's width as a fraction of the depth, ``min_cells`` the fewest cells of a face, ``scale`` the object's
    median depth and extent (objects.object_scale). The inlier distance is ``sensor``'s at the object's median
    depth (support.SensorNoise), as for cylinders. Returns the planes
    kept and their adjacency, the faces (each one connected piece of cells no kept plane holds) and the count of
    fits that did not converge. ``room``: :func:`leaves_room` of the object where the caller already asked it."""
    from .planes import largest_piece

    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return planes, list(adjacency), [], 0
    if not (leaves_room(mask, nrm_box, rows, cols, planes, adjacency, settings) if room is None else room):
        return planes, list(adjacency), [], 0
    i0, i1, j0, j1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    box = mask[i0:i1, j0:j1]
    nrm = cell_rows(nrm_box, box).astype(np.float64)
    pts = cell_rows(xyz[i0:i1, j0:j1], box).astype(np.float64)
    plane_of = np.full(len(pts), -1)
    for k, p in enumerate(planes):
        plane_of[p.mask[i0:i1, j0:j1][box]] = k
    z, extent = scale
    found = object_quadrics(pts, nrm, box, plane_of, [p.plane for p in planes], sensor.inlier_m(z), extent,
                            cell_rel * z, min_cells, seed, settings)
    if not found.faces:
        return planes, list(adjacency), [], found.unconverged
    gone = {k for *_, g in found.faces for k in g}
    keep = [k for k in range(len(planes)) if k not in gone]
    faces = []
    for surface, model, on, _ in found.faces:
        face = np.zeros_like(mask)
        face[i0:i1, j0:j1][box] = on
        for k in keep:
            face &= ~planes[k].mask
        face = largest_piece(face)
        if not face.any():
            continue
        p = xyz[face].astype(np.float64)
        res, _ = _residual_normal(model, p)
        faces.append(QuadricFace(surface, face, xyz[face].astype(np.float32), float(np.sqrt(np.mean(res ** 2))),
                                 sphere=model if surface == "sphere" else None,
                                 cone=model if surface == "cone" else None))
    index = {k: i for i, k in enumerate(keep)}
    return ([planes[k] for k in keep], [(index[a], index[b]) for a, b in adjacency if a in index and b in index],
            faces, found.unconverged)
