"""Cylindrical surfaces of an object: the side of a can, a tin, a cup or a bottle, as one face rather than a fan
of planes.

The depth stage fits planes first (planes.object_planes); a curved side comes out as a fan of narrow planes, each
turned from the next by a few tens of degrees, all perpendicular to one axis. A fan of two or more touching planes
turned by less than a polyhedron's edge turns (``CurvedSettings.max_step_deg``) is a cylinder candidate: the
axis is the direction the fan's normals are most nearly perpendicular to, and the circle is Kasa's algebraic
least-squares fit to the points projected along it. The candidate is a curved face when the surface fits its
points within the sensor's noise, its normals turn through a wide, gap-free arc around the axis (a box's two
faces leave a gap of nearly 90 deg), and its radius is below the object's size. Its face then holds every cell
of the object on the surface, and the fan's planes are gone. Planes across the axis (a can's lid) stay planes.

Why not a RANSAC over all the object's points (PCL's SACMODEL_CYLINDER): a tin's lid, a large plane, fits a
cylinder of huge radius better than the side fits any, and a box's two faces fit one of radius about half the
box; the fan of planes already says where the surface turns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...cylinder import Cylinder


@dataclass(frozen=True)
class CurvedSettings:
    """Thresholds of the cylinder search (scale-free: fractions of the object, angles, multiples of the inlier
    distance, itself the sensor's noise at the object's depth).

    ``max_step_deg`` (degrees): touching planes turned from each other by less are facets of one curved surface;
    the sides of the prisms lv3d knows turn by 60 deg or more (a hexagonal prism's), a fan of facets on a can by
    15-40.
    ``normal_deg`` (degrees): how far a cell's normal may turn from the radial direction (normals are averaged
    over 5x5 cells, so they lag the surface's turn on a small radius).
    ``inlier_dists`` (multiples of the inlier distance, the sensor's noise at the object's depth): how far from
    the surface a cell may lie and still be on it.
    ``min_cover`` (fraction): the share of the fan's cells the fitted surface must hold.
    ``min_arc_deg`` / ``max_gap_deg`` (degrees): the surface's normals must turn through at least this arc around
    the axis, with no gap inside it wider than this (two faces of a box turn by 90 deg with nothing between).
    ``max_radius_frac`` (fraction of the object's extent in metres): a larger radius is a plane's.
    """

    max_step_deg: float = 50.0
    normal_deg: float = 25.0
    inlier_dists: float = 1.0
    min_cover: float = 0.7
    min_arc_deg: float = 40.0
    max_gap_deg: float = 20.0
    max_radius_frac: float = 1.0


DEFAULT = CurvedSettings()


@dataclass(frozen=True)
class CurvedFace:
    """A cylindrical face of an object: its ``cylinder``, grid ``mask`` (h, w) bool, ``points`` (m, 3) metres and
    ``rms_m``, the RMS of the points' distances from the surface."""

    cylinder: Cylinder
    mask: np.ndarray
    points: np.ndarray
    rms_m: float


def _inliers(cyl: Cylinder, pts: np.ndarray, nrm: np.ndarray, dist_m: float, cos_min: float) -> np.ndarray:
    r, out = cyl.radial(pts)
    return (np.abs(r - cyl.radius) <= dist_m) & (np.einsum("ij,ij->i", out, nrm) >= cos_min)


def refine(pts: np.ndarray, nrm: np.ndarray) -> Cylinder | None:
    """Least-squares cylinder through points (m, 3) with outward unit normals (m, 3): the axis is the direction
    the normals are most nearly perpendicular to, the circle Kasa's fit to the points projected along it."""
    _, vecs = np.linalg.eigh(nrm.T @ nrm)
    a = vecs[:, 0]
    b1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(a, b1)
    x, y = pts @ b1, pts @ b2
    mat = np.stack([x, y, np.ones_like(x)], axis=1)
    sol, *_ = np.linalg.lstsq(mat, x * x + y * y, rcond=None)
    cx, cy = sol[0] / 2, sol[1] / 2
    r2 = sol[2] + cx * cx + cy * cy
    if r2 <= 0:
        return None
    along = float(np.mean(pts @ a))
    return Cylinder(tuple(a), tuple(cx * b1 + cy * b2 + along * a), float(np.sqrt(r2)))


def _normal_arc(cyl: Cylinder, nrm: np.ndarray) -> tuple[float, float]:
    """The arc (degrees) the unit normals (m, 3) span around the cylinder's axis, and the widest gap inside it."""
    a = np.asarray(cyl.axis)
    b1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(a, b1)
    ang = np.sort(np.degrees(np.arctan2(nrm @ b2, nrm @ b1)))
    gaps = np.diff(np.concatenate([ang, ang[:1] + 360.0]))
    k = int(np.argmax(gaps))  # the arc is the circle less its widest gap
    inner = np.delete(gaps, k)
    return float(360.0 - gaps[k]), float(inner.max()) if len(inner) else 0.0


def fan_cylinder(normals: list[np.ndarray], sizes: list[int], adjacency: list[tuple[int, int]],
                 pts: np.ndarray, nrm: np.ndarray, plane_of: np.ndarray, dist_m: float, extent_m: float,
                 settings: CurvedSettings = DEFAULT) -> tuple[Cylinder, np.ndarray, list[int]] | None:
    """The cylindrical face of an object whose planes have unit ``normals`` (towards the camera), cell counts
    ``sizes`` and touching pairs ``adjacency``; ``pts`` (m, 3) metres and unit ``nrm`` (m, 3) are the object's
    cells (zero normal where unknown), ``plane_of`` (m,) the plane index of each cell (-1: none). Returns the
    cylinder, the cells on it (m,) bool and the planes it replaces; None when no fan makes one."""
    cos_step = np.cos(np.radians(settings.max_step_deg))
    parent = list(range(len(normals)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in adjacency:
        if float(normals[i] @ normals[j]) >= cos_step:
            parent[find(i)] = find(j)
    groups: dict[int, list[int]] = {}
    for i in range(len(normals)):
        groups.setdefault(find(i), []).append(i)
    fans = sorted((g for g in groups.values() if len(g) >= 2), key=lambda g: -sum(sizes[i] for i in g))
    known = np.linalg.norm(nrm, axis=1) > 0.5
    cos_min = np.cos(np.radians(settings.normal_deg))
    for fan in fans:
        cells = np.isin(plane_of, fan) & known
        if np.count_nonzero(cells) < 20:
            continue
        cyl = refine(pts[cells], nrm[cells])
        if cyl is None or cyl.radius > settings.max_radius_frac * extent_m:
            continue
        inl = known & _inliers(cyl, pts, nrm, settings.inlier_dists * dist_m, cos_min)
        for _ in range(3):  # refit on the surface's own cells, strips between the fan's planes included
            if np.count_nonzero(inl) < 20:
                break
            again = refine(pts[inl], nrm[inl])
            if again is None or again.radius > settings.max_radius_frac * extent_m:
                break
            cyl = again
            inl = known & _inliers(cyl, pts, nrm, settings.inlier_dists * dist_m, cos_min)
        if np.count_nonzero(inl & cells) < settings.min_cover * np.count_nonzero(cells):
            continue
        r, _ = cyl.radial(pts[inl])
        if float(np.sqrt(np.mean((r - cyl.radius) ** 2))) > dist_m:
            continue
        arc, gap = _normal_arc(cyl, nrm[inl])
        if arc < settings.min_arc_deg or gap > settings.max_gap_deg:
            continue
        return cyl, inl, fan
    return None
