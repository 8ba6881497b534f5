"""Faces of a solid that no traced face covers, from its silhouette: colour alone, what is left of a solid's
region (silhouette.foreground) once the faces found are taken out.

The planar graph traces a face only where segments close it. A face seen almost edge-on is a sliver whose corners
collapse into its neighbours' (thin.py closes it only where one segment, or two at a slight kink, runs along its
whole outer side), and a solid whose faces are of one shade shows LSD its outline in pieces that turn by a few
degrees where a face's edge would meet it, too little for the graph to join them. In both cases the solid's
region, told from the floor by chromaticity, still holds the face: the part of the region outside every found face
is its outline.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..boundary import grow_convex
from ..edges import edge_support
from ..polygons import area, clockwise, drop_short_sides, is_simple, mean_width, outline_distance, rasterize, simplify
from .split import reflex_corners
from .thin import outline_distance_map


def untraced_faces(solids: np.ndarray, found: list[np.ndarray], dist: np.ndarray, color: np.ndarray,
                   min_area_px: float = 150.0, max_area_px: float = np.inf, open_px: int = 3, touch_px: float = 2.5,
                   min_touch: float = 0.15, min_step: float = 8.0, grow_px: int = 3, tol_px: float = 1.0,
                   keep_area_frac: float = 0.25, max_thin_px: float = 12.0, min_support: float = 0.55,
                   frame_px: float = 3.0, whole_share: float = 0.9) -> list[np.ndarray]:
    """Polygons (clockwise, pixels) of the parts of ``solids`` (H, W) uint8 (silhouette.foreground) outside every
    ``found`` polygon, opened by a disc ``open_px`` wide (the strip of a pixel or two that the found outlines leave
    along the silhouette). ``color``: the (H, W, 3) image.

    A part must be ``min_area_px`` to ``max_area_px`` and surround nothing (a table is a region of its own colour
    with the solids on it as holes). Either it holds ``whole_share`` of a region of ``solids`` or more (a solid
    none of whose faces was traced), or it runs within ``touch_px`` of the found outlines for ``min_touch`` of its
    outline and its median colour is at least ``min_step`` (RGB levels) from that of every found face it touches (a
    strip of a found face that its traced outline left out is of that face's colour). Such a part is then grown by
    the pixels within ``grow_px`` of it nearer its colour than its neighbours' (a neighbour's traced outline may
    reach over part of a sliver).

    Its outline, simplified to its corners (Douglas-Peucker within ``tol_px``, then polygons.simplify keeping a
    corner that holds ``keep_area_frac`` of its area), must be simple, convex where it is at most ``max_thin_px``
    wide (a bent strip is a sliver run together with part of a traced face), on image edges for ``min_support``
    of its length (``dist``: (H, W) distance to the nearest edge pixel) and off the image's frame
    (``frame_px``). A convex outline is grown by half a pixel: the contour runs through the region's outer pixels'
    centres."""
    h, w = solids.shape[:2]
    whole = (solids > 0).astype(np.uint8)
    free = whole.copy()
    if found:
        cv2.fillPoly(free, [np.round(p).astype(np.int32) for p in found], 0)
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (open_px, open_px))
    free = cv2.morphologyEx(free, cv2.MORPH_OPEN, k)
    contours, hierarchy = cv2.findContours(free, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE)
    if not contours:
        return []
    hierarchy = hierarchy[0]
    n_regions, regions = cv2.connectedComponents(whole, connectivity=8)
    region_area = np.bincount(regions.ravel(), minlength=n_regions)
    to_found = None
    face_colour: dict[int, np.ndarray] = {}  # median colour of each found face, when needed
    out = []
    for c, (_, _, child, parent) in zip(contours, hierarchy):
        a = cv2.contourArea(c) + 0.5 * cv2.arcLength(c, True)  # its pixels: the contour runs through the outer ones
        if parent >= 0 or a < min_area_px or a > max_area_px:
            continue
        if _surrounds(contours, hierarchy, child, min_area_px):
            continue
        p = c.reshape(-1, 2)
        if (p.min(axis=0) <= frame_px).any() or (p.max(axis=0) >= np.array([w, h]) - 1 - frame_px).any():
            continue
        region = regions[p[0, 1], p[0, 0]]
        if a < whole_share * region_area[region]:  # part of a region: beside found faces, of its own colour
            if to_found is None:
                to_found = outline_distance_map(found, (h, w))
            if np.mean(to_found[p[:, 1], p[:, 0]] <= touch_px) < min_touch:
                continue
            beside = [i for i, q in enumerate(found) if np.any(outline_distance(p.astype(np.float64), q) <= touch_px)]
            if not beside:
                continue
            for i in beside:
                if i not in face_colour:
                    face_colour[i] = np.median(color[rasterize(found[i], (h, w))], axis=0)
            x, y, cw, ch = cv2.boundingRect(c)
            u0, v0 = max(0, x - grow_px - 1), max(0, y - grow_px - 1)
            u1, v1 = min(w, x + cw + grow_px + 1), min(h, y + ch + grow_px + 1)
            inside = np.zeros((v1 - v0, u1 - u0), np.uint8)
            cv2.drawContours(inside, [c - np.array([u0, v0])], -1, 1, -1)
            window = color[v0:v1, u0:u1].astype(np.float64)
            own = np.median(window[inside > 0], axis=0)
            sides = [face_colour[i] for i in beside]
            if min(float(np.linalg.norm(m - own)) for m in sides) < min_step:
                continue
            c = _grown(inside > 0, own, sides, window, solids[v0:v1, u0:u1], grow_px) + np.array([u0, v0])
        poly = cv2.approxPolyDP(c, tol_px, True).reshape(-1, 2).astype(np.float64)
        poly = clockwise(drop_short_sides(simplify(poly, keep_area_frac=keep_area_frac)))
        reflex = len(poly) >= 3 and bool(reflex_corners(poly))
        if reflex and mean_width(poly) <= max_thin_px:
            continue
        if len(poly) >= 3 and not reflex:
            poly = grow_convex(poly, 0.5)
        if len(poly) < 3 or not is_simple(poly) or area(poly) < min_area_px:
            continue
        if edge_support(poly, dist) < min_support:
            continue
        out.append(poly)
    return out


def _grown(inside: np.ndarray, own: np.ndarray, means: list[np.ndarray], color: np.ndarray, solids: np.ndarray,
           grow_px: int) -> np.ndarray:
    """The contour of the region ``inside`` (h, w) bool of median colour ``own`` in ``color`` (h, w, 3) float, grown
    by the pixels of ``solids`` (h, w) within ``grow_px`` of it nearer in colour to ``own`` than to every one of
    ``means`` (the median colours of the faces beside it, whose traced outlines may reach over part of it)."""
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow_px + 1, 2 * grow_px + 1))
    band = (cv2.dilate(inside.astype(np.uint8), k) > 0) & (solids > 0) & ~inside
    near_own = np.linalg.norm(color - own, axis=2)
    near_face = np.min([np.linalg.norm(color - m, axis=2) for m in means], axis=0)
    region = (inside | (band & (near_own < near_face))).astype(np.uint8)
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    return max(contours, key=cv2.contourArea)


def _surrounds(contours: list, hierarchy: np.ndarray, child: int, min_area_px: float) -> bool:
    """True when the outer contour whose first hole is ``child`` (cv2.RETR_CCOMP) has a hole of ``min_area_px``
    or more."""
    while child >= 0:
        if cv2.contourArea(contours[child]) >= min_area_px:
            return True
        child = hierarchy[child][0]
    return False
