import numpy as np

from lv3d.perception.depth.planes import DepthPlane, merge_strips, object_planes
from lv3d.perception.depth.support import refine
from lv3d.plane import Plane

from .conftest import cell_grid


def _piece(mask: np.ndarray, depth_of_cell, rng: np.random.Generator, sigma_m: float = 0.002,
           plane: Plane | None = None) -> DepthPlane:
    """A DepthPlane of the cells of ``mask`` (rows i, columns j; 2 mm per cell) at depth ``depth_of_cell(i, j)``
    (metres) plus Gaussian noise; its plane is ``plane`` or the least-squares fit."""
    i, j = np.nonzero(mask)
    pts = np.stack([j * 0.002, i * 0.002, depth_of_cell(i, j) + rng.normal(0, sigma_m, len(i))], 1)
    p = plane if plane is not None else refine(pts)
    rms = float(np.sqrt(np.mean(p.distance(pts) ** 2)))
    return DepthPlane(p, mask, pts.astype(np.float32), rms)


def _angle(a: Plane, b: Plane) -> float:
    return float(np.degrees(np.arccos(min(1.0, abs(a.n @ b.n)))))


def test_a_strip_of_a_face_with_a_tilted_plane_joins_its_face():
    rng = np.random.default_rng(0)
    flat = lambda i, j: np.full(len(i), 1.0)  # a face square to the camera at 1 m
    face = np.zeros((40, 40), bool)
    face[:, 3:] = True
    strip = np.zeros((40, 40), bool)
    strip[:, :3] = True  # three cells wide along the silhouette, as perception peels them off
    big = _piece(face, flat, rng)
    # the strip's points lie on the face, but its fitted plane is tilted by 50 deg about the strip's long axis
    tilted = Plane.from_arrays([np.sin(np.radians(50)), 0.0, -np.cos(np.radians(50))],
                               np.cos(np.radians(50)) * 1.0 - np.sin(np.radians(50)) * 0.002)
    small = _piece(strip, flat, rng, plane=tilted)
    assert _angle(small.plane, big.plane) > 45
    out = merge_strips([big, small], dist_m=0.008)
    assert len(out) == 1
    assert out[0].mask.sum() == 1600 and len(out[0].points) == 1600
    assert _angle(out[0].plane, Plane.from_arrays([0, 0, -1], 1.0)) < 1.0


def test_a_true_neighbouring_face_stays_apart():
    rng = np.random.default_rng(1)
    a = np.zeros((40, 40), bool)
    a[:, 20:] = True
    b = ~a
    # two faces meeting along column 20 at 100 deg between their planes (a ridge 80 deg from flat)
    t = np.tan(np.radians(40))
    left = _piece(b, lambda i, j: 1.0 + (20 - j) * 0.002 * t, rng)
    right = _piece(a, lambda i, j: 1.0 + (j - 20) * 0.002 * t, rng)
    out = merge_strips([right, left], dist_m=0.008)
    assert len(out) == 2
    assert {len(p.points) for p in out} == {800}


def test_a_coplanar_piece_that_does_not_touch_stays_apart():
    rng = np.random.default_rng(2)
    flat = lambda i, j: np.full(len(i), 1.0)
    a = np.zeros((40, 40), bool)
    a[:, :15] = True
    b = np.zeros((40, 40), bool)
    b[:, 30:] = True
    out = merge_strips([_piece(a, flat, rng), _piece(b, flat, rng)], dist_m=0.008)
    assert len(out) == 2


def test_a_thin_face_seen_edge_on_with_its_neighbours_strip_stays_apart():
    rng = np.random.default_rng(3)
    flat = lambda i, j: np.full(len(i), 1.0)
    face = np.zeros((40, 40), bool)
    face[:, 5:] = True
    # a piece five cells wide: three of the face's own cells and, beyond them, two columns of a face turned
    # 80 deg away (seen nearly edge-on), on a plane of its own
    piece = np.zeros((40, 40), bool)
    piece[:, :5] = True
    edge_on = lambda i, j: 1.0 + np.maximum(0, 2 - j) * 0.002 * np.tan(np.radians(80))
    big = _piece(face, flat, rng, sigma_m=0.0)
    small = _piece(piece, edge_on, rng, sigma_m=0.0)
    assert len(merge_strips([big, small], dist_m=0.008)) == 2
    # the same piece with its off-plane points scattered like flying pixels joins the face
    fly = lambda i, j: np.where(j < 2, 1.0 + rng.uniform(0.01, 0.05, len(i)), 1.0)
    assert len(merge_strips([big, _piece(piece, fly, rng, sigma_m=0.0)], dist_m=0.008)) == 1


def test_points_along_the_silhouette_go_to_the_face_they_lie_on():
    # a roof seen from the front on 2 mm cells: face A square to the camera at 1 m (columns 0-19), face B turned 45
    # degrees away behind it (columns 20-39); above it (rows 0-9) a wall 0.3 m further back, read but not the object's
    n, top, ridge = 40, 10, 20
    i, j = np.mgrid[0:top + n, 0:n]
    z = np.where(i < top, 1.3, np.where(j < ridge, 1.0, 1.0 + (j - ridge) * 0.002))
    grid = cell_grid(z)  # normals measured where needed
    planes = object_planes(grid, i >= top, seed=0)
    assert len(planes) == 2
    face_a, face_b = sorted(planes, key=lambda p: -abs(p.plane.n[2]))
    # B's top rows near the ridge lie within A's reach: normals mixed with the wall's points, which faces the camera
    # as A does, gave them to A
    assert np.all(face_b.mask[top:top + 3, ridge + 1:ridge + 12])
    assert not np.any(face_a.mask[:, ridge + 1:])  # the ridge's own column lies on both
    assert np.all(face_a.mask[top:, :ridge])


def test_a_large_objects_small_face_gets_its_plane():
    # 2 mm cells: a face square to the camera at 1 m (286 columns) and a 14-column side turned away, 4.7% of the
    # object's 60000 cells: under the 6% share asked under heavy noise, above the 1500 points asked at most
    j = np.mgrid[0:200, 0:300][1]
    z = np.where(j < 286, 1.0, 1.0 + (j - 286) * 0.002)
    grid = cell_grid(z)
    obj = np.ones(z.shape, bool)
    planes = object_planes(grid, obj, seed=0, min_frac=0.06)
    assert len(planes) == 2
    side = min(planes, key=lambda p: np.count_nonzero(p.mask))
    assert np.all(side.mask[:, 290:]) and not np.any(side.mask[:, :284])
    assert _angle(side.plane, refine(grid.xyz[:, 287:].reshape(-1, 3).astype(np.float64))) < 1
    assert len(object_planes(grid, obj, seed=0, min_frac=0.06, max_need=10 ** 9)) == 1  # the share alone: none
    assert len(object_planes(grid, obj, seed=0, max_need=10 ** 9)) == 2  # 3.5% asked where noise is not heavy
