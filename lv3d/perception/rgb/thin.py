"""Thin faces between found faces and a long outer edge beside them, which the planar graph cannot trace.

A face seen almost edge-on is a sliver a few pixels wide. Its long sides are nearly parallel, so the graph never
joins them (segments meet only at least ``min_angle_deg`` apart), and its short ends are shorter than the
distance at which the graph merges junctions, so its corners collapse into its neighbours' and the face is lost.
Its inner side is the outline of faces already found; its outer side is one long segment, or two meeting at a
slight kink (the sliver's own corner), on the silhouette or another face's edge. The sliver is closed directly:
the corners of found faces lying a few pixels to one side of the outer edge, the kink, and the extreme corners
projected onto the outer edge.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..edges import edge_distance, edge_support
from ..polygons import (area, clockwise, distance_to_segments, is_simple, mean_width, pixel_values, rasterize,
                       sample_boundary)


def outline_distance_map(polys: list[np.ndarray], shape: tuple[int, int]) -> np.ndarray:
    """Distance (H, W) float32 in pixels from each pixel to the nearest outline of ``polys`` (one distance
    transform: looked up for many points, far cheaper than a point-polygon test each)."""
    lines = np.zeros(shape, np.uint8)
    cv2.polylines(lines, [np.round(p).astype(np.int32) for p in polys], True, 1, 1)
    return edge_distance(lines)


def _to_polyline(pts: np.ndarray, line: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For points (m, 2) and a polyline (k, 2): the arc-length position (m,) of each point's projection on the
    nearest piece's line, its signed distance (m,) from that line (positive to the left of the direction of
    travel, v down), and the nearest piece's index (m,)."""
    a, b = line[:-1], line[1:]
    d = b - a
    L = np.hypot(d[:, 0], d[:, 1])
    u = d / L[:, None]
    rel = pts[:, None, :] - a[None]
    t = (rel * u[None]).sum(-1)                                  # (m, pieces) along each piece's line
    off = rel[..., 0] * -u[None, :, 1] + rel[..., 1] * u[None, :, 0]
    gap = np.maximum(np.maximum(-t, t - L[None]), 0.0)           # beyond the piece's ends
    piece = np.argmin(np.abs(off) + gap, axis=1)
    rows = np.arange(len(pts))
    start = np.concatenate([[0.0], np.cumsum(L)[:-1]])
    return start[piece] + t[rows, piece], off[rows, piece], piece


