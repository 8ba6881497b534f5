"""Planes of one object: seeded RANSAC on points and normals, peeled off one at a time, each kept as one
connected piece of the image grid and refitted by least squares; then every object point goes to the plane it
fits best, so that neighbouring planes' masks meet along their shared edge."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ...plane import Plane
from .cloud import PointGrid, cell_rows, crop_normals
from .support import SENSOR, SensorNoise, ransac_plane, refine


@dataclass(frozen=True)
class DepthPlane:
    """``plane`` in the camera frame; ``mask`` (h, w) bool on the point grid; ``points`` (m, 3) metres;
    ``rms_m``: RMS point-to-plane distance of those points."""

    plane: Plane
    mask: np.ndarray
    points: np.ndarray
    rms_m: float


def largest_piece(mask: np.ndarray) -> np.ndarray:
    """The largest 8-connected piece of ``mask`` (h, w) bool (of two as large, the one a row-by-row scan meets
    first). The pieces are labelled on the mask's bounding box only: an object's mask covers a small part of the
    grid, and labelling the whole grid for every plane took a tenth of the depth stage's time."""
    rows = np.flatnonzero(mask.any(axis=1))
    if len(rows) == 0:
        return mask
    cols = np.flatnonzero(mask.any(axis=0))
    i0, i1, j0, j1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    n, lab, stats, _ = cv2.connectedComponentsWithStats(mask[i0:i1, j0:j1].astype(np.uint8), connectivity=8)
    if n <= 2:
        return mask.astype(bool)  # one piece: a copy, as the labelled one would be
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    out = np.zeros_like(mask)
    out[i0:i1, j0:j1] = lab == best
    return out


def largest_piece_on(sel: np.ndarray, box: np.ndarray) -> np.ndarray:
    """The largest 8-connected piece of the selected cells ``sel`` (m,) bool laid out on ``box`` (the cells of
    an object on its bounding box of the grid, bool), as a selection of the same cells."""
    if not sel.any():
        return sel
    grid = np.zeros(box.shape, bool)
    grid[box] = sel
    return largest_piece(grid)[box]


def object_planes(grid: PointGrid, obj_mask: np.ndarray, seed: int = 0, max_planes: int = 6,
                  min_frac: float = 0.035, max_need: int = 1500, min_points: int = 25,
                  max_angle_deg: float = 20.0, max_misses: int = 3, normals: np.ndarray | None = None,
                  sensor: SensorNoise = SENSOR) -> list[DepthPlane]:
    """Planes of the object whose grid cells are ``obj_mask`` (h, w) bool, largest first. A plane needs at least
    ``max(min_points, min(min_frac * object size, max_need))`` points in one connected piece: a share of the object
    keeps strips and noise out (depth.py asks more under heavy depth noise), and ``max_need`` lets a large object's
    small face in (the side of a large prism can be under 5 % of its cells).
    A sample whose plane is too small a piece sets its points aside and the search goes on, ``max_misses`` times
    at most: a curved surface beside the object's planes (a can, a drill, in clutter) must not end the search
    before the planes behind it are found. ``normals``: the object's normals on its bounding box of the grid, as
    :func:`~lv3d.perception.cloud.crop_normals` gives them with ``within=obj_mask``, where already computed.
    ``sensor``: the inlier distance at the object's median depth (support.SensorNoise)."""
    rng = np.random.default_rng(seed)
    rows, cols = np.flatnonzero(obj_mask.any(axis=1)), np.flatnonzero(obj_mask.any(axis=0))
    if len(rows) == 0:
        return []
    # work on the object's bounding box of the grid: connected components there are cheap
    i0, j0, i1, j1 = rows[0], cols[0], rows[-1] + 1, cols[-1] + 1
    box = obj_mask[i0:i1, j0:j1]
    pts = cell_rows(grid.xyz[i0:i1, j0:j1], box).astype(np.float64)
    nrm_grid = grid.normals[i0:i1, j0:j1] if normals is None else normals
    if not nrm_grid.any():
        # from the object's points alone: along its silhouette, normals mixed with the table's points agree with
        # none of its faces, and the score below would give a face's silhouette strip to its neighbour
        nrm_grid = crop_normals(grid, i0, j0, i1, j1, within=obj_mask)
    nrm = cell_rows(nrm_grid, box).astype(np.float64)
    if len(pts) < min_points:
        return []
    dist_m = sensor.inlier_m(float(np.median(pts[:, 2])))
    need = max(min_points, min(int(min_frac * len(pts)), max_need))
    free = np.ones(len(pts), bool)
    h, w = box.shape
    planes: list[Plane] = []
    flat = np.flatnonzero(box)  # the object's cells as flat indices, in the order of ``pts``
    tried = np.ones(len(pts), bool)  # points not set aside by a miss
    misses = 0
    while len(planes) < max_planes:
        idx = np.nonzero(free & tried)[0]
        if len(idx) < need:
            break
        plane, inl = ransac_plane(np.take(pts, idx, axis=0), dist_m, rng, iterations=96,
                                  normals=np.take(nrm, idx, axis=0), max_angle_deg=max_angle_deg)
        m = np.zeros((h, w), bool)
        m.flat[flat[idx[inl]]] = True
        piece = largest_piece(m)
        sel = piece[box] & free & tried
        if np.count_nonzero(sel) < need:
            misses += 1
            if misses > max_misses:
                break
            tried[idx[inl]] = False
            continue
        plane = refine(np.compress(sel, pts, axis=0))
        planes.append(plane)
        free &= ~sel
    if not planes:
        return []
    # each point to its best plane (distance, with normals that disagree counted as far)
    cos = np.abs(nrm @ np.array([p.n for p in planes]).T)
    dist = np.abs(pts @ np.array([p.n for p in planes]).T + np.array([p.offset for p in planes])[None, :])
    known = np.linalg.norm(nrm, axis=1) > 0
    score = dist / dist_m + np.where(known[:, None], 2.0 * (1.0 - cos) / (1 - np.cos(np.radians(max_angle_deg))), 0)
    best = np.argmin(score, axis=1)
    ok = dist[np.arange(len(pts)), best] <= 3 * dist_m
    pieces = []  # masks on the object's box until the strips are merged (dilating the box is cheaper)
    for k, plane in enumerate(planes):
        m = np.zeros((h, w), bool)
        m.flat[flat[ok & (best == k)]] = True
        m = largest_piece(m)
        sel = m[box]
        if np.count_nonzero(sel) < need:
            continue
        mine = np.compress(sel, pts, axis=0)
        p = refine(mine)
        rms = float(np.sqrt(np.mean(p.distance(mine) ** 2)))
        pieces.append(DepthPlane(p, m, mine.astype(np.float32), rms))
    out = []
    for d in merge_strips(pieces, dist_m):
        full = np.zeros(obj_mask.shape, bool)
        full[i0:i1, j0:j1] = d.mask
        out.append(DepthPlane(d.plane, full, d.points, d.rms_m))
    out.sort(key=lambda d: -np.count_nonzero(d.mask))
    return out


