"""Objects on the support plane: the points above it, split into connected pieces of the image grid where
neither the mask nor the depth breaks."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from ...plane import Plane
from .cloud import PointGrid, cell_rows
from .support import SENSOR, SensorNoise


@dataclass(frozen=True)
class DepthObject:
    """One object: ``mask`` (h, w) bool on the point grid; ``height_m``: its highest point above the support."""

    mask: np.ndarray
    height_m: float

    @property
    def size(self) -> int:
        return int(np.count_nonzero(self.mask))


def object_scale(points: np.ndarray) -> tuple[float, float]:
    """(median depth, extent) of an object's points (m, 3) metres: its extent is the length of the diagonal from
    the 5th to the 95th percentile of each coordinate, a size a few flying points do not stretch. The depth stage
    computes it once per object; the searches for curved faces and for unread faces scale with it."""
    extent = float(np.linalg.norm(np.percentile(points, 95, axis=0) - np.percentile(points, 5, axis=0)))
    return float(np.median(points[:, 2])), extent


def border_contact(mask: np.ndarray) -> float:
    """Length of the mask's outline on the grid border over its whole outline length (grid cells)."""
    edge = np.count_nonzero(mask[0]) + np.count_nonzero(mask[-1]) + np.count_nonzero(mask[:, 0]) + \
        np.count_nonzero(mask[:, -1])
    inner = mask & ~cv2.erode(mask.astype(np.uint8), np.ones((3, 3), np.uint8), borderType=cv2.BORDER_REPLICATE
                              ).astype(bool)
    return edge / max(1, np.count_nonzero(inner))


# a cut between objects: a depth jump over this share of the depth, at this many sigmas of the depth noise
_REL_JUMP = 0.02
_JUMP_SIGMAS = 3.0


def heavy_noise(noise_rel: float, rel_jump: float = _REL_JUMP, jump_sigmas: float = _JUMP_SIGMAS) -> bool:
    """True when depth noise alone (``noise_rel``: sigma as a fraction of depth) makes neighbouring readings differ by
    over ``rel_jump`` of the depth at ``jump_sigmas`` standard deviations (of a difference of two readings)."""
    return jump_sigmas * np.sqrt(2.0) * noise_rel > rel_jump


