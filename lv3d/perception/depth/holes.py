"""Faces seen at a grazing angle, where the depth sensor gives no reading: holes in the depth image beside an
object whose outline the colour image confirms.

A stereo or structured-light sensor returns nothing where the view ray meets the surface nearly edge-on (beyond
about 78 degrees on a RealSense). Such a face is then a region without depth readings lying along the object's
silhouette: depth segmentation cannot see it (it has no points), and colour often misses it too (it is dark,
blurred, and its corners are a few px apart). Its shape is kept in the hole, though: the readings stop at the
face's own edges, on the object's side (the neighbour face) and on the table's. A hole is taken for a face when
it is a convex region (its polygon covers it and nothing more), runs along the object for a good part of its
outline, and its outline lies on colour edges (a hole of missing readings on a plain surface, as sensors also
leave, has no edge along the part of its outline that crosses the table or the object).

Depth alone (:func:`unread_faces`) has no colour to confirm a hole with, but the readings around it: they stop at
the face's own edges, so the points just outside a hole that is an unread face lie on one plane, the face's, and
that plane is seen nearly edge-on (which is why the sensor read nothing there). A blob of missing readings on the
table or on a face has that surface's plane around it instead, and one inside the object is surrounded by it,
where a face seen edge-on lies along the object's silhouette. Geometry cannot tell such a face from a sensor's
occlusion shadow (a band the projector does not light beside an object, which the renders do not model and real
Kinect frames show): with colour (rgbd) an unread face is kept only where colour edges run along more than the
object's side of it (:func:`add_hole_faces`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import cv2
import numpy as np

from ...plane import Plane, angle_deg, column_means
from ...rgbd import RGBD
from ...scene import Face
from ..boundary import grow_convex
from .cloud import PointGrid
from ..edges import edge_support
from .ranges import check_ranges
from ..polygons import area, clockwise, drop_short_sides, rasterize
from .support import SENSOR, SensorNoise, ransac_plane


# a plane seen within this angle of face-on is one the sensor reads: a RealSense reads to about 78 degrees
_UNREAD_DEG = 70.0
# a pixel's neighbourhood (px, not a scale): a band of a pixel or two between two regions drawn apart on the pixel
# grid (rasterised outlines, a hole and the readings round it) is where they touch
_RIM_PX = 2


@dataclass(frozen=True)
class HoleSettings:
    """Which regions without depth readings beside an object may be faces (:func:`hole_regions`), and when colour
    takes one for a face (:func:`hole_faces`, :func:`add_hole_faces`). Sizes are fractions of the image diagonal
    d (px), so that a frame of another resolution takes the same holes (at 640x480, d = 800 px).

    ``min_area_frac`` (fraction of d squared): the least area of a hole that may be a face, 150 px at 640x480: a
    face seen edge-on is a strip a few px wide and tens long; smaller gaps are the sensor's speckle.
    ``min_rim_frac`` (fraction of d): the least read pixels around a hole for a plane to be fitted to them, 30 px.
    ``min_touch_frac`` (fraction of d): a face meets another, and a hole touches a face, along at least this
    many px, 4 px.
    ``min_contact`` (fraction of the hole's outline): the share of it that must touch the object; a hole beside
    the object, not a blob elsewhere in the crop.
    ``min_fill`` / ``max_fill`` (ratio): the hole's area over its polygon's: a convex region that the polygon
    describes.
    ``min_support`` (fraction of the outline): the share of a hole's polygon on colour edges for colour to take it
    for a face; a hole of missing readings on a plain surface has none along the part that crosses it.
    ``max_taken`` (fraction of the hole's pixels): a hole the object's faces cover for more is a face found
    already.
    ``graze_deg`` (degrees from face-on): a face seen at least this obliquely, which a hole beside it continues,
    is extended over the hole (the sensor read part of it); the sensor reads a plane seen within it.
    """

    min_area_frac: float = 150.0 / 800.0 ** 2
    min_rim_frac: float = 30.0 / 800.0
    min_touch_frac: float = 4.0 / 800.0
    min_contact: float = 0.25
    min_fill: float = 0.85
    max_fill: float = 1.15
    min_support: float = 0.55
    max_taken: float = 0.3
    graze_deg: float = _UNREAD_DEG

    def __post_init__(self) -> None:
        check_ranges(self, fractions=("min_area_frac", "min_rim_frac", "min_touch_frac", "min_contact", "min_fill",
                                      "min_support", "max_taken"),
                     positive=("max_fill",), acute=("graze_deg",))
        if not self.min_fill <= self.max_fill:
            raise ValueError(f"min_fill must not exceed max_fill, got {self.min_fill!r} and {self.max_fill!r}")


HOLES = HoleSettings()


@dataclass(frozen=True)
class UnreadSettings:
    """When a hole beside an object is a face that depth alone did not read (:func:`unread_faces`).

    ``min_graze_deg`` (degrees from face-on): the plane of the hole's rim must be seen at least this obliquely; a
    RealSense reads to about 78 degrees, so a plane seen within 70 is one the sensor reads, and cannot be why
    there is a hole.
    ``min_apart_deg`` (degrees): the rim's plane must stand this far from every plane already known (the
    object's and the support's): a hole on a face or on the table has that surface's plane as its rim.
    ``min_on_plane`` (fraction of the rim's read pixels): the share that must lie on one plane; a face's
    readings stop at its own edges, so most of its rim is on its plane.
    ``max_on_object`` (fraction of the pixels around the hole): the object may make at most this share of what
    surrounds the hole; a face seen edge-on lies along the silhouette, a hole the object surrounds is a blob on
    one of its faces.
    ``max_planes`` (planes): a hole that runs into another (two faces seen edge-on side by side) has this many
    planes peeled off its rim at most.
    ``max_behind`` (multiples of the object's extent): a rim plane whose readings lie (median) farther behind
    the object's median depth than this is no face of it: a Kinect's veil of mixed pixels between an object's
    edge and the background, or the two sides of an occlusion shadow, reach from the object's edge to the
    surface behind it, tens of centimetres away, where a face of the object lies within its own size.
    """

    min_graze_deg: float = _UNREAD_DEG
    min_apart_deg: float = 20.0
    min_on_plane: float = 0.6
    max_on_object: float = 0.55
    max_planes: int = 3
    max_behind: float = 1.0

    def __post_init__(self) -> None:
        check_ranges(self, acute=("min_graze_deg", "min_apart_deg"), fractions=("min_on_plane", "max_on_object"),
                     counts={"max_planes": 0}, positive=("max_behind",))


UNREAD = UnreadSettings()


def hole_sizes(shape: tuple[int, ...], settings: HoleSettings = HOLES) -> tuple[float, int, int]:
    """(least hole area px, least read rim px, least contact px) for an image of ``shape`` (H, W, ...)."""
    d = float(np.hypot(shape[0], shape[1]))
    return (settings.min_area_frac * d * d, int(np.ceil(settings.min_rim_frac * d - 1e-9)),
            int(np.ceil(settings.min_touch_frac * d - 1e-9)))


def hole_faces(no_reading: np.ndarray, object_px: np.ndarray, edge_dist: np.ndarray, min_area_px: float,
               settings: HoleSettings = HOLES) -> list[np.ndarray]:
    """Polygons (n, 2) pixels, clockwise, of the faces that are holes in the depth image, all in one crop.

    ``no_reading``: (H, W) bool, pixels without a depth reading; ``object_px``: (H, W) bool, the depth object's
    pixels; ``edge_dist``: (H, W) float, distance (px) to the nearest colour edge pixel; ``min_area_px``: the
    least hole area (:func:`hole_sizes` of the whole image). A hole qualifies when it is one of
    :func:`hole_regions` and at least ``settings.min_support`` of its polygon's outline is on colour edges."""
    return [poly for poly, _ in hole_regions(no_reading, object_px, min_area_px, settings)
            if edge_support(poly, edge_dist) >= settings.min_support]


def hole_regions(no_reading: np.ndarray, object_px: np.ndarray, min_area_px: float,
                 settings: HoleSettings = HOLES) -> list[tuple[np.ndarray, np.ndarray]]:
    """The holes in the depth image (H, W) that may be faces, as (polygon (n, 2) pixels clockwise, region (H, W)
    bool): connected regions of ``no_reading`` outside ``object_px`` (both (H, W) bool) of at least
    ``min_area_px``, at least ``settings.min_contact`` of whose outline pixels touch the object, not touching the
    crop's border (the object or the hole is cut off there), whose area over their polygon's is within
    ``settings.min_fill`` and ``max_fill`` (a convex region)."""
    return _holes(no_reading, object_px, min_area_px, settings)[0]


def _holes(no_reading: np.ndarray, object_px: np.ndarray, min_area_px: float, settings: HoleSettings = HOLES
           ) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[np.ndarray]]:
    """The regions of ``no_reading`` along the object as :func:`hole_regions` takes them, and the regions (H, W)
    bool it leaves (touching the crop's border, or not convex)."""
    h, w = no_reading.shape
    near_obj = cv2.dilate(object_px.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    n, lab, stats, _ = cv2.connectedComponentsWithStats((no_reading & ~object_px).astype(np.uint8), connectivity=8)
    taken, left = [], []
    for k in range(1, n):
        x, y, bw, bh, a = stats[k]
        if a < min_area_px:
            continue
        m = lab[y:y + bh, x:x + bw] == k
        ring = m & ~cv2.erode(m.astype(np.uint8), np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT,
                              borderValue=0).astype(bool)
        touching = np.count_nonzero(ring & near_obj[y:y + bh, x:x + bw])
        if touching < settings.min_contact * max(1, np.count_nonzero(ring)):
            continue
        poly = None if x == 0 or y == 0 or x + bw >= w or y + bh >= h else _outline(m)
        if poly is not None:
            poly += np.array([x, y], float)
            if not settings.min_fill <= a / max(area(poly), 1e-9) <= settings.max_fill:
                poly = None
        region = lab == k
        if poly is None:
            left.append(region)
        else:
            taken.append((poly, region))
    return taken, left


class UnreadFace(NamedTuple):
    """A face depth did not read (:func:`unread_faces`): its ``polygon`` (n, 2) pixels, the ``plane`` through its
    rim, the rim ``points`` (m, 3) metres on that plane, their RMS distance ``rms_m`` to it, and the indices of the
    object's planes it meets (``neighbours``)."""

    polygon: np.ndarray
    plane: Plane
    points: np.ndarray
    rms_m: float
    neighbours: list[int]


def unread_faces(depth: np.ndarray, grid: PointGrid, object_px: np.ndarray, plane_masks: list[np.ndarray],
                 known: list[Plane], box: tuple[int, int, int, int], seed: int = 0,
                 reach: tuple[float, float] | None = None, settings: UnreadSettings = UNREAD,
                 holes: HoleSettings = HOLES, sensor: SensorNoise = SENSOR) -> list[UnreadFace]:
    """Faces of one object that depth alone infers from the holes beside it where no colour confirms them: the
    readings stop at a face's own edges, on the object's neighbouring faces and on the table, so the points just
    outside a hole that is an unread face lie on the face's plane.

    A hole of :func:`hole_regions` is taken for a face (thresholds: ``settings``, :class:`UnreadSettings`) when at
    least ``min_on_plane`` of its rim points (read pixels within 2 px of it, at least the least rim of
    :func:`hole_sizes`) lie on one plane (RANSAC within the inlier distance of ``sensor`` at their depth) that is
    seen at ``min_graze_deg`` or more from face-on (a plane the sensor reads well cannot be the reason for a hole:
    a blob of missing readings on a face or on the table has that face's or the table's plane as its rim) and
    stands at least ``min_apart_deg`` from every plane in ``known`` (the object's planes and the support), and
    when the object makes at most ``max_on_object`` of what surrounds it (a face seen edge-on lies along the
    object's silhouette; a hole the object surrounds is a blob on one of its faces).
    With ``reach`` (the median depth and the extent of the object's points, metres), a plane whose rim points lie
    (median) farther behind the object's median depth than ``max_behind`` times its extent is no face of it: a
    Kinect's veil of mixed pixels between an object's edge and the background, or the two sides of an occlusion
    shadow, reach from the object's edge to the surface behind it, tens of centimetres away.

    A hole that runs into another (two faces seen edge-on side by side, or a face and a blob of missing readings)
    is not convex, or reaches the crop's border: up to ``max_planes`` planes are peeled off its rim, and each that
    passes those tests gives the face where the hole lies within the hull of that plane's rim points, when that
    part is itself a hole :func:`hole_regions` would take.

    ``depth``: (H, W) metres (0 = no reading); ``grid``: its point grid; ``object_px``: (v1 - v0, u1 - u0) bool,
    the object's pixels in ``box`` = (u0, v0, u1, v1); ``plane_masks``: the object's planes' grid masks, for the
    planes each face meets (at least the least contact of :func:`hole_sizes` in rim points on a plane's mask).
    ``holes``: which regions without readings may be faces. Polygons are in full-frame pixels."""
    min_graze_deg, min_apart_deg, max_behind = settings.min_graze_deg, settings.min_apart_deg, settings.max_behind
    min_on_plane, max_on_object, max_planes = settings.min_on_plane, settings.max_on_object, settings.max_planes
    min_area_px, min_rim, min_contact = hole_sizes(depth.shape, holes)
    u0, v0, u1, v1 = box
    crop = depth[v0:v1, u0:u1]
    read = np.isfinite(crop) & (crop > 0)
    rng = np.random.default_rng(seed)
    s = grid.stride
    off = np.array([u0, v0], float)
    ring = np.ones((2 * _RIM_PX + 1, 2 * _RIM_PX + 1), np.uint8)

    def rim(region: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """The read pixels (v, u) around ``region``, their grid cells (i, j) and points (m, 3); None when the
        object surrounds it."""
        around = cv2.dilate(region.astype(np.uint8), ring).astype(bool) & ~region
        if np.count_nonzero(around & object_px) > max_on_object * np.count_nonzero(around):
            return None
        vv, uu = np.nonzero(around & read)
        i, j = np.minimum((vv + v0) // s, grid.shape[0] - 1), np.minimum((uu + u0) // s, grid.shape[1] - 1)
        ok = grid.valid[i, j]
        return vv[ok], uu[ok], np.stack([i[ok], j[ok]]), grid.xyz[i[ok], j[ok]].astype(np.float64)

    def face_plane(pts: np.ndarray, need: int) -> tuple[Plane, np.ndarray] | None:
        """The plane of the most of ``pts`` and its inliers, when at least ``need`` and a plane depth missed."""
        plane, inl = ransac_plane(pts, sensor.inlier_m(float(np.median(pts[:, 2]))), rng)
        if np.count_nonzero(inl) < max(need, 3):
            return None
        ray = column_means(pts[inl])  # the angle it is seen at, from face-on
        if np.degrees(np.arccos(min(1.0, abs(float(plane.n @ ray)) / float(np.linalg.norm(ray))))) < min_graze_deg:
            return None
        if any(angle_deg(plane, q) < min_apart_deg for q in known):
            return None
        if reach is not None and float(np.median(pts[inl, 2])) - reach[0] > max_behind * reach[1]:
            return None
        return plane, inl

    def face(poly: np.ndarray, plane: Plane, pts: np.ndarray, ij: np.ndarray) -> UnreadFace:
        rms = float(np.sqrt(np.mean(plane.distance(pts) ** 2)))
        meets = [k for k, m in enumerate(plane_masks) if np.count_nonzero(m[ij[0], ij[1]]) >= min_contact]
        return UnreadFace(poly + off, plane, pts, rms, meets)

    out = []
    convex, merged = _holes(~read, object_px, min_area_px, holes)
    for poly, region in convex:
        r = rim(region)
        if r is None or len(r[3]) < min_rim:
            continue
        found = face_plane(r[3], int(np.ceil(min_on_plane * len(r[3]))))
        if found is not None:
            plane, inl = found
            out.append(face(poly, plane, r[3][inl], r[2][:, inl]))
    for region in merged:
        r = rim(region)
        if r is None:
            continue
        vv, uu, ij, pts = r
        for _ in range(max_planes):
            if len(pts) < min_rim:
                break
            found = face_plane(pts, min_rim)
            if found is None:
                break
            plane, inl = found
            hull = np.zeros(read.shape, np.uint8)
            cv2.fillPoly(hull, [cv2.convexHull(np.stack([uu[inl], vv[inl]], axis=1).astype(np.int32))], 1)
            part = hole_regions(region & hull.astype(bool), object_px, min_area_px, holes)
            if len(part) == 1 and rim(part[0][1]) is not None:
                known = known + [plane]
                out.append(face(part[0][0], plane, pts[inl], ij[:, inl]))
            vv, uu, ij, pts = vv[~inl], uu[~inl], ij[:, ~inl], pts[~inl]
    return out


def add_hole_faces(faces: list[Face], pairs: set[tuple[int, int]], keep: list[int], frame: RGBD,
                   box: tuple[int, int, int, int], object_px: np.ndarray, edge_dist: np.ndarray,
                   masks: dict[int, np.ndarray] | None = None, unread: list[UnreadFace] = (),
                   min_unread_support: float = 0.5, settings: HoleSettings = HOLES) -> list[int]:
    """The faces depth has no reading of, appended to ``faces``: first the ``unread`` faces (:func:`unread_faces`,
    full-frame polygons, each with the plane through its rim) whose outline lies on colour edges for at least
    ``min_unread_support`` of its length, with provenance 'rgbd'; then the holes whose outline colour edges confirm
    (:func:`hole_faces`) where no face lies yet, with provenance 'rgb' (no plane), unless such a hole is the unread
    rest of a face the sensor read at a grazing angle (:func:`_extend`: that face then covers it). Each added face
    is made a neighbour (in ``pairs``) of the kept faces it touches. Returns their indices.
    ``box``: the crop (u0, v0, u1, v1) pixels that ``object_px`` (the object's pixels) and ``edge_dist`` cover;
    ``masks``: the ``keep`` faces' masks in that crop when the caller has them already (index -> (H, W) bool;
    updated in place), else they are drawn here.

    A hole that the kept faces cover for at most ``settings.max_taken`` of its pixels is a face beside them;
    otherwise a face there was found already (``settings``: :class:`HoleSettings`)."""
    u0, v0, u1, v1 = box
    depth = frame.depth[v0:v1, u0:u1]
    no_reading = ~(np.isfinite(depth) & (depth > 0))
    if not no_reading.any():
        return []
    off = np.array([u0, v0], float)
    shape = no_reading.shape
    if masks is None:
        masks = {i: rasterize(faces[i].polygon - off, shape) for i in keep}
    added = []
    # an unread face needs colour edges along more of its outline than the object's side alone: a sensor's
    # occlusion shadow beside an object (a band without readings that depth alone takes for a face) has none where
    # it crosses the table. One that colour confirms comes first: it has a plane, a colour hole there has none
    found = [(u.polygon - off, Face("", u.polygon, "rgbd", plane=u.plane, points=u.points, plane_rms_m=u.rms_m))
             for u in unread if edge_support(u.polygon - off, edge_dist) >= min_unread_support]
    min_area_px, _, touch = hole_sizes(frame.shape, settings)
    found += [(poly, Face("", poly + off, "rgb"))
              for poly in hole_faces(no_reading, object_px, edge_dist, min_area_px, settings)]
    for poly, face in found:
        hole = rasterize(poly, shape)
        a = max(1, np.count_nonzero(hole))
        cover = {i: np.count_nonzero(hole & m) for i, m in masks.items()}
        if sum(cover.values()) > settings.max_taken * a:
            continue  # a face there was found already
        grown = cv2.dilate(hole.astype(np.uint8), np.ones((2 * _RIM_PX + 1, 2 * _RIM_PX + 1), np.uint8)).astype(bool)
        if face.plane is None and _extend(faces, masks, hole, grown, off, touch, settings):
            continue
        new = len(faces)
        faces.append(face)
        pairs |= {(i, new) for i, m in masks.items() if np.count_nonzero(grown & m) >= touch}
        masks[new] = hole
        added.append(new)
    return added


def _extend(faces: list[Face], masks: dict[int, np.ndarray], hole: np.ndarray, grown: np.ndarray, off: np.ndarray,
            touch: int, settings: HoleSettings = HOLES) -> bool:
    """Extends over ``hole`` (a region without readings, crop pixels; ``grown``: it dilated) the one face it touches
    (along ``touch`` px or more) whose plane is seen at ``settings.graze_deg`` or more from face-on, when the two
    make one convex region (their union over its hull's area within ``settings.min_fill`` and ``max_fill``): the
    sensor read that face on part of it only, and the hole is the rest of it, not a face of its own. Updates the
    face's polygon and ``masks`` in place; True when it did."""
    touching = [i for i, m in masks.items() if np.count_nonzero(grown & m) >= touch]
    grazing = [i for i in touching if faces[i].plane is not None and faces[i].points is not None
               and len(faces[i].points) and _graze_deg(faces[i]) >= settings.graze_deg]
    if len(grazing) != 1:
        return False
    i = grazing[0]
    union = masks[i] | hole
    # the closing fills the rim of a pixel or two the two outlines may leave between them
    union = cv2.morphologyEx(union.astype(np.uint8), cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8)).astype(bool)
    poly = _outline(union)
    if poly is None or not settings.min_fill <= np.count_nonzero(union) / max(area(poly), 1e-9) <= settings.max_fill:
        return False
    faces[i].polygon = poly + off
    masks[i] = rasterize(poly, hole.shape)
    return True


def _graze_deg(face: Face) -> float:
    """The angle (degrees) from face-on at which the camera sees ``face``'s plane, at its points' centroid."""
    ray = np.asarray(face.points, np.float64).mean(axis=0)
    return float(np.degrees(np.arccos(min(1.0, abs(float(face.plane.n @ ray)) / float(np.linalg.norm(ray))))))


def _outline(mask: np.ndarray, eps_frac: float = 0.02) -> np.ndarray | None:
    """The corners of a convex pixel region (h, w) bool, in its own coordinates: the hull of its contour,
    simplified with a tolerance that stays under a fifth of the region's width (a grazing face is a strip a
    few px wide whose corners must not collapse). Pixel (u, v) spans [u - 0.5, u + 0.5], so the hull is grown
    by half a pixel."""
    c, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not c:
        return None
    hull = cv2.convexHull(max(c, key=cv2.contourArea)).astype(np.float32)
    peri = cv2.arcLength(hull, True)
    short_side = min(cv2.minAreaRect(hull)[1])
    eps = max(1.0, min(eps_frac * peri, 0.2 * short_side))
    approx = cv2.approxPolyDP(hull, eps, True).reshape(-1, 2).astype(np.float64)
    if len(approx) < 3:
        return None
    # no further simplify: its relative tolerance and minimum turn cut a strip's short ends (a few px off the
    # chord of a long side, turning little)
    poly = clockwise(drop_short_sides(approx))
    return clockwise(grow_convex(poly, 0.5)) if len(poly) >= 3 else None