def merge_strips(planes: list[DepthPlane], dist_m: float, max_median: float = 0.5,
                 min_contact: int = 4) -> list[DepthPlane]:
    """``planes`` with every piece whose points lie on a larger touching plane (median distance at most
    ``max_median`` times the inlier distance ``dist_m``, metres) merged into it and the union refitted, unless
    the points off that plane are a face of their own (:func:`_holds_face`).

    Why: along a silhouette the grid normals mix in the background, so a strip of a face two or three cells
    wide fails the normal test of its face's plane and is peeled off as a plane of its own. Across so narrow a
    strip the depth noise barely constrains a tilt, and the flying pixels on its outer side tilt the fit by
    tens of degrees: a false edge with a false dihedral. A true neighbouring face leaves its points far from the
    other plane (median above the inlier distance), a strip of the same face within half of it. Pieces are taken smallest first, each once, into the largest plane that
    takes it."""
    planes = list(planes)
    for small in sorted(planes, key=lambda p: len(p.points)):
        if not any(q is small for q in planes):
            continue  # grown by a smaller piece already: taken as a plane, not as a strip
        grown = cv2.dilate(small.mask.view(np.uint8), np.ones((5, 5), np.uint8)).view(bool)  # 2 cells around
        for b in sorted(range(len(planes)), key=lambda i: -len(planes[i].points)):
            big = planes[b]
            if big is small or len(big.points) < len(small.points) or np.count_nonzero(grown & big.mask) < min_contact:
                continue
            d = np.abs(big.plane.distance(small.points))
            # median distance within the limit, counted (np.median cost more than the rest of this loop)
            if 2 * np.count_nonzero(d <= max_median * dist_m) < len(d):
                continue
            # the other planes found: big's own is left out, as the far points lie off it by their definition
            others = [q.plane for q in planes if q is not small and q is not big]
            if _holds_face(small.points[d > dist_m], len(d), dist_m, others):
                continue
            # the strip's flying pixels (behind the silhouette) stay out of the refit
            near = d <= dist_m
            pts = np.concatenate([big.points, np.compress(near, small.points, axis=0)])
            plane = refine(pts.astype(np.float64))
            rms = float(np.sqrt(np.mean(plane.distance(pts) ** 2)))
            planes[b] = DepthPlane(plane, big.mask | small.mask, pts, rms)
            planes = [q for q in planes if q is not small]
            break
    return planes