def segment_objects(grid: PointGrid, support: Plane | None, min_points: int = 60, min_height_m: float = 0.015,
                    rel_jump: float = _REL_JUMP, max_border: float = 0.12,
                    band_m: float | None = None, regrow: int = 5, noise_rel: float = 0.0,
                    jump_sigmas: float = _JUMP_SIGMAS, seed_bands: float = 3.0, sensor: SensorNoise = SENSOR
                    ) -> list[DepthObject]:
    """Objects above ``support`` on the grid, largest first. Points within the noise band of the support plane
    or below it are removed; the rest splits at depth jumps larger than ``rel_jump`` * depth; pieces with fewer
    than ``min_points`` grid points, lower than ``min_height_m``, or cut by the image border along more than
    ``max_border`` of their outline (walls, furniture, the floor beyond a table: scenery, not objects) are
    dropped. ``band_m``: the noise band (metres) above the support that counts as support; by default 1.5 times
    the inlier distance of ``sensor`` at the scene's median depth (see :func:`support_band`). Each piece then takes
    back the foreground cells left out of every piece (depth jumps, the opening) within ``regrow`` cells of it.
    Without a support plane every valid point counts as foreground.

    ``noise_rel``: the frame's depth noise sigma as a fraction of depth (:func:`~lv3d.perception.cloud.slope_noise`
    over the focal length). Where noise alone makes jumps over ``rel_jump`` (``jump_sigmas`` standard deviations
    of the difference of two readings), jumps are measured on a 3x3 median of the depth instead, which keeps
    steps and has 0.41 of the noise, against the larger of ``rel_jump`` and ``jump_sigmas`` of that (0.45 taken,
    on the safe side). Why: under heavy noise (sigma = 0.008 z^2) noise alone cuts the full grid into pieces and
    objects fall apart; at the noise of consumer sensors nothing changes."""
    valid = grid.valid
    if support is not None:
        h_above = np.where(valid, grid.xyz @ support.n.astype(np.float32) + np.float32(support.offset), 0)
        # the depths gathered by np.compress: the same values as indexing the grid's strided depth by the mask
        z_med = float(np.median(np.compress(valid.ravel(), grid.xyz[..., 2].ravel()))) if valid.any() else 1.0
        band = 1.5 * sensor.inlier_m(z_med) if band_m is None else band_m
        fg = valid & (h_above > band)
    else:
        h_above = np.where(valid, 1.0, 0)
        fg = valid.copy()
    z = grid.xyz[..., 2]
    if heavy_noise(noise_rel, rel_jump, jump_sigmas):
        z = cv2.medianBlur(np.ascontiguousarray(z), 3)
        rel_jump = max(rel_jump, jump_sigmas * np.sqrt(2.0) * 0.45 * noise_rel)
    # cut the grid where depth jumps between neighbours: touching-in-the-image objects at different depths
    jump = np.zeros_like(fg)
    dz_u = np.abs(np.diff(z, axis=1)) > rel_jump * z[:, 1:]
    dz_v = np.abs(np.diff(z, axis=0)) > rel_jump * z[1:, :]
    jump[:, 1:] |= dz_u
    jump[1:, :] |= dz_v
    fg_cut = fg & ~jump
    fg_cut = cv2.morphologyEx(fg_cut.astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8)).astype(bool)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(fg_cut.astype(np.uint8), connectivity=4)
    if support is not None:
        n, labels, stats = _split_by_height(labels, n, stats, h_above, band, min_points, seed_bands)
    # foreground cells outside every piece: the cuts themselves, and what the opening removed. A face seen
    # nearly edge-on is all depth jumps between neighbouring cells, and a few cells wide: without these cells
    # it is lost whole
    free = fg & (labels == 0)
    out = []
    for lab in range(1, n):
        if stats[lab, cv2.CC_STAT_AREA] < min_points:
            continue
        m = labels == lab
        if border_contact(m) > max_border:
            continue
        height = float(np.percentile(h_above[m], 95)) if support is not None else np.inf
        if height < min_height_m:
            continue
        # give back the free cells within ``regrow`` cells of this piece, through free cells only (worked on
        # the piece's bounding box grown by ``regrow``: dilating the whole grid per piece costs more)
        x, y, bw, bh = stats[lab, :4]
        i0, j0 = max(0, y - regrow), max(0, x - regrow)
        i1, j1 = min(m.shape[0], y + bh + regrow), min(m.shape[1], x + bw + regrow)
        grown = m[i0:i1, j0:j1].copy()
        room = free[i0:i1, j0:j1]
        for _ in range(regrow):
            ring = cv2.dilate(grown.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool) & room & ~grown
            if not ring.any():
                break
            grown |= ring
        room &= ~grown  # a view into ``free``: these cells are taken
        m = m.copy()
        m[i0:i1, j0:j1] |= grown
        out.append(DepthObject(m, height))
    out = _fill_holes(out, valid)
    out.sort(key=lambda o: (-o.size, int(np.argmax(o.mask))))
    return out


