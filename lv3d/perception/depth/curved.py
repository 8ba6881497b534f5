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

A fan is not always there: on RealSense frames the plane search cuts a small can's side into facets 60 deg
apart (as far apart as a hexagonal prism's sides), or hands half of it to the lid's plane, or the can is one of
several objects the segmentation joined. So after the fan, a seeded sample consensus over the object's remaining
cells draws pairs of cells with their normals (Schnabel, Wahl and Klein 2007: two oriented points fix a cylinder)
and keeps the cylinder most cells agree with; it is refitted on every cell on its surface in one connected piece,
and stands only where it fits those cells better than the object's planes do and its normals fill a wide arc
without the dip two planes leave (a box's two faces at 90 deg stay planes), and where it takes over at least half
of one of the object's planes. A tin's lid fits no pair (its normals are parallel).

A cylinder is read from either side: its outside (a can; the normals point away from the axis) or its inside
(an open pot's or a cup's inner wall seen over the rim; the normals point towards it). A pair of cells tells
which: the centre lies behind both or in front of both. An inside must also beat a sphere, which a bowl's
inside is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...cylinder import Cylinder
from ...plane import column_means, row_norms
from ...sphere import algebraic_sphere
from .planes import largest_piece_on
from .ranges import check_ranges


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
    ``min_radius_cells`` (grid cells at the object's depth): a smaller radius turns the normals within the 5x5
    cells they are averaged over (a box's edge, rounded by the sensor, fits one).
    ``min_share`` (fraction): the share of one plane's residual variance over the face's cells the cylinder must
    explain (describe.curved_evidence, the fact's confidence; 0.5: curved is the likelier reading).
    ``misfit_ratio`` (fraction): a sampled cylinder's systematic misfit over the cells the object's planes held
    must be at most this share of the planes' own (:func:`misfit`: the part of the residuals that does not average
    out over bins around the axis). On a real sensor's depth both surfaces fit a can within the noise, so their
    RMS residuals are alike, but planes fitted to a curved side bow away from it in the middle of each facet and
    a cylinder fitted across a box's faces bows away at the edge: the surface that is the wrong model leaves
    residuals that keep their sign bin after bin.
    ``sample_arc_deg`` / ``min_dip`` (degrees / fraction): the normals of a sampled cylinder's cells, binned every
    ``max_gap_deg / 2`` around the axis, must spread over this arc, its emptiest bin holding this share of its
    fullest (curved.normal_profile): RealSense normals scatter by 7-10 deg on a flat face, which fills the gaps a
    box's edge leaves between single normals but not the dip between its faces' two peaks.
    ``bin_cells`` (cells): a bin of positions around the axis counts when it holds this many (curved.track).
    ``max_faces`` (faces): the most cylindrical faces of one object (a clutter of cans the segmentation joined).
    ``trials`` / ``score_cells`` / ``refits``: the sample consensus's pairs of cells, the seeded sample of cells
    each is scored on, and the least-squares refits on all the object's cells on the surface.
    """

    max_step_deg: float = 50.0
    normal_deg: float = 25.0
    inlier_dists: float = 1.0
    min_cover: float = 0.7
    min_arc_deg: float = 40.0
    max_gap_deg: float = 20.0
    max_radius_frac: float = 1.0
    min_radius_cells: float = 4.0
    min_share: float = 0.5
    misfit_ratio: float = 0.7
    sample_arc_deg: float = 60.0
    min_dip: float = 0.1
    bin_cells: int = 10
    max_faces: int = 3
    trials: int = 256
    score_cells: int = 800
    refits: int = 3

    def __post_init__(self) -> None:
        check_ranges(self, angles=("max_step_deg",), acute=("normal_deg",),
                     fractions=("min_cover", "min_share", "misfit_ratio", "min_dip"),
                     arcs=("min_arc_deg", "max_gap_deg", "sample_arc_deg"),
                     positive=("inlier_dists", "max_radius_frac", "min_radius_cells"),
                     counts={"bin_cells": 1, "max_faces": 1, "trials": 1, "score_cells": 1, "refits": 0})


DEFAULT = CurvedSettings()


@dataclass(frozen=True)
class CurvedFace:
    """A cylindrical face of an object: its ``cylinder``, grid ``mask`` (h, w) bool, ``points`` (m, 3) metres and
    ``rms_m``, the RMS of the points' distances from the surface."""

    cylinder: Cylinder
    mask: np.ndarray
    points: np.ndarray
    rms_m: float


def _inliers(cyl: Cylinder, pts: np.ndarray, nrm: np.ndarray, dist_m: float, cos_min: float, side: float = 1.0
             ) -> np.ndarray:
    """The points (m, 3) within ``dist_m`` of the surface whose unit normals (m, 3) turn from the radial
    direction by less than ``arccos(cos_min)``: the direction away from the axis for ``side`` 1 (the outside of
    a can), towards it for -1 (the inside of a pot or a cup, seen over its rim)."""
    r, out = cyl.radial(pts)
    return (np.abs(r - cyl.radius) <= dist_m) & (side * np.einsum("ij,ij->i", out, nrm) >= cos_min)


def facing(cyl: Cylinder, nrm: np.ndarray, pts: np.ndarray) -> float:
    """Which side of the cylinder the points (m, 3) with unit normals (m, 3) show: 1 its outside (their normals
    point away from the axis, most of them), -1 its inside."""
    _, out = cyl.radial(pts)
    return 1.0 if float(np.median(np.einsum("ij,ij->i", out, nrm))) >= 0 else -1.0


def refine(pts: np.ndarray, nrm: np.ndarray) -> Cylinder | None:
    """Least-squares cylinder through points (m, 3) with unit normals (m, 3), of its outside or its inside (the
    normals' sign does not matter): the axis is the direction the normals are most nearly perpendicular to, the
    circle Kasa's fit to the points projected along it."""
    _, vecs = np.linalg.eigh(nrm.T @ nrm)
    a, b1, b2 = axis_basis(vecs[:, 0])
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
    _, b1, b2 = axis_basis(cyl.axis)
    ang = np.sort(np.degrees(np.arctan2(nrm @ b2, nrm @ b1)))
    gaps = np.diff(np.concatenate([ang, ang[:1] + 360.0]))
    k = int(np.argmax(gaps))  # the arc is the circle less its widest gap
    inner = np.delete(gaps, k)
    return float(360.0 - gaps[k]), float(inner.max()) if len(inner) else 0.0


def fan_cylinder(normals: list[np.ndarray], sizes: list[int], adjacency: list[tuple[int, int]],
                 pts: np.ndarray, nrm: np.ndarray, plane_of: np.ndarray, dist_m: float, extent_m: float,
                 settings: CurvedSettings = DEFAULT) -> tuple[Cylinder, np.ndarray, list[int], float] | None:
    """The cylindrical face of an object whose planes have unit ``normals`` (towards the camera), cell counts
    ``sizes`` and touching pairs ``adjacency``; ``pts`` (m, 3) metres and unit ``nrm`` (m, 3) are the object's
    cells (zero normal where unknown), ``plane_of`` (m,) the plane index of each cell (-1: none). Returns the
    cylinder, the cells on it (m,) bool, the planes it replaces and the side the fan shows (:func:`facing`: 1 the
    outside, -1 the inside); None when no fan makes one."""
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
    known = row_norms(nrm) > 0.5
    cos_min = np.cos(np.radians(settings.normal_deg))
    for fan in fans:
        cells = np.isin(plane_of, fan) & known
        if np.count_nonzero(cells) < 20:
            continue
        cyl = refine(pts[cells], nrm[cells])
        if cyl is None or cyl.radius > settings.max_radius_frac * extent_m:
            continue
        side = facing(cyl, nrm[cells], pts[cells])
        inl = known & _inliers(cyl, pts, nrm, settings.inlier_dists * dist_m, cos_min, side)
        for _ in range(3):  # refit on the surface's own cells, strips between the fan's planes included
            if np.count_nonzero(inl) < 20:
                break
            again = refine(pts[inl], nrm[inl])
            if again is None or again.radius > settings.max_radius_frac * extent_m:
                break
            cyl = again
            inl = known & _inliers(cyl, pts, nrm, settings.inlier_dists * dist_m, cos_min, side)
        if np.count_nonzero(inl & cells) < settings.min_cover * np.count_nonzero(cells):
            continue
        r, _ = cyl.radial(pts[inl])
        if float(np.sqrt(np.mean((r - cyl.radius) ** 2))) > dist_m:
            continue
        arc, gap = _normal_arc(cyl, nrm[inl])
        if arc < settings.min_arc_deg or gap > settings.max_gap_deg:
            continue
        return cyl, inl, fan, side
    return None


def _pair_cylinders(p1: np.ndarray, n1: np.ndarray, p2: np.ndarray, n2: np.ndarray, min_sin: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cylinders through pairs of oriented points (k, 3) each (Schnabel, Wahl and Klein 2007): the axis is
    perpendicular to both normals, the centre where the lines along the normals meet, seen along the axis.
    Returns axes (k, 3), centres (k, 3), radii (k,), sides (k,) (1: the centre lies behind both points, which
    show the cylinder's outside; -1: in front of both, its inside) and which pairs give one (their normals turned
    by an angle whose sine is ``min_sin`` or more, the centre on one side of both points at distances that agree
    within half)."""
    a = np.cross(n1, n2)
    s = np.linalg.norm(a, axis=1)
    ok = s >= min_sin
    a = a / np.maximum(s, 1e-12)[:, None]
    d = p1 - p2
    d = d - np.einsum("ij,ij->i", d, a)[:, None] * a
    # t n1 - u n2 = d (both normals are perpendicular to the axis): p1 - t n1 = p2 - u n2 is the centre
    c12 = np.einsum("ij,ij->i", n1, n2)
    det = c12 * c12 - 1.0  # of [[1, -c12], [c12, -1]]
    b1, b2 = np.einsum("ij,ij->i", n1, d), np.einsum("ij,ij->i", n2, d)
    det = np.where(np.abs(det) < 1e-12, 1e-12, det)
    t = (-b1 + c12 * b2) / det
    u = (-c12 * b1 + b2) / det
    side = np.where(t + u >= 0, 1.0, -1.0)
    r = 0.5 * np.abs(t + u)
    ok &= (side * t > 0) & (side * u > 0) & (np.abs(t - u) <= 0.5 * r)
    centre = p1 - t[:, None] * n1
    return a, centre, r, side, ok


def axis_terms(pts: np.ndarray, nrm: np.ndarray, origins: np.ndarray, axes: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For k lines (a point ``origins`` (k, 3) and a unit direction ``axes`` (k, 3) each) and s points (s, 3)
    with unit normals (s, 3): the points' distances from each line (k, s), and the dot of each point's normal
    with its offset from the line (k, s) (the distance times the cosine between the normal and the direction
    away from the line), and each point's position along each line from its origin (k, s). Products of (k, 3)
    by (3, s) matrices, coordinates about the points' mean."""
    o = column_means(pts)
    p, c = pts - o, origins - o
    along = axes @ p.T - np.einsum("kj,kj->k", c, axes)[:, None]              # (k, s): d . a
    dd = np.einsum("sj,sj->s", p, p)[None, :] - 2.0 * (c @ p.T) + np.einsum("kj,kj->k", c, c)[:, None]
    r = np.sqrt(np.maximum(dd - along * along, 0.0))
    dn = np.einsum("sj,sj->s", p, nrm)[None, :] - c @ nrm.T - along * (axes @ nrm.T)
    return r, dn, along


def sample_cylinder(pts: np.ndarray, nrm: np.ndarray, dist_m: float, cos_min: float, r_min: float, r_max: float,
                    rng: np.random.Generator, trials: int = 256, score_points: int = 800,
                    min_pair_deg: float = 15.0) -> tuple[Cylinder, float] | None:
    """The cylinder with most inliers (within ``dist_m`` of the surface, the normal within ``arccos(cos_min)`` of
    the radial direction, outwards or inwards as the pair shows it) among ``trials`` seeded random pairs of the
    oriented points (m, 3) and unit normals (m, 3), scored on a seeded sample of ``score_points`` of them; its
    radius in [r_min, r_max]. Returns it and the side the points show (1 outside, -1 inside: _pair_cylinders);
    None when no pair gives one."""
    m = len(pts)
    if m < 20:
        return None
    score = rng.choice(m, min(m, score_points), replace=False)
    sp, sn = pts[score], nrm[score]
    i, j = rng.integers(0, m, trials), rng.integers(0, m, trials)
    axes, centres, radii, sides, ok = _pair_cylinders(pts[i], nrm[i], pts[j], nrm[j],
                                                      np.sin(np.radians(min_pair_deg)))
    ok &= (radii >= r_min) & (radii <= r_max)
    if not ok.any():
        return None
    axes, centres, radii, sides = axes[ok], centres[ok], radii[ok], sides[ok]
    # each hypothesis k against each scored point s, d = p_s - c_k, in (k, s) products rather than (k, s, 3)
    # arrays: along = d . a, r^2 = |d|^2 - along^2, and the radial direction's dot with the normal is
    # (d . n - along (a . n)) / r (coordinates taken about the scored points' mean, where they are small)
    r, radial_n, _ = axis_terms(sp, sn, centres, axes)
    count = np.count_nonzero((np.abs(r - radii[:, None]) <= dist_m) & (sides[:, None] * radial_n >= cos_min * r),
                             axis=1)
    b = int(np.argmax(count))
    return Cylinder(tuple(axes[b]), tuple(centres[b]), float(radii[b])), float(sides[b])


def object_cylinders(pts: np.ndarray, nrm: np.ndarray, box: np.ndarray, plane_of: np.ndarray, planes: list,
                     dist_m: float, extent_m: float, cell_m: float, min_cells: int, seed: int = 0,
                     settings: CurvedSettings = DEFAULT, adjacency: list[tuple[int, int]] = (), sample: bool = True
                     ) -> list[tuple[Cylinder, np.ndarray, list[int]]]:
    """The cylindrical faces of an object: ``pts`` (m, 3) metres and unit ``nrm`` (m, 3) (zero where unknown) are
    its cells, in row-major order of ``box`` (the object's cells on its bounding box of the grid, bool);
    ``plane_of`` (m,) the index of each cell's plane (-1: none) among ``planes`` (lv3d.plane.Plane), which touch
    in pairs ``adjacency``; ``dist_m`` the inlier distance, ``extent_m`` the object's size, ``cell_m`` the width of
    one grid cell at its depth (metres), ``min_cells`` the fewest cells of a face.

    First a fan of planes that a cylinder fits (:func:`fan_cylinder`); then, on the cells of no face found, the
    cylinder a seeded sample consensus over the cells' points and normals finds (:func:`sample_cylinder`),
    refitted on every free cell on its surface in one connected piece. A sampled cylinder stands when its
    systematic misfit over the cells the planes held is well below the planes' (``misfit_ratio``) and it passes
    :func:`_stands`: a fan of planes 60 deg
    apart on a small can, a can whose planes took cells of its lid, a can in a clutter of objects. Returns
    (cylinder, its cells (m,) bool, the planes it replaces: those with half their cells or more on it) per face,
    at most ``settings.max_faces``. ``sample`` False: the fan of planes only (the caller found that the object's
    planes leave no room for a curved surface: quadrics.leaves_room), which spares a box the sample consensus."""
    rng = np.random.default_rng(seed)
    n_planes = len(planes)
    known = row_norms(nrm) > 0.5
    free = known.copy()
    cos_min = np.cos(np.radians(settings.normal_deg))
    dist = settings.inlier_dists * dist_m
    r_min, r_max = settings.min_radius_cells * cell_m, settings.max_radius_frac * extent_m
    plane_cells = np.bincount(plane_of[known & (plane_of >= 0)], minlength=n_planes)
    res = np.full(len(pts), np.nan)  # each cell's signed distance from its plane, positive towards the camera
    for k, p in enumerate(planes):
        mine = plane_of == k
        if mine.any():
            res[mine] = p.distance(pts[mine])
            if float(p.n @ column_means(pts[mine])) > 0:
                res[mine] *= -1.0
    out = []

    def replaced(on: np.ndarray) -> list[int]:
        got = np.bincount(plane_of[on & (plane_of >= 0)], minlength=n_planes)
        return [k for k in range(n_planes) if plane_cells[k] and got[k] >= 0.5 * plane_cells[k]]

    if n_planes >= 2 and adjacency:
        fan = fan_cylinder([p.n for p in planes], [int(c) for c in plane_cells], list(adjacency), pts, nrm,
                           plane_of, dist_m, extent_m, settings)
        if fan is not None:
            cyl, on, members, side = fan
            on = largest_piece_on(on, box)
            if _stands(cyl, pts[on], nrm[on], None, dist_m, min_cells, settings, side):
                out.append((cyl, on, sorted(set(members) | set(replaced(on)))))
                free &= ~on
    for _ in range(settings.max_faces * 2 if sample else 0):  # a rejected sample does not end the search at once
        if len(out) >= settings.max_faces or np.count_nonzero(free) < max(20, min_cells):
            break
        idx = np.flatnonzero(free)
        sampled = sample_cylinder(pts[idx], nrm[idx], dist, cos_min, r_min, r_max, rng, settings.trials,
                                  settings.score_cells)
        if sampled is None:
            break
        cyl, side = sampled
        on = np.zeros(len(pts), bool)
        for _ in range(settings.refits):
            on = largest_piece_on(free & _inliers(cyl, pts, nrm, dist, cos_min, side), box)
            if np.count_nonzero(on) < max(20, min_cells):
                break
            again = refine(pts[on], nrm[on])
            if again is None or not r_min <= again.radius <= r_max:
                break
            cyl = again
        on = largest_piece_on(free & _inliers(cyl, pts, nrm, dist, cos_min, side), box)
        ok = on & (plane_of >= 0)
        gone = replaced(on) if ok.any() else []
        if gone and _stands(cyl, pts[on], nrm[on], (pts[ok], res[ok]), dist, min_cells, settings, side):
            out.append((cyl, on, gone))
            free &= ~on
        elif on.any():
            free &= ~on  # the next sample searches elsewhere
        else:
            break
    return out


def _stands(cyl: Cylinder, pts: np.ndarray, nrm: np.ndarray, plane_fit: tuple[np.ndarray, np.ndarray] | None,
            dist_m: float, min_cells: int, settings: CurvedSettings, side: float = 1.0) -> bool:
    """Whether a cylinder's cells (points and normals) make a curved face: enough of them, within the inlier
    distance of it on average and with a systematic misfit well below the object's planes' (``plane_fit``: the
    points of its cells that lie on planes and their signed distances from them, positive towards the camera
    (:func:`misfit`); None for a fan of planes already read as a cylinder), spread around the axis through a
    wide arc without a gap (:func:`track`), and a cylinder that explains most of one plane's residual over them
    (:func:`curved_share`). Cells that show a cylinder's inside (``side`` -1: a pot's or a cup's inner wall over
    its rim) must also be explained better by it than by a sphere (the share of the algebraic sphere's residual
    variance it explains at least ``min_share``): a bowl's inside is a sphere's, which the sphere search
    (quadrics, before this one) reads from either side, as it reads a ball's outside, and may have left."""
    if len(pts) < max(20, min_cells):
        return False
    r, _ = cyl.radial(pts)
    rms = float(np.sqrt(np.mean((r - cyl.radius) ** 2)))
    if rms > dist_m:
        return False
    if plane_fit is not None:
        on_planes, plane_res = plane_fit
        bin_deg = settings.max_gap_deg / 2
        theirs = misfit(cyl, on_planes, plane_res, bin_deg)
        if misfit(cyl, on_planes, side * (cyl.radial(on_planes)[0] - cyl.radius), bin_deg) > \
                settings.misfit_ratio * theirs:
            return False
    _, arc, gap = track(cyl, pts, nrm, settings.max_gap_deg / 2, settings.bin_cells)
    if arc < settings.min_arc_deg or gap > settings.max_gap_deg:
        return False
    arc, dip = normal_profile(cyl, nrm, settings.max_gap_deg / 2)
    if arc < settings.sample_arc_deg or dip < settings.min_dip:
        return False
    if side < 0:
        sphere = algebraic_sphere(pts)
        if sphere is not None:
            over_sphere = explained_share(rms * rms, float(np.mean(sphere.residual(pts) ** 2)))
            if over_sphere is None or over_sphere < settings.min_share:
                return False
    return curved_share(pts, cyl) >= settings.min_share


def misfit(cyl: Cylinder, pts: np.ndarray, res: np.ndarray, bin_deg: float) -> float:
    """The systematic part of the residuals ``res`` (m,) (metres, signed) of points (m, 3) on or near a
    cylinder: the points binned by their angle around its axis, ``bin_deg`` wide, the RMS over the points of
    their bin's mean residual. Noise averages out in a bin's mean (to its sigma over the root of the bin's count,
    alike for any surface fitted to the same points); a surface of the wrong shape leaves residuals of one sign
    across a bin: a plane fitted to a curved side lies behind it at the facet's middle and in front at its ends,
    a cylinder fitted across a box's two faces in front of the faces and behind their edge. 0 for no point."""
    if len(pts) == 0:
        return 0.0
    a, b1, b2 = axis_basis(cyl.axis)
    d = pts - np.asarray(cyl.point)
    bins = ((np.degrees(np.arctan2(d @ b2, d @ b1)) + 180.0) // bin_deg).astype(int)
    count = np.bincount(bins)
    total = np.bincount(bins, weights=res)
    full = count > 0
    mean = total[full] / count[full]
    return float(np.sqrt(np.sum(count[full] * mean * mean) / len(pts)))


def plane_ms(pts: np.ndarray) -> float:
    """Mean square distance of points (m, 3) from their least-squares plane."""
    centred = pts - column_means(pts)
    return float(np.linalg.svd(centred, compute_uv=False)[-1] ** 2 / len(pts))


def explained_share(ms: float, alt_ms: float) -> float | None:
    """1 - ms / alt_ms in [0, 1]: the share of a simpler surface's residual variance (``alt_ms``, mean square)
    that a surface with residual ``ms`` explains; None where either is not finite or ``alt_ms`` is not above 0.
    The confidence of the curved-surface facts (describe.curved_evidence, quadrics)."""
    if not (np.isfinite(ms) and np.isfinite(alt_ms) and alt_ms > 0):
        return None
    return float(np.clip(1.0 - ms / alt_ms, 0.0, 1.0))


def cylinder_share(pts: np.ndarray, cyl: Cylinder) -> float | None:
    """The share of a plane's residual variance over the points (m, 3) that the cylinder explains,
    1 - rms_cylinder^2 / rms_plane^2 (:func:`explained_share`)."""
    r, _ = cyl.radial(pts)
    return explained_share(float(np.mean((r - cyl.radius) ** 2)), plane_ms(pts))


def curved_share(pts: np.ndarray, cyl: Cylinder) -> float:
    """:func:`cylinder_share`, 0 where it cannot be measured (describe.curved_evidence, the fact's confidence)."""
    share = cylinder_share(pts, cyl)
    return 0.0 if share is None else share


def axis_basis(axis) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unit ``axis`` (3,) (normalised) and two unit vectors that make a right-handed frame with it."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    b1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    return a, b1, np.cross(a, b1)


def track(cyl: Cylinder, pts: np.ndarray, nrm: np.ndarray, bin_deg: float, min_count: int
          ) -> tuple[float, float, float]:
    """How the normals (m, 3) of points (m, 3) on a cylinder follow its surface: the points' angles around the
    axis are cut into bins ``bin_deg`` wide; in each bin of ``min_count`` points or more, the median turn of the
    normals from the radial direction (degrees, seen along the axis). Returns (the largest of those medians in
    absolute value, the arc the points span over such bins, the widest gap between them), degrees. A cylinder's
    normals follow the radial direction and only their noise spreads them (a median cancels it); two planes a
    cylinder was fitted through keep their normals fixed while the radial direction turns along them."""
    a, b1, b2 = axis_basis(cyl.axis)
    d = pts - np.asarray(cyl.point)
    theta = np.degrees(np.arctan2(d @ b2, d @ b1))
    phi = np.degrees(np.arctan2(nrm @ b2, nrm @ b1))
    turn = (phi - theta + 180.0) % 360.0 - 180.0
    # unwrap the positions at their widest gap, so that the arc is one run of bins
    order = np.sort(theta)
    gaps = np.diff(np.concatenate([order, order[:1] + 360.0]))
    k = int(np.argmax(gaps))
    start = order[(k + 1) % len(order)]
    theta = (theta - start) % 360.0
    bins = (theta // bin_deg).astype(int)
    counts = np.bincount(bins)
    full = np.flatnonzero(counts >= min_count)
    if len(full) == 0:
        return 180.0, 0.0, 0.0
    worst = max(abs(float(np.median(turn[bins == b]))) for b in full)
    arc = float((full[-1] - full[0] + 1) * bin_deg)
    gap = float((np.diff(full).max() - 1) * bin_deg) if len(full) > 1 else 0.0
    return worst, arc, gap


def normal_profile(cyl: Cylinder, nrm: np.ndarray, bin_deg: float, edge_frac: float = 0.25) -> tuple[float, float]:
    """How evenly the unit normals (m, 3) turn around the cylinder's axis: their angles seen along it, in bins
    ``bin_deg`` wide. The arc runs from the first to the last bin holding ``edge_frac`` of the fullest bin or more;
    the dip is the emptiest bin inside it over the fullest. Returns (arc, dip), degrees and a fraction. A curved
    side's normals fill their arc (a camera sees fewer cells per degree towards its rims, half as many at 60 deg
    from the line of sight); two planes' normals make two peaks with a dip between them that their noise does not
    fill (a box's edge, rounded by the sensor, holds a few cells per degree where its faces hold hundreds)."""
    a, b1, b2 = axis_basis(cyl.axis)
    phi = np.degrees(np.arctan2(nrm @ b2, nrm @ b1))
    nb = int(np.ceil(360.0 / bin_deg))
    counts = np.bincount(((phi + 180.0) // bin_deg).astype(int) % nb, minlength=nb)
    # start the circle of bins after its longest empty run, so that the arc does not wrap
    empty = counts == 0
    if empty.any():
        run, best, best_end = 0, -1, 0
        for i in range(2 * nb):
            run = run + 1 if empty[i % nb] else 0
            if run > best:
                best, best_end = run, i
        counts = np.roll(counts, -((best_end + 1) % nb))
    full = np.flatnonzero(counts >= edge_frac * counts.max())
    inside = counts[full[0]:full[-1] + 1]
    return float(len(inside) * bin_deg), float(inside.min() / counts.max())