def merge_coplanar(planes: list[DepthPlane], max_deg: float = 8.0, sensor: SensorNoise = SENSOR
                   ) -> list[DepthPlane]:
    """``planes`` of one solid with every pair that is one plane merged and refitted: normals within ``max_deg``
    and the smaller one's points (median) within the inlier distance (``sensor``) of the larger one's plane. A
    solid has no two faces in one plane; one face seen in two parts (around an occluder, or split by a sample of
    RANSAC) is one face.
    ``max_deg``: twice the normal error of a plane fitted to a few hundred noisy points, well below any
    polyhedron's edge (the hexagonal prism's sides turn by 60 deg)."""
    planes = sorted(planes, key=lambda p: -len(p.points))
    cos_max = np.cos(np.radians(max_deg))
    merged = True
    while merged:
        merged = False
        for i in range(len(planes)):
            for j in range(i + 1, len(planes)):
                a, b = planes[i], planes[j]
                if abs(float(a.plane.n @ b.plane.n)) < cos_max:
                    continue
                dist_m = sensor.inlier_m(float(np.median(np.concatenate([a.points[:, 2], b.points[:, 2]]))))
                if np.median(np.abs(a.plane.distance(b.points))) > dist_m:
                    continue  # the smaller piece off the larger's plane (the better measured of the two)
                pts = np.concatenate([a.points, b.points])
                plane = refine(pts.astype(np.float64))
                rms = float(np.sqrt(np.mean(plane.distance(pts) ** 2)))
                planes[i] = DepthPlane(plane, a.mask | b.mask, pts, rms)
                del planes[j]
                merged = True
                break
            if merged:
                break
    return planes


def _holds_face(far: np.ndarray, n: int, dist_m: float, others: list[Plane], min_share: float = 0.25,
                min_far: int = 20, max_rms: float = 0.05) -> bool:
    """True when the points ``far`` (m, 3) metres of a piece of ``n`` points, those more than ``dist_m`` off the
    plane it would join, are a face seen nearly edge-on: at least ``min_share`` of the piece and ``min_far``
    points, within ``max_rms`` inlier distances (RMS) of their own least-squares plane, and not on any plane of
    ``others`` (median distance over ``dist_m``: not a strip of another face found already).

    Why: a thin triangle seen edge-on (2.5-3 px wide) is too narrow for a plane of its own; depth peels it off
    together with the silhouette strip of its neighbour, and most of that piece lies on the neighbour's plane.
    On clean depth its off-plane points fit a plane almost exactly, a silhouette strip's flying pixels to a tenth
    of an inlier distance or more; so under noise both are merged."""
    if len(far) < max(min_far, min_share * n):
        return False
    p = refine(far.astype(np.float64))
    if float(np.sqrt(np.mean(p.distance(far) ** 2))) > max_rms * dist_m:
        return False
    return not any(np.median(np.abs(q.distance(far))) <= dist_m for q in others)


def plane_adjacency(planes: list[DepthPlane], min_contact: int = 4,
                    min_angle_deg: float = 15.0) -> list[tuple[int, int]]:
    """Pairs (i, j), i < j, of planes whose masks touch along at least ``min_contact`` grid cells and whose
    normals differ by at least ``min_angle_deg`` (two parallel touching pieces are one face, not an edge)."""
    out = []
    if len(planes) < 2:
        return out
    # on the planes' bounding box grown by the dilation's reach: dilating whole grids costs more than the rest
    rows = np.flatnonzero(np.any([p.mask.any(axis=1) for p in planes], axis=0))
    cols = np.flatnonzero(np.any([p.mask.any(axis=0) for p in planes], axis=0))
    h, w = planes[0].mask.shape
    i0, i1, j0, j1 = max(0, rows[0] - 2), min(h, rows[-1] + 3), max(0, cols[0] - 2), min(w, cols[-1] + 3)
    masks = [np.ascontiguousarray(p.mask[i0:i1, j0:j1]) for p in planes]
    grown = [cv2.dilate(m.view(np.uint8), np.ones((3, 3), np.uint8), iterations=2).view(bool) for m in masks]
    for i in range(len(planes)):
        for j in range(i + 1, len(planes)):
            contact = np.count_nonzero(grown[i] & masks[j])
            ang = np.degrees(np.arccos(np.clip(abs(planes[i].plane.n @ planes[j].plane.n), -1, 1)))
            if contact >= min_contact and ang >= min_angle_deg:
                out.append((i, j))
    return out