def _split_by_height(labels: np.ndarray, n: int, stats: np.ndarray, h_above: np.ndarray, band_m: float,
                     min_points: int,
                     seed_bands: float = 3.0) -> tuple[int, np.ndarray, np.ndarray]:
    """Pieces of the foreground (``labels`` 1..n-1, 0 = none) parted where they dip towards the support between
    parts that stand higher: a marker-controlled watershed on the height above the support (``h_above``, metres).

    Seeds are the connected parts higher than ``seed_bands`` support bands (``band_m``) with ``min_points`` cells
    or more; each piece's cells go to the seed reached along the path that stays highest. A piece with fewer
    than two seeds is kept whole. Why: a sensor that smooths its depth (RealSense's spatial filter) joins
    neighbouring objects by ramps of interpolated readings near the table, with no depth jump to cut.
    Returns (n, labels, stats) as cv2.connectedComponentsWithStats gives them."""
    fg = labels > 0
    high = (fg & (h_above > seed_bands * band_m)).astype(np.uint8)
    k, seeds, st, _ = cv2.connectedComponentsWithStats(high, connectivity=4)
    big = np.flatnonzero(st[:, cv2.CC_STAT_AREA] >= min_points)
    big = big[big > 0]
    if len(big) < 2:
        return n, labels, stats
    piece_of_seed = {int(s): int(np.bincount(labels[seeds == s]).argmax()) for s in big}
    counts = np.bincount(list(piece_of_seed.values()), minlength=n)
    if counts.max() < 2:
        return n, labels, stats
    markers = np.zeros(labels.shape, np.int16)
    for j, s in enumerate(big, start=1):
        if counts[piece_of_seed[int(s)]] >= 2:
            markers[seeds == s] = j
    top = max(float(h_above[fg].max()), 1e-6)
    cost = np.where(fg, np.clip((top - h_above) / top, 0, 1) * 65534, 65535).astype(np.uint16)
    flooded = ndimage.watershed_ift(cost, markers)
    out = labels.copy()
    split = np.isin(labels, np.flatnonzero(counts >= 2)) & fg
    out[split] = n + flooded[split] - 1
    ids = np.unique(out[out > 0])
    lut = np.zeros(int(out.max()) + 1, np.int32)
    lut[ids] = np.arange(1, len(ids) + 1)
    out = lut[out]
    return len(ids) + 1, out, _stats(out, len(ids) + 1)


def _stats(labels: np.ndarray, n: int) -> np.ndarray:
    """cv2-style stats (n, 5) of labels 0..n-1: left, top, width, height, area."""
    st = np.zeros((n, 5), np.int64)
    for lab, sl in enumerate(ndimage.find_objects(labels, max_label=n - 1) if n > 1 else [], start=1):
        if sl is None:
            continue
        st[lab] = (sl[1].start, sl[0].start, sl[1].stop - sl[1].start, sl[0].stop - sl[0].start, 0)
    st[:, 4] = np.bincount(labels.ravel(), minlength=n)[:n]
    return st


def _fill_holes(objects: list[DepthObject], valid: np.ndarray) -> list[DepthObject]:
    """Each object with the read cells it encloses and no other object holds: the inside of a bowl or a mug lies
    within the support's noise band (its bottom is a few millimetres above the table) and was cut out with the
    support, leaving a ring."""
    if not objects:
        return objects
    taken = np.zeros(valid.shape, bool)
    for o in objects:
        taken |= o.mask
    out = []
    for o in objects:
        rows, cols = np.flatnonzero(o.mask.any(axis=1)), np.flatnonzero(o.mask.any(axis=0))
        i0, i1, j0, j1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
        inside = ndimage.binary_fill_holes(o.mask[i0:i1, j0:j1]) & valid[i0:i1, j0:j1] & ~taken[i0:i1, j0:j1]
        if inside.any():
            m = o.mask.copy()
            m[i0:i1, j0:j1] |= inside
            o = DepthObject(m, o.height_m)
        out.append(o)
    return out


def support_band(grid: PointGrid, support: Plane, min_band_m: float = 0.004, k: float = 4.0,
                 sensor: SensorNoise = SENSOR) -> float:
    """The height (metres) above ``support`` within which points are the support itself: ``k`` times the noise (a
    robust standard deviation of the distances to the plane of the grid points near it), between ``min_band_m``
    and the default band, 1.5 times the inlier distance of ``sensor`` at the points' median depth. A fixed band
    sized for the noisiest sensors cuts the bottom few centimetres off every object of a cleaner depth image; the
    pixels lost there are the lower parts of the side faces, often all of a small face."""
    valid = grid.valid[::4, ::4]  # a few thousand points measure the noise well enough
    pts = cell_rows(grid.xyz[::4, ::4], valid)
    if len(pts) < 50:
        return 1.5 * sensor.inlier_m(1.0)
    z_med = float(np.median(pts[:, 2]))
    wide = 1.5 * sensor.inlier_m(z_med)
    d = np.abs(pts @ support.n.astype(np.float32) + np.float32(support.offset))
    near = d[d <= sensor.inlier_m(z_med)]
    if len(near) < 50:
        return wide
    sigma = 1.4826 * float(np.median(near))  # robust: the near set also holds the feet of objects and walls
    return float(np.clip(k * sigma, min_band_m, wide))
