"""The cut at concave creases of the depth surface (perception/depth/creases.py): touching curved solids part
along the valley between them; one convex or gently concave surface, and a piece set into another, stay whole."""

import cv2
import numpy as np

from lv3d.perception.depth.cloud import PointGrid, crop_normals
from lv3d.perception.depth.creases import CreaseSettings, crease_cells, split_at_creases

H, W = 240, 320
CELL = 0.001  # metres across one cell at 1 m
X = (np.arange(W)[None, :] - W / 2) * CELL + np.zeros((H, 1))


def grid_of(z: np.ndarray) -> PointGrid:
    """Cells seen straight on at depths ``z`` (H, W) metres, every cell read."""
    i, j = np.mgrid[0:H, 0:W]
    xyz = np.stack([(j - W / 2) * CELL * z, (i - H / 2) * CELL * z, z], -1).astype(np.float32)
    return PointGrid(xyz, np.zeros_like(xyz), np.ones(z.shape, bool), 1)


def cylinders(centres_m: list[float], radius_m: float = 0.05, z0: float = 1.0):
    """Upright cylinders side by side (axes along the image's rows), each seen from the front; where two overlap
    in the image the nearer surface is seen. Returns the grid and the object mask (every cylinder cell)."""
    z = np.full((H, W), np.inf)
    for c in centres_m:
        inside = np.abs(X - c) < radius_m * 0.98
        zc = z0 - np.sqrt(np.clip(radius_m ** 2 - (X - c) ** 2, 0, None))
        z = np.where(inside & (zc < z), zc, z)
    mask = np.isfinite(z)
    mask[:20], mask[-20:] = False, False
    return grid_of(np.where(mask, z, z0 + 0.2)), mask


def split(grid: PointGrid, mask: np.ndarray, min_cells: int = 60, settings: CreaseSettings = CreaseSettings()):
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    normals = crop_normals(grid, rows[0], cols[0], rows[-1] + 1, cols[-1] + 1, within=mask)
    return split_at_creases(grid, mask, normals, min_cells, settings)


def test_two_touching_cylinders_part_along_their_valley():
    grid, mask = cylinders([-0.045, 0.045])
    pieces = split(grid, mask)
    assert len(pieces) == 2
    assert not np.any(pieces[0] & pieces[1]) and np.array_equal(pieces[0] | pieces[1], mask)
    left = next(p for p in pieces if p[H // 2, W // 2 - 60])
    # the cut lies at the valley (x = 0), within a few cells
    cut = np.flatnonzero(left[H // 2])[-1]
    assert abs(cut - W // 2) <= 4


def test_one_cylinder_stays_whole():
    grid, mask = cylinders([0.0])
    assert len(split(grid, mask)) == 1


def test_a_convex_edge_and_a_gentle_dish_are_not_creases():
    mask = np.zeros((H, W), bool)
    mask[20:-20, 40:-40] = True
    roof = 1.0 + np.abs(X) * 1.0  # two planes meeting at a convex 90 deg edge, as a box's
    assert len(split(grid_of(roof), mask)) == 1
    dish = 1.0 - 0.5 * (X ** 2 + ((np.arange(H)[:, None] - H / 2) * CELL) ** 2)  # a bowl's inside: gently concave
    assert len(split(grid_of(dish), mask)) == 1
    assert not crease_cells(grid_of(dish).xyz.astype(np.float64), crop_normals(grid_of(dish), 0, 0, H, W),
                            mask, 2, 45.0).any()


def test_a_sharp_concave_crease_parts_two_solids_unless_one_is_too_small():
    mask = np.zeros((H, W), bool)
    mask[20:-20, 40:-40] = True
    valley = 1.0 - np.abs(X) * 1.0  # two planes meeting at a concave 90 deg crease: a box against a box
    pieces = split(grid_of(valley), mask)
    assert len(pieces) == 2
    assert min(np.count_nonzero(p) for p in pieces) > 0.4 * np.count_nonzero(mask)
    # the same crease where the smaller side is below the least object: one piece
    off = 1.0 - np.abs(X - 0.09) * 1.0
    assert len(split(grid_of(off), mask, min_cells=int(0.2 * np.count_nonzero(mask)))) == 1


def test_a_piece_set_into_another_joins_it():
    # a flat rim around a recessed square floor, walls at 63 deg: the floor is ringed by the rim and walls
    yy = (np.arange(H)[:, None] - H / 2) * CELL + np.zeros((1, W))
    r = np.maximum(np.abs(X), np.abs(yy))
    z = 1.0 + np.clip(2.0 * (0.06 - r), 0, 0.03)  # floor 3 cm behind the rim
    mask = np.zeros((H, W), bool)
    mask[10:-10, 60:-60] = True
    assert len(split(grid_of(z), mask)) == 1
    # (its border is a ring: the mean normals of the cells along it cancel, so the bend test joins it too)
    assert len(split(grid_of(z), mask, settings=CreaseSettings(inset_share=1.0))) == 1


def test_a_surface_covered_in_creases_by_noise_is_not_cut():
    # two touching cylinders, with depth noise that bends the normals everywhere (a far wall's, at this scale)
    grid, mask = cylinders([-0.045, 0.045])
    noisy = grid.xyz.copy()
    noisy[..., 2] += np.random.default_rng(0).normal(0.0, 0.005, noisy.shape[:2]).astype(np.float32)
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    g = PointGrid(noisy, grid.normals, grid.valid, 1)
    normals = crop_normals(g, rows[0], cols[0], rows[-1] + 1, cols[-1] + 1, within=mask)
    box = mask[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]
    crease = crease_cells(noisy[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1].astype(np.float64),
                          normals.astype(np.float64), box, 2, 45.0)
    assert crease[box].mean() > CreaseSettings().max_crease_frac
    assert len(split_at_creases(g, mask, normals, 60)) == 1
    # without the guard, the bend test joins most of what the noise cut (the pieces' own normals hardly bend
    # between them) and keeps the true valley between the two cylinders
    loose = split_at_creases(g, mask, normals, 60, CreaseSettings(max_crease_frac=1.0, bend_deg=0.0))
    pieces = split_at_creases(g, mask, normals, 60, CreaseSettings(max_crease_frac=1.0))
    assert 2 <= len(pieces) < len(loose)
    left, right = (H // 2, W // 2 - 45), (H // 2, W // 2 + 45)
    assert not any(p[left] and p[right] for p in pieces)


def test_h_maxima_marks_the_cells_skimage_marks():
    """The crease cut's seeds: creases.h_maxima against skimage's on distance maps with plateaus, ties and
    several peaks, on noise, and where h exceeds the image's range."""
    from skimage.morphology import h_maxima as skimage_h_maxima

    from lv3d.perception.depth.creases import h_maxima
    from lv3d.perception.distance import euclidean_distance

    rng = np.random.default_rng(0)
    for trial in range(30):
        shape = tuple(rng.integers(8, 90, size=2))
        blobs = np.zeros(shape, np.uint8)
        for _ in range(rng.integers(1, 5)):
            centre = (int(rng.integers(0, shape[1])), int(rng.integers(0, shape[0])))
            cv2.circle(blobs, centre, int(rng.integers(2, 30)), 1, -1)
        images = [euclidean_distance(blobs), rng.random(shape).astype(np.float32) * 10]
        for image in images:
            for h in (1.0, 2.5, float(np.ptp(image)) + 1.0):
                want = skimage_h_maxima(image, h)
                got = h_maxima(image, h)
                assert got.dtype == want.dtype and np.array_equal(got, want), (trial, h)
