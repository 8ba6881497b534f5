"""The depth image as an organised point grid: back-projection on a strided pixel grid, per-point normals from
neighbouring points, removal of isolated (flying) points, and a measure of how noisy the depth is.

A grid is (h, w, 3) camera-frame metres for pixels (u, v) = (stride * j, stride * i); invalid points are zero
with ``valid`` False. Perception works on the full-resolution grid (stride 1): a strided grid is cheaper, but
loses the faces a few pixels wide that a solid seen edge-on shows.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ...camera import Intrinsics


@dataclass(frozen=True)
class PointGrid:
    """``xyz``: (h, w, 3) float32 metres; ``normals``: (h, w, 3) unit, towards the camera (zero where unknown);
    ``valid``: (h, w) bool; ``stride``: pixel step of the grid; grid cell (i, j) is pixel (stride*j, stride*i)."""

    xyz: np.ndarray
    normals: np.ndarray
    valid: np.ndarray
    stride: int

    @property
    def shape(self) -> tuple[int, int]:
        return self.valid.shape

    def pixels(self, ij: np.ndarray) -> np.ndarray:
        """Grid cells (m, 2) as (i, j) -> pixels (m, 2) as (u, v)."""
        return np.stack([ij[:, 1] * self.stride, ij[:, 0] * self.stride], axis=1).astype(np.float64)


def back_project(depth: np.ndarray, k: Intrinsics, stride: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Depth (H, W) metres -> points (h, w, 3) float32 and valid (h, w) on the strided grid."""
    z = np.ascontiguousarray(depth[::stride, ::stride]).astype(np.float32)
    h, w = z.shape
    u = (np.arange(w, dtype=np.float32) * stride - k.cx) / k.fx
    v = (np.arange(h, dtype=np.float32) * stride - k.cy) / k.fy
    xyz = np.empty((h, w, 3), np.float32)
    xyz[..., 0] = u[None, :] * z
    xyz[..., 1] = v[:, None] * z
    xyz[..., 2] = z
    return xyz, np.isfinite(z) & (z > 0)


def slope_noise(depth: np.ndarray, k: Intrinsics, row_step: int = 4) -> float:
    """How noisy the depth image (H, W) metres is, in units of the pixel footprint: the robust standard deviation
    of depth noise divided by the width z / f that one pixel spans at that depth (so also the noise of depth
    differences between neighbouring pixels, as a slope). It is read off second differences along every
    ``row_step``-th row, z[u-1] - 2 z[u] + z[u+1], which vanish on a plane seen at a small angle and are
    sqrt(6) sigma wide from noise: their median absolute value, scaled by f / z pixel by pixel and by
    1 / (0.6745 sqrt 6), is sigma's. Jumps over a tenth of the depth (edges, flying pixels) are left out.
    0 when no three neighbouring pixels are read."""
    z = np.ascontiguousarray(depth[::row_step]).astype(np.float32)
    a, b, c = z[:, :-2], z[:, 1:-1], z[:, 2:]
    d2 = np.abs(a - 2 * b + c)
    ok = (a > 0) & (b > 0) & (c > 0) & (d2 < 0.1 * b)
    if not ok.any():
        return 0.0
    return float(np.median(d2[ok] / b[ok])) * k.fx / (0.6745 * np.sqrt(6.0))


def remove_flying(xyz: np.ndarray, valid: np.ndarray, rel_jump: float = 0.03, min_neighbours: int = 4) -> np.ndarray:
    """Valid mask without isolated points: a point needs ``min_neighbours`` of its 8 grid neighbours within
    ``rel_jump`` * depth of it (flying pixels between a foreground edge and the background have none)."""
    z = np.where(valid, xyz[..., 2], 0).astype(np.float32)
    zp = np.pad(z, 1)
    h, w = z.shape
    tol = rel_jump * z
    count = np.zeros(z.shape, np.uint8)
    # buffers reused for the 8 neighbours: at full resolution the temporaries cost more than the arithmetic
    diff, near, read = np.empty_like(z), np.empty(z.shape, bool), np.empty(z.shape, bool)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di == 0 and dj == 0:
                continue
            nb = zp[1 + di:1 + di + h, 1 + dj:1 + dj + w]
            np.abs(np.subtract(nb, z, out=diff), out=diff)
            np.less_equal(diff, tol, out=near)
            near &= np.greater(nb, 0, out=read)
            count += near.view(np.uint8)
    return valid & (count >= min_neighbours)


