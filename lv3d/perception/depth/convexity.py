"""Objects cut at concave creases: the local-convexity segmentation of PCL's LCCP (Stein et al. 2014), on an
object's planes.

1. Patches: the object's planes (planes.object_planes) over-segment its surface; a can's side or a bowl comes
   as a fan of planes.
2. Junctions: every pair of touching planes is convex (the surface bends outwards, as at a solid's edge) or
   concave (it bends inwards, as where one solid stands on or leans against another). With n_i, n_j the
   normals (towards the camera) and c_i, c_j the centroids of each plane's cells near the junction, it is convex
   when (n_i - n_j) . (c_i - c_j) > 0.
3. Solids: planes joined across every junction that is not a sharp concave crease; what is left joined only
   across such creases is a solid of its own. Cells on no plane go to the solid of the nearest plane cell.

A solid's own concave surface (the inside of a bowl or a mug) stays joined to the rest through its rim, a convex
junction, as in LCCP; an object with a concave junction too gentle to be a crease between solids is not cut
at all (``ConvexitySettings.concave_tol_deg``).

Why planes rather than region growing on normals: on Kinect depth the normals turn smoothly across a box's
edges (the sensor smooths them), so growing from neighbour to neighbour crosses them; a plane's points give its
normal near a junction with far less noise than any local patch.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from ...plane import column_means, column_sums
from ..distance import euclidean_distance
from .cloud import PointGrid, cell_rows
from .planes import DepthPlane
from .ranges import check_ranges


@dataclass(frozen=True)
class ConvexitySettings:
    """Thresholds of the cut at concave creases (scale-free: angles and fractions of the object's size).

    ``concave_min_deg`` (degrees): the smallest angle between two patches' normals at a concave junction that cuts
    the object there. Solids rest on flat faces, so where one stands on or against another the crease is about
    as sharp as the angle between those faces (near 90 deg for boxes and cans).
    ``concave_tol_deg`` (degrees): a concave junction gentler than ``concave_min_deg`` but sharper than this is a
    concave surface of one solid; such an object is not cut, since its sharper creases may be that surface's
    too. LCCP's own concavity tolerance is of this size (10 deg).
    ``max_gap_rel``: two planes meet at a junction only where the cells of each along it lie within this fraction
    of their depth of the other's plane; across an occluding edge the near surface is a depth step away from the
    far one and the two do not meet (objects are cut at steps of 2 % of the depth: objects.segment_objects).
    ``band_frac``: the width of the strip on each side of a junction whose cells give that side's normal and
    centroid, as a fraction of the object's larger extent on the grid.
    ``contact_frac``: the least length of a junction, as a fraction of the smaller patch's perimeter (four times
    the square root of its cell count): patches that touch at a corner are not neighbours.
    """

    concave_min_deg: float = 55.0
    concave_tol_deg: float = 10.0
    max_gap_rel: float = 0.01
    band_frac: float = 0.08
    contact_frac: float = 0.05

    def __post_init__(self) -> None:
        check_ranges(self, angles=("concave_min_deg", "concave_tol_deg"),
                     fractions=("max_gap_rel", "band_frac", "contact_frac"))


DEFAULT = ConvexitySettings()


def junctions(labels: np.ndarray, xyz: np.ndarray, normals: np.ndarray, offsets: np.ndarray,
              settings: ConvexitySettings = DEFAULT) -> list[tuple[int, int, float]]:
    """Every pair (a, b, bend) of planes that meet (labels a < b; ``normals`` (h, w, 3) the plane normal of each
    cell, ``offsets`` (k,) each plane's offset): ``bend`` (degrees) is the angle between their normals, negative
    where the surface bends inwards across the junction (concave)."""
    k = int(labels.max())
    if k < 2:
        return []
    ij = np.argwhere(labels > 0)
    extent = int((ij.max(axis=0) - ij.min(axis=0)).max()) + 1
    band = max(2, int(round(settings.band_frac * extent)))
    reach: list[np.ndarray | None] = [None] * k  # cells within ``band`` of each patch, made when first needed

    def within(i: int) -> np.ndarray:
        if reach[i] is None:
            # Euclidean distance to the patch: the disc a dilation by an ellipse of radius ``band`` reaches
            dist = euclidean_distance(~masks[i])
            reach[i] = dist <= band
        return reach[i]

    masks = [labels == a for a in range(1, k + 1)]
    sizes = [int(np.count_nonzero(m)) for m in masks]
    touch = [cv2.dilate(m.view(np.uint8), np.ones((3, 3), np.uint8), iterations=2).view(bool) for m in masks]
    # each patch's normal: that of its first cell in row-major order (every cell of a patch holds its plane's)
    first = [normals.reshape(-1, normals.shape[-1])[int(np.argmax(m))] for m in masks]
    out = []
    for a in range(k):
        for b in range(a + 1, k):
            contact = np.count_nonzero(touch[a] & masks[b])
            if contact < max(3, settings.contact_frac * 4 * np.sqrt(min(sizes[a], sizes[b]))):
                continue
            if not _meet(xyz, touch[b] & masks[a], first[b], offsets[b + 1], settings) or \
                    not _meet(xyz, touch[a] & masks[b], first[a], offsets[a + 1], settings):
                continue
            near_b = within(b) & masks[a]
            near_a = within(a) & masks[b]
            na, nb = column_sums(cell_rows(normals, near_b)), column_sums(cell_rows(normals, near_a))
            la, lb = np.linalg.norm(na), np.linalg.norm(nb)
            if la == 0 or lb == 0:
                continue
            na, nb = na / la, nb / lb
            ca, cb = column_means(cell_rows(xyz, near_b)), column_means(cell_rows(xyz, near_a))
            angle = float(np.degrees(np.arccos(np.clip(na @ nb, -1.0, 1.0))))
            convex = float((na - nb) @ (ca - cb)) > 0
            if convex and not _sane(na, nb, ca - cb, angle):
                continue  # not a junction of one surface: a step seen across an occluding edge
            out.append((a + 1, b + 1, angle if convex else -angle))
    return out


def _sane(na: np.ndarray, nb: np.ndarray, d: np.ndarray, angle_deg: float) -> bool:
    """LCCP's sanity criterion for a convex junction: two planes that meet along an edge have their centroids'
    offset ``d`` well across the line where they intersect (n_a x n_b); an offset nearly along that line is a
    step between surfaces one above or behind the other, seen touching in the image. The least angle allowed grows
    with the angle between the normals, as 60 deg / (1 + exp(-0.25 (angle - 25 deg))) (Stein et al. 2014)."""
    s = np.cross(na, nb)
    ls, ld = np.linalg.norm(s), np.linalg.norm(d)
    if ls < 1e-9 or ld < 1e-12:
        return True
    theta = float(np.degrees(np.arccos(min(1.0, abs(float(s @ d)) / (ls * ld)))))  # 0 when along the line
    return theta >= 60.0 / (1.0 + np.exp(-0.25 * (angle_deg - 25.0)))


def _meet(xyz: np.ndarray, along: np.ndarray, n: np.ndarray, d: float, settings: ConvexitySettings) -> bool:
    """True when the cells ``along`` a junction lie (median) within ``max_gap_rel`` of their depth of plane (n, d)."""
    p = cell_rows(xyz, along)
    if len(p) == 0:
        return False
    return bool(np.median(np.abs(p @ n + d) / p[:, 2]) <= settings.max_gap_rel)


def _solids(k: int, bends: list[tuple[int, int, float]], settings: ConvexitySettings) -> list[int]:
    """Solid label of patches 1..k (list index 0 unused), joined across the junctions that are not sharp concave
    creases; a group with no crease to another group joins the largest group (nothing says it is a solid)."""
    parent = list(range(k + 1))

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b, bend in bends:
        if bend > -settings.concave_min_deg:
            parent[find(a)] = find(b)
    label = [find(a) for a in range(k + 1)]
    cut = set()
    for a, b, bend in bends:
        if bend <= -settings.concave_min_deg and label[a] != label[b]:
            cut |= {label[a], label[b]}
    home = label[1] if label[1] in cut else (min(cut) if cut else label[1])
    return [label[a] if label[a] in cut else home for a in range(k + 1)]


def split_at_concave(grid: PointGrid, obj_mask: np.ndarray, planes: list[DepthPlane],
                     settings: ConvexitySettings = DEFAULT) -> list[np.ndarray]:
    """The object's cells ``obj_mask`` (h, w) bool on ``grid`` cut into solids at sharp concave creases between its
    ``planes``; one mask (the object's own) when nothing cuts it."""
    rows, cols = np.flatnonzero(obj_mask.any(axis=1)), np.flatnonzero(obj_mask.any(axis=0))
    if len(rows) == 0:
        return [obj_mask]
    i0, i1, j0, j1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    m = obj_mask[i0:i1, j0:j1]
    p = grid.xyz[i0:i1, j0:j1].astype(np.float64)
    n = np.zeros(p.shape)
    labels = np.zeros(m.shape, np.int32)
    for k, q in enumerate(planes, start=1):
        on = q.mask[i0:i1, j0:j1] & m & (labels == 0)
        labels[on] = k
        n[on] = q.plane.n
    offsets = np.array([0.0] + [q.plane.offset for q in planes])
    bends = junctions(labels, p, n, offsets, settings)
    if not any(b <= -settings.concave_min_deg for _, _, b in bends):
        return [obj_mask]
    if any(-settings.concave_min_deg < b < -settings.concave_tol_deg for _, _, b in bends):
        return [obj_mask]  # a concave surface of one solid (module docstring)
    solid = np.asarray(_solids(int(labels.max()), bends, settings))
    # every object cell takes the solid of its nearest plane cell
    _, (ii, jj) = ndimage.distance_transform_edt(labels == 0, return_indices=True)
    per_cell = solid[labels[ii, jj]]
    out = []
    for s in np.unique(per_cell[m]):
        full = np.zeros_like(obj_mask)
        full[i0:i1, j0:j1] = m & (per_cell == s)
        out.append(full)
    return out if len(out) > 1 else [obj_mask]
