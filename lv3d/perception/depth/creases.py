"""Objects cut at concave creases of the surface itself, where no planes describe it: touching curved objects
(mugs side by side, a can against a bottle) meet along a valley of the depth surface, and their planes are too
few or none (a curved surface is no plane), so the cut between planes (convexity.split_at_concave) cannot see it.

1. Creases: a cell is on a crease where the surface bends inwards (concave, as LCCP tests a junction: with n_a,
   n_b the normals and p_a, p_b the points of the cells ``baseline`` cells before and after it along a row or a
   column, (n_a - n_b) . (p_a - p_b) < 0) by more than ``crease_deg`` between them.
2. Pieces: the distance of every object cell to the nearest crease or outline cell is high inside a solid and
   low at the necks and creases between solids; each regional maximum standing ``dynamics_frac`` of the grid's
   diagonal above its surroundings seeds a piece, and a watershed on that distance grows the seeds over the
   object (the classic cut of touching blobs, here with the creases as part of the outline).
3. Cuts kept: two pieces stay apart only where at least ``crease_share`` of the cells along their common border
   lie on a crease (a border across a smooth or convex surface is a neck of one solid, and the two join again),
   where the two pieces' cells near it bend inwards by ``bend_deg`` or more (LCCP's test of a junction, on
   the pieces' own normals: a border the watershed ran along scattered crease cells of one flat face fails it),
   and where that border is at most ``inset_share`` of each piece's outline (a piece almost ringed by another is
   set into it: a can's lid inside its rim). A piece smaller than the least object joins the neighbour it
   shares the longest border with. A surface whose creases are everywhere (sensor noise on a far wall) is not
   cut.

Why the watershed rather than connected pieces between creases: on real depth a crease is broken in places
(noise, a dark pixel, a handle), and one gap would join two solids; seeds far apart compete for the cells
between them whatever the gaps.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage
from skimage.segmentation import watershed

from ...plane import column_means, column_sums
from ..distance import euclidean_distance
from .cloud import PointGrid, known
from .ranges import check_ranges


@dataclass(frozen=True)
class CreaseSettings:
    """The cut at concave creases of the depth surface (scale-free: angles, fractions of the grid's diagonal in
    cells, shares of a border).

    ``crease_deg`` (degrees): the least inward bend between the normals ``baseline`` cells either side of a cell
    that makes it a crease. Where two solids touch the bend is near 90 deg or more (each surface turns away from
    the other); a bowl's or a mug's inside bends by under 10 deg over that baseline.
    ``baseline_frac``: half the span over which the bend is measured, as a fraction of the grid's diagonal (3
    cells at 640x480): long enough that sensor noise in the normals is well under ``crease_deg``, short enough
    to stay within one face of a small object.
    ``dynamics_frac``: how far (fraction of the grid's diagonal, in cells of distance) a maximum of the distance
    to creases and outline must stand above the saddle to the next one to seed a piece of its own (h-maxima):
    a solid's body, not a bump of its outline.
    ``crease_share``: the least share of the cells along two pieces' common border that lie on a crease
    (dilated by one cell) for the cut between them to stand.
    ``inset_share``: a cut along more than this share of either piece's outline joins again: that piece is set
    into the other (a can's recessed lid inside its rim, a mug's inside, a bowl's bottom), not a solid beside it.
    Solids side by side or stacked share a part of each outline; the rest of it is their silhouettes.
    ``bend_deg`` (degrees): the least inward bend between the mean normals of two pieces' cells along their
    border (within twice ``baseline`` of it) for the cut to stand, as LCCP tests a junction. Half ``crease_deg``:
    along a curved border (one solid standing in or on another) the normals of each side turn with it and their
    mean bends by less than any single crease cell; the pieces of one flat face a watershed ran between
    scattered noise creases bend by a few degrees.
    ``max_crease_frac``: an object with more of its cells on creases than this share is not cut at all. Creases
    between solids are lines, a small share of their cells (at most 0.11 of the cluttered RealSense objects of
    the real dev frames); where the sensor's noise alone bends the normals by ``crease_deg`` they cover the
    surface (0.16-0.23 of a far wall in rendered RealSense frames), and every cut there is noise.
    """

    crease_deg: float = 45.0
    baseline_frac: float = 0.004
    dynamics_frac: float = 0.004
    crease_share: float = 0.5
    inset_share: float = 0.5
    max_crease_frac: float = 0.15
    bend_deg: float = 22.5

    def __post_init__(self) -> None:
        check_ranges(self, angles=("crease_deg", "bend_deg"),
                     fractions=("baseline_frac", "dynamics_frac", "crease_share", "inset_share", "max_crease_frac"))


DEFAULT = CreaseSettings()


def crease_cells(xyz: np.ndarray, normals: np.ndarray, mask: np.ndarray, baseline: int, crease_deg: float
                 ) -> np.ndarray:
    """(h, w) bool: the cells of ``mask`` on a concave crease (module docstring, step 1); ``xyz`` and ``normals``
    (h, w, 3) on the same crop, normals zero where unknown."""
    b = max(1, int(baseline))
    ok = mask & known(normals)
    out = np.zeros(mask.shape, bool)
    cos_max = np.cos(np.radians(crease_deg))
    for axis in (0, 1):
        if mask.shape[axis] <= 2 * b:
            continue
        before, after, mid = [slice(None)] * 2, [slice(None)] * 2, [slice(None)] * 2
        before[axis], after[axis], mid[axis] = slice(0, -2 * b), slice(2 * b, None), slice(b, -b)
        na, nb = normals[tuple(before)], normals[tuple(after)]
        pa, pb = xyz[tuple(before)], xyz[tuple(after)]
        concave = np.einsum("ijk,ijk->ij", na - nb, pa - pb) < 0
        sharp = np.einsum("ijk,ijk->ij", na, nb) < cos_max
        out[tuple(mid)] |= ok[tuple(before)] & ok[tuple(after)] & concave & sharp
    return out & mask


def split_at_creases(grid: PointGrid, obj_mask: np.ndarray, normals: np.ndarray, min_cells: int,
                     settings: CreaseSettings = DEFAULT) -> list[np.ndarray]:
    """The object's cells ``obj_mask`` (h, w) bool on ``grid`` cut at concave creases into solids of at least
    ``min_cells`` cells (module docstring); ``normals``: the object's normals on its bounding box of the grid
    (cloud.crop_normals with ``within``). One mask, the object's own, when nothing cuts it."""
    rows, cols = np.flatnonzero(obj_mask.any(axis=1)), np.flatnonzero(obj_mask.any(axis=0))
    if len(rows) == 0 or np.count_nonzero(obj_mask) < 2 * min_cells:
        return [obj_mask]
    i0, i1, j0, j1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    m = obj_mask[i0:i1, j0:j1]
    diag = float(np.hypot(*grid.shape))
    baseline = max(1, round(settings.baseline_frac * diag))
    xyz, nrm = grid.xyz[i0:i1, j0:j1].astype(np.float64), normals.astype(np.float64)
    crease = crease_cells(xyz, nrm, m, baseline, settings.crease_deg)
    if not crease.any() or np.count_nonzero(crease) > settings.max_crease_frac * np.count_nonzero(m):
        return [obj_mask]
    inside = np.pad(m & ~crease, 1).view(np.uint8)
    dist = euclidean_distance(inside)[1:-1, 1:-1]
    seeds = h_maxima(dist, max(1.0, settings.dynamics_frac * diag)) & m
    n_seeds, markers = cv2.connectedComponents(seeds.view(np.uint8), connectivity=8)
    if n_seeds <= 2:
        return [obj_mask]
    pieces = watershed(-dist, markers, mask=m)
    if np.any(m & (pieces == 0)):  # parts of the object no seed reaches: to the nearest piece
        _, (ii, jj) = ndimage.distance_transform_edt(pieces == 0, return_indices=True)
        pieces = np.where(m, pieces[ii, jj], 0)
    near_crease = cv2.dilate(crease.view(np.uint8), np.ones((3, 3), np.uint8)).view(bool)
    labels = _join(pieces, n_seeds, near_crease, min_cells, settings, (xyz, nrm, 2 * baseline))
    out = []
    for lab in np.unique(labels[m]):
        full = np.zeros_like(obj_mask)
        full[i0:i1, j0:j1] = m & (labels == lab)
        out.append(full)
    return out if len(out) > 1 else [obj_mask]


def _borders(labels: np.ndarray, n: int, near_crease: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For labels 0..n-1 of a crop (0 = not the object): (total, on, outline), where total[a, b] (a < b) counts
    the 4-neighbour cell pairs between pieces a and b, on[a, b] those with a cell near a crease, and outline[a]
    the pairs between piece a and anything else (another piece, not the object, or beyond the crop)."""
    padded = np.pad(labels, 1)
    crease = np.pad(near_crease, 1)
    total = np.zeros((n, n))
    on = np.zeros((n, n))
    outline = np.zeros(n)
    for a, b, c in ((padded[:, :-1], padded[:, 1:], crease[:, :-1] | crease[:, 1:]),
                    (padded[:-1, :], padded[1:, :], crease[:-1, :] | crease[1:, :])):
        diff = a != b
        outline += np.bincount(a[diff], minlength=n)[:n] + np.bincount(b[diff], minlength=n)[:n]
        both = diff & (a > 0) & (b > 0)
        lo, hi = np.minimum(a[both], b[both]), np.maximum(a[both], b[both])
        np.add.at(total, (lo, hi), 1)
        np.add.at(on, (lo, hi), c[both])
    return total, on, outline


def _bends(labels: np.ndarray, a: int, b: int, xyz: np.ndarray, normals: np.ndarray, band: int,
           bend_deg: float) -> bool:
    """Whether pieces ``a`` and ``b`` of ``labels`` meet at a concave crease, as LCCP tests a junction: the mean
    normals n_a, n_b and centroids c_a, c_b of each piece's cells within ``band`` cells of the other bend
    inwards, (n_a - n_b) . (c_a - c_b) < 0, by ``bend_deg`` or more."""
    sides = []
    rows, cols = np.nonzero((labels == a) | (labels == b))
    i0, i1 = max(0, rows.min() - 1), rows.max() + 2
    j0, j1 = max(0, cols.min() - 1), cols.max() + 2
    lab, nrm, pts = labels[i0:i1, j0:j1], normals[i0:i1, j0:j1], xyz[i0:i1, j0:j1]
    for this, other in ((a, b), (b, a)):
        far = cv2.distanceTransform((lab != other).astype(np.uint8), cv2.DIST_L2, 3)
        near = (lab == this) & (far <= band) & known(nrm)
        if not near.any():
            return False
        n = column_sums(nrm[near])
        norm = np.linalg.norm(n)
        if norm == 0:
            return False
        sides.append((n / norm, column_means(pts[near])))
    (na, ca), (nb, cb) = sides
    return float((na - nb) @ (ca - cb)) < 0 and float(na @ nb) < np.cos(np.radians(bend_deg))


def _join(pieces: np.ndarray, n: int, near_crease: np.ndarray, min_cells: int, settings: CreaseSettings,
          surface: tuple[np.ndarray, np.ndarray, int]) -> np.ndarray:
    """Labels (h, w) of ``pieces`` (1..n-1, 0 = not the object) after the cuts that do not stand are undone
    (module docstring, step 3); ``surface``: the crop's points and normals (h, w, 3) and the band (cells) either
    side of a border whose cells say how the pieces meet there."""
    labels = pieces
    xyz, normals, band = surface
    for step in ("smooth", "bend", "inset", "small"):
        while True:
            ids = np.unique(labels[labels > 0])
            if len(ids) < 2:
                return labels
            lut = np.zeros(int(labels.max()) + 1, np.int64)
            lut[ids] = np.arange(1, len(ids) + 1)
            labels = lut[labels]
            k = len(ids) + 1
            total, on, outline = _borders(labels, k, near_crease)
            size = np.bincount(labels.ravel(), minlength=k)
            pairs = np.argwhere(total > 0)
            if step == "smooth":
                weak = [(a, b) for a, b in pairs if on[a, b] < settings.crease_share * total[a, b]]
            elif step == "bend":  # every pair judged once, on the pieces as the smooth step left them
                flat = [(a, b) for a, b in pairs if not _bends(labels, a, b, xyz, normals, band, settings.bend_deg)]
                root = list(range(k))

                def find(x: int) -> int:
                    while root[x] != x:
                        root[x] = root[root[x]]
                        x = root[x]
                    return x

                for a, b in flat:
                    root[find(a)] = find(b)
                labels = np.array([find(x) for x in range(k)])[labels]
                break
            elif step == "inset":
                weak = [(a, b) for a, b in pairs
                        if total[a, b] > settings.inset_share * min(outline[a], outline[b])]
            else:
                small = [a for a in range(1, k) if size[a] < min_cells and total[a].sum() + total[:, a].sum() > 0]
                if not small:
                    break
                a = min(small, key=lambda x: size[x])
                shared = total[a] + total[:, a]
                weak = [(a, int(np.argmax(shared)))]
            if not weak:
                break
            a, b = max(weak, key=lambda ab: total[ab[0], ab[1]])  # the longest weak border first
            labels = np.where(labels == b, a, labels)
    return labels


_SQUARE = np.ones((3, 3), np.uint8)


def h_maxima(image: np.ndarray, h: float) -> np.ndarray:
    """The regional maxima of float32 ``image`` that stand ``h`` or more above every path to a higher one (uint8
    0/1, ``image``'s shape; 8-connected): the same cells as ``skimage.morphology.h_maxima(image, h)``, in a
    fraction of its time on an object's distance map. Both reconstruct ``image - h`` (less a few units in the
    last place, which keeps it below ``image - h`` after rounding) by dilation under ``image`` and keep the cells
    the reconstruction leaves ``h`` or more below ``image``; skimage sorts every cell first (Vincent's queue
    algorithm), here the 3x3 dilation is repeated until nothing changes (tens of steps on an object's box).
    Maxima and minima of float32 values are float32 values, so the reconstruction is the same array."""
    image = np.asarray(image, np.float32)
    if image.size == 0 or h > np.ptp(image):
        return np.zeros(image.shape, np.uint8)
    h = np.float32(h)
    shifted = image - h - 2 * np.finfo(np.float32).resolution * np.abs(image)
    rec = shifted
    while True:
        prev = rec
        for _ in range(4):  # a few steps between tests: the test costs as much as a step
            rec = np.minimum(cv2.dilate(rec, _SQUARE), image)
        if np.array_equal(rec, prev):
            break
    return ((image - rec.astype(np.float64)) >= h).astype(np.uint8)
