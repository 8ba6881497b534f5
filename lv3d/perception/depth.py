"""Faces from depth alone: point grid -> support plane -> objects above it -> planes per object -> boundary
polygons, plane adjacency."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..plane import Plane
from ..rgbd import RGBD
from .boundary import mask_polygon
from .cloud import PointGrid, point_grid, slope_noise
from .convexity import split_at_concave
from .objects import DepthObject, heavy_noise, segment_objects, support_band
from .planes import DepthPlane, object_planes, plane_adjacency
from .plane_outline import simplify_on_plane
from .polygons import merge_close_corners
from .snap import add_triple_corners, snap_polygons
from .support import noise_threshold


# the most objects a frame's depth stage describes (largest first): a table-top scene, clutter included, holds
# fewer; every object costs grounding time. An option of perceive() and `lv3d extract --max-objects`
MAX_OBJECTS = 24

# the share of an object's points a plane needs under heavy depth noise (planes.object_planes' min_frac; its
# default holds otherwise)
_NOISY_PLANE_SHARE = 0.06


@dataclass(frozen=True)
class DepthObjectResult:
    """One object: its grid ``mask``, ``planes`` (largest first), their image ``polygons`` (None where the
    mask gave none), ``adjacency`` (i, j) between planes, and the object's point centroid (metres)."""

    obj: DepthObject
    planes: list[DepthPlane]
    polygons: list[np.ndarray | None]
    adjacency: list[tuple[int, int]]
    centroid_m: np.ndarray
    box_px: tuple[int, int, int, int]  # (u0, v0, u1, v1), end exclusive


@dataclass
class DepthResult:
    grid: PointGrid
    support: Plane | None
    objects: list[DepthObjectResult]
    timings_ms: dict[str, float] = field(default_factory=dict)
    dropped_objects: int = 0  # objects found beyond the cap (``max_objects``), smallest first


def depth_scene(frame: RGBD, stride: int = 1, seed: int = 0, max_objects: int = MAX_OBJECTS) -> DepthResult:
    """Run the depth stages on one frame; the ``max_objects`` largest objects are described, the number left out
    is ``dropped_objects``."""
    if max_objects < 1:
        raise ValueError(f"max_objects must be at least 1, got {max_objects}")
    t0 = time.perf_counter()
    grid = point_grid(frame.depth, frame.intrinsics, stride, normals=False)
    t1 = time.perf_counter()
    support = _support(grid, seed)
    t2 = time.perf_counter()
    band = support_band(grid, support) if support is not None else None
    # depth noise as a fraction of depth (sigma / z), measured on the frame: object cuts must stand out of it
    noise_rel = slope_noise(frame.depth, frame.intrinsics) / frame.intrinsics.fx
    objs = segment_objects(grid, support, band_m=band, noise_rel=noise_rel)
    # under heavy noise a small piece of an object is more often noise than a face: a plane needs a larger share
    # (3.5% lifts clean depth recall by 0.016-0.031 on dev seeds, but cost the hard preset up to 0.05 of precision;
    # docs/perception.md, session 27)
    share = {"min_frac": _NOISY_PLANE_SHARE} if heavy_noise(noise_rel) else {}
    solids = _solids(grid, support, objs, seed, share)
    solids.sort(key=lambda op: (-op[0].size, int(np.argmax(op[0].mask))))
    dropped = max(0, len(solids) - max_objects)
    solids = solids[:max_objects]
    t3 = time.perf_counter()
    h, w = frame.shape
    results = []
    t_planes = t_boundary = 0.0
    for k, (o, planes) in enumerate(solids):
        ta = time.perf_counter()
        adj = plane_adjacency(planes)
        tb = time.perf_counter()
        polys = [mask_polygon(p.mask, stride, (h, w)) for p in planes]
        if planes:
            # sides along a neighbour or the support plane go onto the planes' intersection line
            z = float(np.median(planes[0].points[:, 2]))
            polys = snap_polygons(polys, [p.plane for p in planes], adj, support, frame.intrinsics,
                                  2.5 * noise_threshold(z))
            polys = add_triple_corners(polys, [p.plane for p in planes], adj, frame.intrinsics)
            # corners judged on the face's plane, where an edge-on face is not squeezed
            polys = [None if q is None else simplify_on_plane(q, p.plane, frame.intrinsics)
                     for q, p in zip(polys, planes)]
            # a side shorter than a grid cell and a half is below what the grid can measure: a corner cut
            polys = [None if q is None else merge_close_corners(q, 1.5 * stride) for q in polys]
        t_boundary += time.perf_counter() - tb
        t_planes += tb - ta
        ij = np.argwhere(o.mask)
        (i0, j0), (i1, j1) = ij.min(axis=0), ij.max(axis=0)
        box = (int(j0 * stride), int(i0 * stride), min(w, int((j1 + 1) * stride)), min(h, int((i1 + 1) * stride)))
        results.append(DepthObjectResult(o, planes, polys, adj, grid.xyz[o.mask].mean(axis=0).astype(np.float64), box))
    timings = {"cloud": (t1 - t0) * 1e3, "support": (t2 - t1) * 1e3, "objects": (t3 - t2) * 1e3,
               "planes": t_planes * 1e3, "boundary": t_boundary * 1e3}
    return DepthResult(grid, support, results, timings, dropped)


def _solids(grid: PointGrid, support: Plane | None, objs: list[DepthObject], seed: int, share: dict
            ) -> list[tuple[DepthObject, list[DepthPlane]]]:
    """Each object cut at concave creases into solids (convexity.split_at_concave), each solid with its planes: a
    cut piece gets its planes anew, which may cut it again."""
    out = []
    todo = list(objs)
    while todo:
        o = todo.pop(0)
        planes = object_planes(grid, o.mask, seed=seed + len(out), **share)
        pieces = split_at_concave(grid, o.mask, planes)
        if len(pieces) == 1:
            out.append((o, planes))
        else:
            todo += [DepthObject(m, _height(grid, support, m)) for m in pieces]
    return out


def _height(grid: PointGrid, support: Plane | None, mask: np.ndarray) -> float:
    if support is None:
        return float("inf")
    return float(np.percentile(grid.xyz[mask].astype(np.float64) @ support.n + support.offset, 95))


def _support(grid: PointGrid, seed: int) -> Plane | None:
    from .support import support_plane

    # every other grid point is plenty for the support plane
    return support_plane(grid.xyz[::2, ::2][grid.valid[::2, ::2]].astype(np.float64), seed=seed)
