"""A solid seen in parts around what stands in front of it: two of depth's solids that share a plane, with
everything between them in the image nearer the camera than that plane, are one solid.

Depth cuts objects at depth jumps, so a box half hidden behind another comes out as two pieces, one on each side
of the occluder. Their faces lie in the same planes; the occluder's points lie in front of those planes along
the line between the pieces. Two separate solids side by side with coplanar faces are joined only when something
hides the space between them, which the line test checks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .objects import DepthObject
from .planes import DepthPlane
from .ranges import check_ranges
from .support import SENSOR, SensorNoise


@dataclass(frozen=True)
class OcclusionSettings:
    """``coplanar_deg`` (degrees): two planes are one when their normals are this close and the smaller's points
    lie (median) within the inlier distance of the larger's plane; twice the normal error of a plane fitted to a
    few hundred noisy points.
    ``hidden_share`` (fraction): the share of the cells on the line between the two pieces that must lie in front
    of the shared plane (other objects' cells nearer the camera by more than the inlier distance); the rest may
    be unread (the shadow a depth sensor casts beside an occluder).
    ``samples``: cells sampled along that line.
    """

    coplanar_deg: float = 8.0
    hidden_share: float = 0.8
    samples: int = 64

    def __post_init__(self) -> None:
        check_ranges(self, acute=("coplanar_deg",), fractions=("hidden_share",), counts={"samples": 1})


DEFAULT = OcclusionSettings()


def _shared_plane(a: list[DepthPlane], b: list[DepthPlane], cos_min: float, sensor: SensorNoise
                  ) -> tuple[DepthPlane, DepthPlane] | None:
    for p in a:
        for q in b:
            if abs(float(p.plane.n @ q.plane.n)) < cos_min:
                continue
            big, small = (p, q) if len(p.points) >= len(q.points) else (q, p)
            dist_m = sensor.inlier_m(float(np.median(big.points[:, 2])))
            if np.median(np.abs(big.plane.distance(small.points))) <= dist_m:
                return p, q
    return None


def _hidden_between(p: DepthPlane, q: DepthPlane, xyz: np.ndarray, valid: np.ndarray, own: np.ndarray,
                    settings: OcclusionSettings, sensor: SensorNoise) -> bool:
    """True when the cells on the line between the centroids (on the grid) of ``p``'s and ``q``'s cells, off the
    two pieces (``own``), lie in front of ``p``'s plane (or are unread) for ``hidden_share`` of them, and some
    do lie in front."""
    ca, cb = np.argwhere(p.mask).mean(axis=0), np.argwhere(q.mask).mean(axis=0)
    t = np.linspace(0.0, 1.0, settings.samples)
    ij = np.round(ca[None, :] + t[:, None] * (cb - ca)[None, :]).astype(int)
    ij = np.unique(ij, axis=0)
    off = ~own[ij[:, 0], ij[:, 1]]
    if not off.any():
        return False
    cells = ij[off]
    read = valid[cells[:, 0], cells[:, 1]]
    pts = xyz[cells[:, 0], cells[:, 1]].astype(np.float64)
    dist_m = sensor.inlier_m(float(np.median(p.points[:, 2])))
    # normals point towards the camera: a point in front of the plane has a positive distance
    front = read & (p.plane.distance(pts) > dist_m)
    return bool(front.any()) and float(np.mean(front | ~read)) >= settings.hidden_share


def join_occluded(solids: list[tuple[DepthObject, list[DepthPlane]]], xyz: np.ndarray, valid: np.ndarray,
                  settings: OcclusionSettings = DEFAULT, sensor: SensorNoise = SENSOR
                  ) -> list[tuple[DepthObject, list[DepthPlane]]]:
    """``solids`` (each a depth object with its planes) with every two pieces of one solid hidden in part by
    something in front joined: their masks united, their planes together (the shared plane's two pieces are
    merged later, with the solid's other coplanar pieces). The inlier distance is ``sensor``'s at a piece's
    median depth (support.SensorNoise)."""
    cos_min = np.cos(np.radians(settings.coplanar_deg))
    solids = list(solids)
    joined = True
    while joined:
        joined = False
        for i in range(len(solids)):
            for j in range(i + 1, len(solids)):
                (oa, pa), (ob, pb) = solids[i], solids[j]
                shared = _shared_plane(pa, pb, cos_min, sensor)
                if shared is None or not _hidden_between(*shared, xyz, valid, oa.mask | ob.mask, settings, sensor):
                    continue
                solids[i] = (DepthObject(oa.mask | ob.mask, max(oa.height_m, ob.height_m)), pa + pb)
                del solids[j]
                joined = True
                break
            if joined:
                break
    return solids
