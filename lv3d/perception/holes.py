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
"""

from __future__ import annotations

import cv2
import numpy as np

from ..rgbd import RGBD
from ..scene import Face
from .boundary import grow_convex
from .edges import edge_support
from .polygons import area, clockwise, drop_short_sides, rasterize


_FILL = (0.85, 1.15)  # region area over its polygon's area: a convex region that the polygon describes


def hole_faces(no_reading: np.ndarray, object_px: np.ndarray, edge_dist: np.ndarray, min_area_px: float = 150.0,
               min_contact: float = 0.25, min_support: float = 0.55,
               fill: tuple[float, float] = _FILL) -> list[np.ndarray]:
    """Polygons (n, 2) pixels, clockwise, of the faces that are holes in the depth image, all in one crop.

    ``no_reading``: (H, W) bool, pixels without a depth reading; ``object_px``: (H, W) bool, the depth object's
    pixels; ``edge_dist``: (H, W) float, distance (px) to the nearest colour edge pixel. A hole qualifies when
    its area is at least ``min_area_px``, at least ``min_contact`` of its outline pixels touch the object, it
    does not touch the crop's border (the object or the hole is cut off there), its area over its polygon's is
    within ``fill`` (a convex region), and at least ``min_support`` of its polygon's outline is on colour
    edges."""
    h, w = no_reading.shape
    near_obj = cv2.dilate(object_px.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    n, lab, stats, _ = cv2.connectedComponentsWithStats((no_reading & ~object_px).astype(np.uint8), connectivity=8)
    out = []
    for k in range(1, n):
        x, y, bw, bh, a = stats[k]
        if a < min_area_px or x == 0 or y == 0 or x + bw >= w or y + bh >= h:
            continue
        m = lab[y:y + bh, x:x + bw] == k
        ring = m & ~cv2.erode(m.astype(np.uint8), np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT,
                              borderValue=0).astype(bool)
        if np.count_nonzero(ring & near_obj[y:y + bh, x:x + bw]) < min_contact * max(1, np.count_nonzero(ring)):
            continue
        poly = _outline(m)
        if poly is None:
            continue
        poly += np.array([x, y], float)
        if not fill[0] <= a / max(area(poly), 1e-9) <= fill[1]:
            continue
        if edge_support(poly, edge_dist) < min_support:
            continue
        out.append(poly)
    return out


def add_hole_faces(faces: list[Face], pairs: set[tuple[int, int]], keep: list[int], frame: RGBD,
                   box: tuple[int, int, int, int], object_px: np.ndarray, edge_dist: np.ndarray,
                   max_taken: float = 0.3, max_share: float = 0.5,
                   masks: dict[int, np.ndarray] | None = None) -> list[int]:
    """Faces seen so edge-on that depth has no reading there (:func:`hole_faces`), appended to ``faces`` with
    provenance 'rgb' (the outline is checked on colour edges; no plane), each made a neighbour (in ``pairs``)
    of the kept faces it touches. Returns their indices. ``box``: the crop (u0, v0, u1, v1) pixels that
    ``object_px`` (the object's pixels) and ``edge_dist`` cover; ``masks``: the ``keep`` faces' masks in that crop
    when the caller has them already (index -> (H, W) bool; updated in place), else they are drawn here.

    A hole that the kept faces cover for at most ``max_taken`` of its pixels is a face beside them. One that a
    single kept face covers, as a part of at most ``max_share`` of that face, is a face the colour outline
    swallowed (the edge between them is faint where the grazing face is dark): that face gives the hole's
    pixels up when what is left is one convex region with fewer corners. Otherwise a face there was found
    already."""
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
    for poly in hole_faces(no_reading, object_px, edge_dist):
        hole = rasterize(poly, shape)
        a = max(1, np.count_nonzero(hole))
        cover = {i: np.count_nonzero(hole & m) for i, m in masks.items()}
        if sum(cover.values()) > max_taken * a:
            over = [i for i, c in cover.items() if c > max_taken * a]
            if len(over) != 1 or not _give_up(faces, masks, over[0], hole, off, max_share):
                continue
        grown = cv2.dilate(hole.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool)
        new = len(faces)
        faces.append(Face("", poly + off, "rgb"))
        pairs |= {(i, new) for i, m in masks.items() if np.count_nonzero(grown & m) >= 4}
        masks[new] = hole
        added.append(new)
    return added


def _give_up(faces: list[Face], masks: dict[int, np.ndarray], i: int, hole: np.ndarray, off: np.ndarray,
             max_share: float, fill: tuple[float, float] = _FILL) -> bool:
    """Cuts the ``hole`` pixels out of face ``i`` (its polygon and ``masks[i]``, in place) when they are at most
    ``max_share`` of it and the rest is one convex region with fewer corners; True when it did."""
    if np.count_nonzero(masks[i] & hole) > max_share * np.count_nonzero(masks[i]):
        return False
    # the opening removes the rim of a pixel or two that the two outlines leave between them
    rest = cv2.morphologyEx((masks[i] & ~hole).astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    n = np.count_nonzero(rest)
    poly = _outline(rest.astype(bool)) if n else None
    # two convex faces in one outline have more corners than either; a hole that only nicks a face's rim (a
    # strip of its own pixels lost at a grazing angle) leaves as many
    if poly is None or len(poly) >= len(faces[i].polygon) or not fill[0] <= n / max(area(poly), 1e-9) <= fill[1]:
        return False
    faces[i].polygon = poly + off
    masks[i] = rasterize(poly, hole.shape)
    return True


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
