"""The point grid's fast forms give the very numbers of numpy's general ones: gathering cells by a mask
(cloud.cell_rows), where normals are known (cloud.known) and the grid's normals (cloud.grid_normals), bit for bit."""

import numpy as np

from lv3d.perception.depth.cloud import cell_rows, grid_normals, known


def _surface(seed: int = 0, h: int = 60, w: int = 80):
    """A bumpy surface about 0.8 m away as a grid of points (h, w, 3) float32, with holes (no reading)."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:h, 0:w].astype(np.float32)
    z = 0.8 + 0.02 * np.sin(u / 7.0) * np.cos(v / 5.0) + rng.normal(0, 0.001, (h, w))
    xyz = np.stack([(u - w / 2) / 525.0 * z, (v - h / 2) / 525.0 * z, z], axis=-1).astype(np.float32)
    valid = rng.random((h, w)) > 0.05
    xyz[~valid] = 0
    return xyz, valid


def test_cell_rows_is_boolean_indexing():
    xyz, valid = _surface()
    for values, mask in ((xyz, valid), (xyz[5:40, 10:70], valid[5:40, 10:70]), (xyz[::2, ::2], valid[::2, ::2])):
        got = cell_rows(values, mask)
        assert got.dtype == values.dtype and np.array_equal(got, values[mask])
    assert cell_rows(xyz, np.zeros(valid.shape, bool)).shape == (0, 3)


def test_known_is_a_normal_of_length_above_zero():
    n = grid_normals(*_surface(1))
    n[3:9, 4:12] = 0
    n[20, 20] = (1e-20, 0.0, 0.0)  # a length whose square underflows: neither counts it
    assert np.array_equal(known(n), np.linalg.norm(n, axis=2) > 0)


def test_grid_normals_are_those_of_the_general_numpy_calls():
    import cv2

    for seed in range(3):
        xyz, valid = _surface(seed)
        # the same steps written with numpy's general calls
        m = valid.astype(np.float32)
        wsum = cv2.boxFilter(m, -1, (5, 5), normalize=False)
        sm = cv2.boxFilter(xyz * m[..., None], -1, (5, 5), normalize=False) / np.maximum(wsum, 1e-6)[..., None]
        du, dv = np.zeros_like(sm), np.zeros_like(sm)
        du[:, 1:-1] = sm[:, 2:] - sm[:, :-2]
        dv[1:-1, :] = sm[2:, :] - sm[:-2, :]
        want = np.cross(du, dv)
        want /= np.maximum(np.linalg.norm(want, axis=2, keepdims=True), 1e-12)
        want[(want * xyz).sum(axis=2) > 0] *= -1
        ok = valid & (wsum >= 0.6 * 25)
        ok[:, :1] = ok[:, -1:] = False
        ok[:1, :] = ok[-1:, :] = False
        want[~ok] = 0
        got = grid_normals(xyz, valid)
        assert got.dtype == np.float32 and np.array_equal(got, want)
        assert np.allclose(np.linalg.norm(got[ok], axis=1), 1.0, atol=1e-5)  # unit where known, towards the camera
        assert (np.einsum("ij,ij->i", got[ok], xyz[ok]) <= 0).all()