def grid_normals(xyz: np.ndarray, valid: np.ndarray, smooth: int = 5) -> np.ndarray:
    """Unit normals (h, w, 3) from the cross product of the smoothed grid's horizontal and vertical
    differences, oriented towards the camera; zero where a neighbour is missing."""
    m = valid.astype(np.float32)
    ksize = (smooth, smooth)
    wsum = cv2.boxFilter(m, -1, ksize, normalize=False)
    sm = cv2.boxFilter(xyz * m[..., None], -1, ksize, normalize=False) / np.maximum(wsum, 1e-6)[..., None]
    du = np.zeros_like(sm)
    dv = np.zeros_like(sm)
    du[:, 1:-1] = sm[:, 2:] - sm[:, :-2]
    dv[1:-1, :] = sm[2:, :] - sm[:-2, :]
    n = np.empty_like(sm)  # du x dv, written out: np.cross is slow on images
    n[..., 0] = du[..., 1] * dv[..., 2] - du[..., 2] * dv[..., 1]
    n[..., 1] = du[..., 2] * dv[..., 0] - du[..., 0] * dv[..., 2]
    n[..., 2] = du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0]
    # sums over the last axis written out, added left to right as numpy's reduce adds them (the same numbers), at
    # a ninth of the cost of a reduction over an axis three long
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    n /= np.maximum(np.sqrt(x * x + y * y + z * z), 1e-12)[..., None]
    flip = x * xyz[..., 0] + y * xyz[..., 1] + z * xyz[..., 2] > 0  # towards the camera: n . X < 0
    np.negative(n, out=n, where=flip[..., None])
    ok = valid & (wsum >= 0.6 * smooth * smooth)
    ok[:, :1] = ok[:, -1:] = False
    ok[:1, :] = ok[-1:, :] = False
    np.copyto(n, 0, where=~ok[..., None])
    return n.astype(np.float32, copy=False)


def cell_rows(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``values[mask]`` for a grid of vectors ``values`` (h, w, c) and a grid ``mask`` (h, w) bool: the rows of the
    selected cells in row-major order, the same array, gathered by np.compress (boolean indexing of a 3-D array by a
    2-D mask costs several times as much)."""
    return np.compress(mask.ravel(), values.reshape(-1, values.shape[-1]), axis=0)


def known(normals: np.ndarray) -> np.ndarray:
    """Where a grid of normals (h, w, 3) holds one (zero where none is known): ``np.linalg.norm(normals, axis=2) >
    0``, the same cells (the squares added as its reduce adds them) at a ninth of the cost."""
    x, y, z = normals[..., 0], normals[..., 1], normals[..., 2]
    return x * x + y * y + z * z > 0


def point_grid(depth: np.ndarray, k: Intrinsics, stride: int = 2, normals: bool = True) -> PointGrid:
    """Back-project and drop flying points; estimate normals unless ``normals`` is False (then they are zero,
    and :func:`crop_normals` gives them where they are needed)."""
    xyz, valid = back_project(depth, k, stride)
    valid = remove_flying(xyz, valid)
    np.copyto(xyz, 0, where=~valid[..., None])  # boolean indexing of (h, w, 3) costs ten times as much
    nrm = grid_normals(xyz, valid) if normals else np.zeros_like(xyz)
    return PointGrid(xyz, nrm, valid, stride)


def crop_normals(grid: PointGrid, i0: int, j0: int, i1: int, j1: int, margin: int = 3,
                 within: np.ndarray | None = None) -> np.ndarray:
    """Normals (i1 - i0, j1 - j0, 3) of grid rows i0:i1 and columns j0:j1, computed on the crop plus a margin
    (objects are small: normals of the whole grid would cost more than everything else). With ``within`` (h, w)
    bool (an object's cells), from those cells' points alone wherever enough of them surround a cell, and from
    all points elsewhere (a corner or sliver of the object with too few cells of its own)."""
    h, w = grid.shape
    a0, b0, a1, b1 = max(0, i0 - margin), max(0, j0 - margin), min(h, i1 + margin), min(w, j1 + margin)
    xyz, valid = np.ascontiguousarray(grid.xyz[a0:a1, b0:b1]), grid.valid[a0:a1, b0:b1]
    n = grid_normals(xyz, valid)
    if within is not None:
        own = grid_normals(xyz, valid & within[a0:a1, b0:b1])
        n = np.where(own.any(axis=2, keepdims=True), own, n)
    return n[i0 - a0:i1 - a0, j0 - b0:j1 - b0]
