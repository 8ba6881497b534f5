"""The depth stage: point grid -> support plane -> objects above it -> solids (cut at valleys of height and at
concave creases) -> planes per solid -> boundary polygons, plane adjacency.

Its thresholds live in one frozen :class:`DepthSettings`, in scale-free units: fractions of the image (its cell
count or diagonal), fractions of an object's points or of the depth, multiples of the sensor's noise (its model,
support.SensorNoise, or the noise measured on the frame), angles. Pixel counts are derived from them for the
frame at hand, so the same settings hold at 320x240 and at 1280x960. :func:`with_overrides` makes settings other
than the defaults from ``{key: value}`` (the benchmarks' and the studies' way to set them).
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, is_dataclass, replace

import cv2
import numpy as np

from ...plane import Plane, column_means
from ...rgbd import RGBD
from ..boundary import mask_polygon
from .cloud import PointGrid, cell_rows, crop_normals, point_grid, slope_noise
from .convexity import ConvexitySettings, split_at_concave
from .creases import CreaseSettings, split_at_creases
from .curved import CurvedFace, CurvedSettings, object_cylinders
from .holes import HoleSettings, UnreadSettings
from .occlusion import OcclusionSettings, join_occluded
from .ranges import check_ranges
from .quadrics import QuadricFace, QuadricSettings, leaves_room, quadric_faces
from .objects import DepthObject, heavy_noise, object_scale, segment_objects, support_band
from .planes import DepthPlane, largest_piece, merge_coplanar, object_planes, plane_adjacency
from .plane_outline import simplify_on_plane
from ..polygons import merge_close_corners
from .snap import add_triple_corners, snap_polygons
from .support import SENSOR, SensorNoise


@dataclass(frozen=True)
class DepthSettings:
    """Thresholds of the depth stage, each with its unit and the reason for its value.

    ``stride`` (pixels per grid cell, each way): the point grid reads every ``stride``-th pixel of each row and
    column. 1, every pixel: a grid of 2 takes about half the time, and on the Kinect table-top frames of the real
    dev set it keeps the figures (one or two more round objects read as prisms), but on the RealSense clutter
    frames small cans and cups lose their curvature (docs/perception.md, "Speed").
    ``max_objects`` (objects): the most objects described, the largest; a table-top scene, clutter included,
    holds fewer, and every object costs grounding time. The scene counts the rest (``dropped_objects``).
    ``min_object_frac`` (fraction of the image's cells): the smallest object; below it a piece is a speck of
    noise or the tip of something cut by the border. 0.0002 is 60 cells of a 640x480 grid.
    ``max_border`` (fraction of an object's outline): a piece cut by the image border along more of its outline
    is scenery (a wall, the floor beyond a table, furniture), not an object.
    ``regrow_frac`` (fraction of the image diagonal): how far an object takes back the foreground cells that
    depth-jump cuts left out (a face seen edge-on is all jumps); 0.00625 is 5 cells at 640x480.
    ``plane_share`` / ``noisy_plane_share`` (fraction of an object's points): the smallest plane of an object, and
    under heavy noise (``objects.heavy_noise``), where a small piece is more often noise than a face.
    ``plane_max_frac`` (fraction of the image's cells): the share above is capped at this many cells, so that a
    large object's small face counts; 0.0049 is 1500 cells at 640x480.
    ``plane_min_frac`` (fraction of the image's cells): no plane has fewer cells; 25 at 640x480.
    ``seed_bands`` (multiples of the support band, itself four times the support's measured noise): objects stand
    out of their neighbourhood by more than this; their parts above it seed the split at valleys of height
    (objects._split_by_height).
    ``support_stand_rel`` (fraction of the median depth): how high above a candidate support plane points count
    as objects standing on it (their lower parts), and ``support_inner`` (fraction of its extent, about its
    centre) over what part of it (support.support_plane).
    ``convexity``: the cut at concave creases between an object's planes (convexity.ConvexitySettings).
    ``creases``: the cut at concave creases of the surface where its planes do not cut it (curved objects
    touching: creases.CreaseSettings).
    ``curved``: a fan of planes read as one cylindrical face (curved.CurvedSettings).
    ``quadrics``: an object's sphere or cone side read as one face (quadrics.QuadricSettings).
    ``occlusion``: two pieces of one solid seen around an occluder joined (occlusion.OcclusionSettings).
    ``unread``: the faces beside an object that depth did not read, inferred from the holes its readings leave
    (holes.UnreadSettings; perceive asks it of each object).
    ``holes``: which regions without readings beside an object may be faces, for those and for the faces colour
    confirms under rgbd (holes.HoleSettings).
    ``sensor``: the depth noise every fit allows for, the inlier distance at a depth (support.SensorNoise).
    """

    stride: int = 1
    max_objects: int = 24
    min_object_frac: float = 0.0002
    max_border: float = 0.12
    regrow_frac: float = 0.00625
    plane_share: float = 0.035
    noisy_plane_share: float = 0.06
    plane_max_frac: float = 0.0049
    plane_min_frac: float = 0.00008
    seed_bands: float = 3.0
    support_stand_rel: float = 0.1
    support_inner: float = 0.85
    convexity: ConvexitySettings = field(default_factory=ConvexitySettings)
    creases: CreaseSettings = field(default_factory=CreaseSettings)
    curved: CurvedSettings = field(default_factory=CurvedSettings)
    quadrics: QuadricSettings = field(default_factory=QuadricSettings)
    occlusion: OcclusionSettings = field(default_factory=OcclusionSettings)
    unread: UnreadSettings = field(default_factory=UnreadSettings)
    holes: HoleSettings = field(default_factory=HoleSettings)
    sensor: SensorNoise = field(default_factory=SensorNoise)

    def __post_init__(self) -> None:
        check_ranges(self, counts={"stride": 1, "max_objects": 1}, positive=("seed_bands",),
                     fractions=("min_object_frac", "max_border", "regrow_frac", "plane_share", "noisy_plane_share",
                                "plane_max_frac", "plane_min_frac", "support_stand_rel", "support_inner"))


DEFAULT = DepthSettings()


def with_overrides(overrides: Mapping[str, object], base: DepthSettings = DEFAULT) -> DepthSettings:
    """``base`` with each ``{key: value}`` of ``overrides`` applied: a key names a field of DepthSettings
    (``stride``) or of one of its parts (``sensor.base_m``, ``quadrics.fit_cells``); a value has its default's
    kind (a whole number for a count, any number for a float). ValueError naming the key for an unknown key, a
    value of another kind or one the settings refuse."""
    settings = base
    for key, value in overrides.items():
        *path, name = str(key).split(".")
        parts = [settings]
        for p in path:
            inner = getattr(parts[-1], p, None)
            if not is_dataclass(inner):
                raise ValueError(f"{key}: {p!r} is no part of the depth settings")
            parts.append(inner)
        if name not in {f.name for f in fields(parts[-1])}:
            known = ", ".join(f.name for f in fields(parts[-1]))
            raise ValueError(f"{key}: unknown setting {name!r}; known here: {known}")
        was = getattr(parts[-1], name)
        if not _same_kind(value, was):
            raise ValueError(f"{key}: must be of type {type(was).__name__}, as its default {was!r}, got {value!r}")
        try:
            new = replace(parts[-1], **{name: value})
            for outer, p in zip(reversed(parts[:-1]), reversed(path)):
                new = replace(outer, **{p: new})
        except (TypeError, ValueError) as e:
            raise ValueError(f"{key}: {e}") from None
        settings = new
    return settings


def _same_kind(value, default) -> bool:
    """Whether ``value`` may stand for a setting whose default is ``default``: a bool for a bool, a whole number
    (not a bool) for a whole number, any number (not a bool) for a float, else the default's own type."""
    if isinstance(default, bool) or isinstance(value, bool):
        return isinstance(value, bool) and isinstance(default, bool)
    if isinstance(default, float):
        return isinstance(value, (int, float))
    return isinstance(value, type(default))


@dataclass(frozen=True)
class DepthObjectResult:
    """One object: its grid ``mask``, ``planes`` (largest first), their image ``polygons`` (None where the
    mask gave none), ``adjacency`` (i, j) between planes, the object's point centroid (metres) and its ``scale``,
    the median depth and the extent of its points (metres, objects.object_scale)."""

    obj: DepthObject
    planes: list[DepthPlane]
    polygons: list[np.ndarray | None]
    adjacency: list[tuple[int, int]]
    centroid_m: np.ndarray
    box_px: tuple[int, int, int, int]  # (u0, v0, u1, v1), end exclusive
    scale: tuple[float, float]
    # curved faces (a can's side, a ball, a cone's side), not in ``planes``
    curved: list[CurvedFace | QuadricFace] = field(default_factory=list)
    curved_polygons: list[np.ndarray | None] = field(default_factory=list)
    curved_adjacency: list[tuple[int, int]] = field(default_factory=list)  # (plane i, curved face j) touching


@dataclass
class DepthResult:
    grid: PointGrid
    support: Plane | None
    objects: list[DepthObjectResult]
    timings_ms: dict[str, float] = field(default_factory=dict)
    dropped_objects: int = 0  # objects found beyond the cap (``max_objects``), smallest first
    unconverged_fits: int = 0  # sphere and cone least-squares fits that did not converge (no face came of them)
    settings: DepthSettings = DEFAULT  # what the stages ran with


def depth_scene(frame: RGBD, seed: int = 0, max_objects: int | None = None,
                settings: DepthSettings = DEFAULT) -> DepthResult:
    """Run the depth stages on one frame; the ``settings.max_objects`` largest objects (``max_objects`` overrides
    it) are described, the number left out is ``dropped_objects``."""
    if max_objects is not None:
        settings = replace(settings, max_objects=max_objects)
    stride = settings.stride
    t0 = time.perf_counter()
    grid = point_grid(frame.depth, frame.intrinsics, stride, normals=False)
    t1 = time.perf_counter()
    support = _support(grid, seed, settings)
    t2 = time.perf_counter()
    band = support_band(grid, support, sensor=settings.sensor) if support is not None else None
    # depth noise as a fraction of depth (sigma / z), measured on the frame: object cuts must stand out of it
    noise_rel = slope_noise(frame.depth, frame.intrinsics) / frame.intrinsics.fx
    cells = grid.valid.size
    objs = segment_objects(grid, support, band_m=band, noise_rel=noise_rel,
                           min_points=max(1, round(settings.min_object_frac * cells)),
                           max_border=settings.max_border,
                           regrow=max(1, round(settings.regrow_frac * float(np.hypot(*grid.shape)))),
                           seed_bands=settings.seed_bands, sensor=settings.sensor)
    plane_args = {"min_frac": settings.noisy_plane_share if heavy_noise(noise_rel) else settings.plane_share,
                  "max_need": max(1, round(settings.plane_max_frac * cells)),
                  "min_points": max(3, round(settings.plane_min_frac * cells))}
    normals = _Normals(grid)
    solids = _solids(grid, support, objs, seed, plane_args, settings, normals,
                     max(1, round(settings.min_object_frac * cells)))
    solids = join_occluded(solids, grid.xyz, grid.valid, settings.occlusion, settings.sensor)
    solids.sort(key=lambda op: (-op[0].size, int(np.argmax(op[0].mask))))
    dropped = max(0, len(solids) - settings.max_objects)
    solids = solids[:settings.max_objects]
    t3 = time.perf_counter()
    h, w = frame.shape
    results = []
    t_planes = t_boundary = 0.0
    unconverged = 0
    for k, (o, planes) in enumerate(solids):
        ta = time.perf_counter()
        planes = merge_coplanar(planes, sensor=settings.sensor)
        adj = plane_adjacency(planes)
        # whether the planes leave room for a curved surface: asked once, of the planes both searches start from
        room = _room(o.mask, normals(o.mask), planes, adj, settings.quadrics)
        # a sphere or a cone first: the cylinder search would read a cone's side as a cylinder
        own = cell_rows(grid.xyz, o.mask)  # the object's points, (m, 3) metres
        scale = object_scale(own.astype(np.float64))
        planes, adj, quads, failed = quadric_faces(grid.xyz, o.mask, normals(o.mask), planes, adj,
                                                   stride / frame.intrinsics.fx, _plane_need(o, plane_args), seed + k,
                                                   scale, settings.quadrics, room=room, sensor=settings.sensor)
        unconverged += failed
        # (a sphere or a cone that replaced planes leaves others: the question is asked again of those)
        planes, adj, curved = _curved(grid, o, planes, adj, settings.curved, normals, stride / frame.intrinsics.fx,
                                      _plane_need(o, plane_args), seed + k, settings.quadrics, scale,
                                      room=None if quads else room, sensor=settings.sensor)
        curved = quads + [c for c in curved if not any(np.any(c.mask & q.mask) for q in quads)]
        curved_adj = _touching(planes, curved, o.mask)
        tb = time.perf_counter()
        polys = [mask_polygon(p.mask, stride, (h, w)) for p in planes]
        if planes:
            # sides along a neighbour or the support plane go onto the planes' intersection line
            z = float(np.median(planes[0].points[:, 2]))
            polys = snap_polygons(polys, [p.plane for p in planes], adj, support, frame.intrinsics,
                                  2.5 * settings.sensor.inlier_m(z))
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
        curved_polys = [mask_polygon(c.mask, stride, (h, w), convex=False) for c in curved]
        results.append(DepthObjectResult(o, planes, polys, adj, column_means(own).astype(np.float64), box,
                                         scale, curved, curved_polys, curved_adj))
    timings = {"cloud": (t1 - t0) * 1e3, "support": (t2 - t1) * 1e3, "objects": (t3 - t2) * 1e3,
               "planes": t_planes * 1e3, "boundary": t_boundary * 1e3}
    return DepthResult(grid, support, results, timings, dropped, unconverged, settings)


def _touching(planes: list[DepthPlane], curved: list, mask: np.ndarray, reach: int = 2, min_contact: int = 4
              ) -> list[tuple[int, int]]:
    """The pairs (plane i, curved face j) that touch: at least ``min_contact`` cells of the plane within ``reach``
    cells (a square of side 2 reach + 1) of the curved face. Worked on the object's box (its cells ``mask``) grown
    by ``reach``, where every such cell lies, each curved face dilated once."""
    if not curved or not planes:
        return []
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    i0, j0 = max(0, rows[0] - reach), max(0, cols[0] - reach)
    i1, j1 = rows[-1] + 1 + reach, cols[-1] + 1 + reach
    kernel = np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)
    out = []
    for j, c in enumerate(curved):
        near = cv2.dilate(np.ascontiguousarray(c.mask[i0:i1, j0:j1]).view(np.uint8), kernel).view(bool)
        out += [(i, j) for i, p in enumerate(planes) if np.count_nonzero(near & p.mask[i0:i1, j0:j1]) >= min_contact]
    return out


class _Normals:
    """Each object's normals on its bounding box of the grid, from its own points (cloud.crop_normals with
    ``within``), computed once per object mask: the plane search and the cylinder search both need them."""

    def __init__(self, grid: PointGrid):
        self.grid = grid
        self._memo: dict[bytes, np.ndarray] = {}

    def __call__(self, mask: np.ndarray) -> np.ndarray:
        key = hashlib.blake2b(np.packbits(mask).tobytes(), digest_size=16).digest()
        if key not in self._memo:
            rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
            self._memo[key] = crop_normals(self.grid, rows[0], cols[0], rows[-1] + 1, cols[-1] + 1, within=mask)
        return self._memo[key]


def _solids(grid: PointGrid, support: Plane | None, objs: list[DepthObject], seed: int, plane_args: dict,
            settings: DepthSettings, normals: _Normals, min_cells: int
            ) -> list[tuple[DepthObject, list[DepthPlane]]]:
    """Each object cut at concave creases into solids, each solid with its planes: first at creases between its
    planes (convexity.split_at_concave), else at creases of its surface (creases.split_at_creases, pieces of at
    least ``min_cells``); a cut piece gets its planes anew, which may cut it again."""
    out = []
    todo = [(o, True) for o in objs]
    while todo:
        o, whole = todo.pop(0)
        planes = object_planes(grid, o.mask, seed=seed + len(out), normals=normals(o.mask), sensor=settings.sensor,
                               **plane_args)
        pieces = split_at_concave(grid, o.mask, planes, settings.convexity)
        by_planes = len(pieces) > 1
        if not by_planes and whole:
            # a piece the creases cut is not asked again: its creases are its borders
            pieces = split_at_creases(grid, o.mask, normals(o.mask), min_cells, settings.creases)
        if len(pieces) == 1:
            out.append((o, planes))
        else:
            todo += [(DepthObject(m, _height(grid, support, m)), by_planes) for m in pieces]
    return out


def _room(mask: np.ndarray, nrm_box: np.ndarray, planes: list[DepthPlane], adj: list[tuple[int, int]],
          settings: QuadricSettings) -> bool:
    """quadrics.leaves_room of the object whose cells are ``mask``."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    return len(rows) > 0 and leaves_room(mask, nrm_box, rows, cols, planes, adj, settings)


def _curved(grid: PointGrid, o: DepthObject, planes: list[DepthPlane], adj: list[tuple[int, int]],
            settings: CurvedSettings, normals: _Normals, cell_rel: float, min_cells: int, seed: int, room_settings,
            scale: tuple[float, float], room: bool | None = None, sensor: SensorNoise = SENSOR
            ) -> tuple[list[DepthPlane], list[tuple[int, int]], list[CurvedFace]]:
    """The object's planes and their adjacency with the planes its cylindrical faces replace left out, and those
    faces (curved.object_cylinders); the inputs unchanged when there is none. ``cell_rel``: a grid cell's width as
    a fraction of the depth (stride / fx); ``min_cells``: the fewest cells of a face, as of a plane; ``scale``: the
    object's median depth and extent (objects.object_scale). The sample
    consensus of cylinders runs only where the planes leave room for a curved surface (quadrics.leaves_room with
    ``room_settings``; ``room``: its answer where already known); the fan of planes always. The inlier distance
    is ``sensor``'s at the object's median depth (support.SensorNoise)."""
    if not planes:
        return planes, adj, []
    m = o.mask
    rows, cols = np.flatnonzero(m.any(axis=1)), np.flatnonzero(m.any(axis=0))
    i0, i1, j0, j1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    box = m[i0:i1, j0:j1]
    nrm = cell_rows(normals(m), box).astype(np.float64)
    pts = cell_rows(grid.xyz[i0:i1, j0:j1], box).astype(np.float64)
    plane_of = np.full(len(pts), -1)
    for k, p in enumerate(planes):
        plane_of[p.mask[i0:i1, j0:j1][box]] = k
    z, extent = scale
    if room is None:
        room = leaves_room(m, normals(m), rows, cols, planes, adj, room_settings)
    found = object_cylinders(pts, nrm, box, plane_of, [p.plane for p in planes], sensor.inlier_m(z), extent,
                             cell_rel * z, min_cells, seed, settings, adj, sample=room)
    if not found:
        return planes, adj, []
    gone = {k for _, _, fan in found for k in fan}
    keep = [k for k in range(len(planes)) if k not in gone]
    kept = [planes[k] for k in keep]
    curved = []
    for cyl, on, _ in found:
        face = np.zeros_like(m)
        face[i0:i1, j0:j1][box] = on
        for p in kept:
            face &= ~p.mask
        face = largest_piece(face)
        if not face.any():
            continue
        on_face = cell_rows(grid.xyz, face)
        r, _ = cyl.radial(on_face.astype(np.float64))
        curved.append(CurvedFace(cyl, face, on_face.astype(np.float32),
                                 float(np.sqrt(np.mean((r - cyl.radius) ** 2)))))
    index = {k: i for i, k in enumerate(keep)}
    return kept, [(index[a], index[b]) for a, b in adj if a in index and b in index], curved


def _plane_need(o: DepthObject, plane_args: dict) -> int:
    """The fewest cells of a face of object ``o``, as planes.object_planes asks of a plane."""
    return max(plane_args["min_points"], min(int(plane_args["min_frac"] * o.size), plane_args["max_need"]))


def _height(grid: PointGrid, support: Plane | None, mask: np.ndarray) -> float:
    if support is None:
        return float("inf")
    return float(np.percentile(cell_rows(grid.xyz, mask).astype(np.float64) @ support.n + support.offset, 95))


def _support(grid: PointGrid, seed: int, settings: DepthSettings = DEFAULT) -> Plane | None:
    from .support import support_plane

    # every other grid point is plenty for the support plane
    return support_plane(cell_rows(grid.xyz[::2, ::2], grid.valid[::2, ::2]).astype(np.float64), seed=seed,
                         stand_rel=settings.support_stand_rel, inner=settings.support_inner, sensor=settings.sensor)
