"""Two pieces of one solid seen around an occluder are joined; pieces with nothing in front between them are not."""

import numpy as np

from lv3d.perception.depth.objects import DepthObject
from lv3d.perception.depth.occlusion import join_occluded
from lv3d.perception.depth.planes import DepthPlane
from lv3d.perception.depth.support import refine


def _grid(z_between: float):
    h, w = 40, 60
    jj, ii = np.meshgrid(np.arange(w), np.arange(h))
    z = np.full((h, w), 1.0)
    z[:, 20:40] = z_between
    xyz = np.stack([(jj - 30) * z / 500.0, (ii - 20) * z / 500.0, z], axis=-1).astype(np.float32)
    return xyz, np.ones((h, w), bool)


def _piece(xyz: np.ndarray, cols: slice) -> tuple[DepthObject, list[DepthPlane]]:
    m = np.zeros(xyz.shape[:2], bool)
    m[:, cols] = True
    pts = xyz[m].astype(np.float64)
    return DepthObject(m, 0.1), [DepthPlane(refine(pts), m, pts.astype(np.float32), 0.0)]


def test_a_box_seen_on_both_sides_of_an_occluder_is_one_solid():
    xyz, valid = _grid(z_between=0.8)  # an object 20 cm in front covers the middle
    out = join_occluded([_piece(xyz, slice(0, 20)), _piece(xyz, slice(40, 60))], xyz, valid)
    assert len(out) == 1 and np.count_nonzero(out[0][0].mask) == 40 * 40 and len(out[0][1]) == 2


def test_coplanar_pieces_with_nothing_in_front_between_stay_apart():
    xyz, valid = _grid(z_between=1.3)  # what lies between is behind their plane (a wall, the floor)
    assert len(join_occluded([_piece(xyz, slice(0, 20)), _piece(xyz, slice(40, 60))], xyz, valid)) == 2
    valid = valid.copy()
    valid[:, 20:40] = False  # nothing read between them
    assert len(join_occluded([_piece(xyz, slice(0, 20)), _piece(xyz, slice(40, 60))], xyz, valid)) == 2