def _outer_edges(segs: np.ndarray, length: np.ndarray, min_len_px: float, min_kink_deg: float,
                 max_kink_deg: float, join_px: float) -> list[np.ndarray]:
    """Candidate outer edges, longest first: every segment at least ``min_len_px`` long as a polyline of two
    points, and every pair of such segments turning by ``min_kink_deg`` to ``max_kink_deg`` whose lines cross
    within ``join_px`` of an end of each, as a polyline of three (far end, crossing, far end)."""
    idx = np.array([int(i) for i in np.argsort(-length, kind="stable") if length[i] >= min_len_px], int)
    out = [(float(length[i]), segs[i].reshape(2, 2)) for i in idx]
    # a kink within join_px of an end of each: only pairs with ends within 2 join_px of each other
    ends = segs[idx].reshape(-1, 2, 2)
    gap = np.hypot(*(ends[:, None, :, None, :] - ends[None, :, None, :, :]).transpose(4, 0, 1, 2, 3))
    n, m = np.nonzero(np.triu(gap.min(axis=(2, 3)) <= 2.0 * join_px, 1))
    if len(n):
        ei, ej = ends[n], ends[m]                                   # (k, 2, 2)
        ui, uj = ei[:, 1] - ei[:, 0], ej[:, 1] - ej[:, 0]
        c = ui[:, 0] * uj[:, 1] - ui[:, 1] * uj[:, 0]
        w = ej[:, 0] - ei[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            x = ei[:, 0] + ((w[:, 0] * uj[:, 1] - w[:, 1] * uj[:, 0]) / c)[:, None] * ui
        # the end of each segment nearest the crossing meets the other; the far ends bound the edge
        di, dj = np.hypot(*(ei - x[:, None]).transpose(2, 0, 1)), np.hypot(*(ej - x[:, None]).transpose(2, 0, 1))
        ni, nj = np.argmin(di, axis=1), np.argmin(dj, axis=1)
        rows = np.arange(len(n))
        far_i, far_j = ei[rows, 1 - ni], ej[rows, 1 - nj]
        into, out_of = x - far_i, far_j - x
        cos = (into * out_of).sum(1) / np.maximum(np.hypot(*into.T) * np.hypot(*out_of.T), 1e-9)
        turn = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
        ok = (np.abs(c) > 1e-9) & (di[rows, ni] <= join_px) & (dj[rows, nj] <= join_px) & \
             (turn >= min_kink_deg) & (turn <= max_kink_deg)
        for k in np.nonzero(ok)[0]:
            out.append((float(length[idx[n[k]]] + length[idx[m[k]]]), np.array([far_i[k], x[k], far_j[k]])))
    out.sort(key=lambda e: -e[0])
    return [line for _, line in out]


def thin_faces(segs: np.ndarray, dist: np.ndarray, found: list[np.ndarray], min_area_px: float = 150.0,
               min_len_px: float = 30.0, min_gap_px: float = 2.5, max_gap_px: float = 16.0,
               reach_px: float = 10.0, far_reach_px: float = 40.0, rel_reach: float = 0.35,
               min_kink_deg: float = 2.0, max_kink_deg: float = 30.0, min_support: float = 0.8,
               max_overlap: float = 0.35, min_on_edge: float = 0.6, min_inner: float = 0.75,
               max_width_px: float = 12.0) -> list[np.ndarray]:
    """Polygons (clockwise, pixels, the frame of ``segs`` (n, 4)) of thin faces beside the ``found`` polygons.

    An outer edge is a segment at least ``min_len_px`` long, or two such meeting at a kink of ``min_kink_deg``
    to ``max_kink_deg``; one that mostly runs along a found outline is skipped. The found corners up to
    ``max_gap_px`` to one side of it (within its extent, ``reach_px`` beyond its ends or up to
    ``min(far_reach_px, rel_reach * length)``: LSD stops short where a sliver narrows), its kink, and the two
    extreme corners projected onto it make the sliver (their convex hull), which needs three corners or more
    and to be ``min_gap_px`` wide or more (a corner that far off the edge, or the kink that far off the found
    outlines). Kept when at least ``min_area_px``, simple, no wider
    than ``max_width_px`` (twice its area over its perimeter), overlapping the found polygons by under
    ``max_overlap`` of its area, its outer side seen by the segments for ``min_on_edge`` of its length, the rest
    of its outline on found outlines for ``min_inner`` (a sliver between faces and an edge, not a stripe of
    table or a stick lying between two faces), and ``min_support`` of its outline on image edges (``dist``:
    (H, W) distance to the nearest edge pixel). Longest outer edges first; a sliver overlapping one kept
    before is dropped."""
    if len(segs) == 0 or not found:
        return []
    shape = dist.shape
    corners = np.unique(np.round(np.concatenate(found, axis=0), 3), axis=0)
    occupied = None  # the found polygons' pixels, drawn only once a sliver gets that far
    to_found = outline_distance_map(found, shape)
    length = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    # a segment with no found corner near its line and extent bounds no sliver, alone or kinked: skip it early
    u = (segs[:, 2:] - segs[:, :2]) / np.maximum(length, 1e-9)[:, None]
    rel = corners[None] - segs[:, None, :2]
    t = (rel * u[:, None]).sum(-1)
    off = rel[..., 0] * -u[:, None, 1] + rel[..., 1] * u[:, None, 0]
    useful = ((np.abs(off) <= max_gap_px) & (t >= -far_reach_px) & (t <= length[:, None] + far_reach_px)).any(1)
    # nor does a found face's own side (most segments are): nothing thin lies beyond it
    frac = np.linspace(0.0, 1.0, 9)
    along = segs[:, None, :2] + frac[None, :, None] * (segs[:, None, 2:] - segs[:, None, :2])
    on_side = np.mean(pixel_values(to_found, along.reshape(-1, 2)).reshape(len(segs), -1) <= 1.5, axis=1) > 0.5
    length = np.where(useful & ~on_side, length, 0.0)
    out: list[np.ndarray] = []
    for line in _outer_edges(segs, length, min_len_px, min_kink_deg, max_kink_deg, reach_px):
        total = float(np.hypot(*np.diff(line, axis=0).T).sum())
        reach = max(reach_px, min(far_reach_px, rel_reach * total))
        s, off, piece = _to_polyline(corners, line)
        near = (s >= -reach) & (s <= total + reach) & (np.abs(off) <= max_gap_px)
        if np.count_nonzero(near) < 2:
            continue
        side = 1.0 if np.count_nonzero(near & (off > 0)) >= np.count_nonzero(near & (off < 0)) else -1.0
        sel = near & (side * off >= -1.0)
        pts, s_sel, piece_sel = corners[sel], s[sel], piece[sel]
        # the sliver's width: its corners' distance from the edge, or its kink's from the found outlines
        kink = float(pixel_values(to_found, line[1:-1]).max()) if len(line) > 2 else 0.0
        width = max(float((side * off[sel]).max()), kink)
        if len(pts) + len(line) - 2 < 3 or width < min_gap_px:
            continue
        ends = []
        for k in (int(np.argmin(s_sel)), int(np.argmax(s_sel))):
            a, b = line[piece_sel[k]], line[piece_sel[k] + 1]
            u = (b - a) / np.hypot(*(b - a))
            ends.append(a + ((pts[k] - a) @ u) * u)
        hull = cv2.convexHull(np.concatenate([pts, line[1:-1], ends]).astype(np.float32)).reshape(-1, 2)
        hull = hull.astype(np.float64)
        keep = [k for k in range(len(hull)) if np.hypot(*(hull[k] - hull[k - 1])) > 2.0]
        poly = clockwise(hull[keep])
        if len(poly) < 3 or area(poly) < min_area_px or not is_simple(poly) \
                or mean_width(poly) > max_width_px:
            continue
        if not _sides_seen(poly, line, segs, to_found, min_on_edge, min_inner):
            continue
        if occupied is None:
            occupied = np.zeros(shape, bool)
            for f in found:
                occupied |= rasterize(f, shape)
        m = rasterize(poly, shape)
        if np.count_nonzero(m & occupied) > max_overlap * max(1, np.count_nonzero(m)):
            continue
        if edge_support(poly, dist) < min_support:
            continue
        out.append(poly)
        occupied |= m
    return out


def _sides_seen(poly: np.ndarray, line: np.ndarray, segs: np.ndarray, to_found: np.ndarray,
                min_on_edge: float, min_inner: float, tol_px: float = 2.0) -> bool:
    """True when the part of ``poly``'s outline on the outer edge ``line`` lies within ``tol_px`` of a segment
    for ``min_on_edge`` of its length, and the rest of it on the found outlines (``to_found``: (H, W) distance
    to them) for ``min_inner``."""
    pts = sample_boundary(poly, 1.0)
    _, off, _ = _to_polyline(pts, line)
    outer = np.abs(off) <= tol_px
    if not outer.any() or outer.all():
        return False
    to_seg = distance_to_segments(pts[outer], segs[:, :2], segs[:, 2:] - segs[:, :2])
    if np.mean(to_seg <= tol_px) < min_on_edge:
        return False
    return bool(np.mean(pixel_values(to_found, pts[~outer]) <= tol_px) >= min_inner)
