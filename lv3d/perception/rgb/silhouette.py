"""Silhouettes told by colour: the outline of every region whose chromaticity is not the image border's, as line
segments for the planar graph.

Without depth, a solid's outline against the floor reaches the graph only where LSD finds it, and LSD loses it
where the floor's texture is as dark as the face, where a shadow meets a dark face, or where blur spreads a
corner. Its chromaticity (background.py) still tells the solid from the floor there, whatever the shading: the
floor, the wall, their texture and the shadows on them keep the chromaticity of the image's border. The regions
of other chromaticities, cleaned of specks, are the solids (and painted lines wider than a few pixels), whatever
the hues of their faces; each region's outline, simplified to a polygon and moved onto the image's edge, gives its
sides as segments. The regions also tell which faces can belong to one solid: faces on two regions never do
(solids.group_solids).

Before it is moved onto the edge, the outline lies outside the edges LSD finds by about a pixel where blur mixes
the colours across it, and by less on sharp images.
"""

from __future__ import annotations

import cv2
import numpy as np

from .background import border_chromaticity, chromaticity
from .step_edge import line_samples


def foreground(color: np.ndarray, radius: float = 0.02, min_share: float = 0.02, blur_px: float = 1.5,
               bin_size: float = 0.004, clean_px: int = 3) -> np.ndarray:
    """(H, W) uint8 mask, 1 where ``color`` (H, W, 3) uint8 RGB, blurred by ``blur_px`` (sigma), has a
    chromaticity farther than ``radius`` from all but ``min_share`` of the border band's pixels
    (background.border_chromaticity), opened and closed by a disc ``clean_px`` wide. Chromaticities are
    binned ``bin_size`` wide, so that the test is one look-up per pixel."""
    chroma = chromaticity(cv2.GaussianBlur(color, (0, 0), blur_px))
    border = border_chromaticity(chroma)
    nb = int(round(1.0 / bin_size)) + 1
    q = np.clip(np.round(border / bin_size).astype(np.int64), 0, nb - 1)
    hist = np.zeros((nb, nb), np.float32)
    np.add.at(hist, (q[:, 0], q[:, 1]), 1.0)
    r = int(np.ceil(radius / bin_size))
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1)).astype(np.float32)
    near = cv2.filter2D(hist, -1, disc, borderType=cv2.BORDER_CONSTANT)  # border pixels within radius, per bin
    background = near >= min_share * len(border)
    qp = np.clip(np.round(chroma / bin_size).astype(np.int64), 0, nb - 1)
    mask = (~background[qp[..., 0], qp[..., 1]]).astype(np.uint8)
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (clean_px, clean_px))
    return cv2.morphologyEx(cv2.morphologyEx(mask, cv2.MORPH_OPEN, k), cv2.MORPH_CLOSE, k)


def snap_to_edges(segs: np.ndarray, grad: np.ndarray, reach_px: float = 2.5, step_px: float = 0.5) -> np.ndarray:
    """Segments (n, 4) each moved along its normal, by at most ``reach_px`` in steps of ``step_px``, to where the
    mean of ``grad`` (H, W, gradient magnitude) along it, sampled bilinearly every pixel, is largest."""
    if not len(segs):
        return segs.copy()
    a, b = segs[:, :2], segs[:, 2:]
    pts, owner, count, nrm = line_samples(a, b, 1.0, 2.0)
    offsets = np.arange(-reach_px, reach_px + 1e-9, step_px)
    score = np.empty((len(offsets), len(segs)))
    g = np.ascontiguousarray(grad, np.float32)
    for k, off in enumerate(offsets):
        c = (pts + off * nrm[owner]).astype(np.float32)
        vals = cv2.remap(g, c[:, :1], c[:, 1:], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)[:, 0]
        score[k] = np.bincount(owner, weights=vals, minlength=len(segs)) / np.maximum(count, 1)
    shift = offsets[np.argmax(score, axis=0)][:, None] * nrm
    return np.hstack([a + shift, b + shift])


def silhouette_segments(mask: np.ndarray, grad: np.ndarray | None = None, min_area_px: float = 150.0,
                        tol_px: float = 2.0, min_len_px: float = 12.0, frame_px: int = 2) -> np.ndarray:
    """Segments (n, 4) pixels: the sides, at least ``min_len_px`` long, of the outline of each region of ``mask``
    (H, W) uint8 (``foreground``) of at least ``min_area_px``, simplified to a polygon within ``tol_px``
    (Douglas-Peucker), each moved onto the image's edge (``snap_to_edges``) where ``grad`` (H, W), the gradient
    magnitude, is given.
    Sides along the image's frame (within ``frame_px``) are left out: there the region is cut off, not outlined."""
    h, w = mask.shape[:2]
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    out = []
    for c in contours:
        if cv2.contourArea(c) < min_area_px:
            continue
        p = cv2.approxPolyDP(c, tol_px, True).reshape(-1, 2).astype(np.float64)
        if len(p) < 3:
            continue
        q = np.roll(p, -1, axis=0)
        sides = np.hstack([p, q])
        long_enough = np.hypot(*(q - p).T) >= min_len_px
        on_frame = np.zeros(len(p), bool)
        for axis, hi in ((0, w - 1), (1, h - 1)):
            on_frame |= (np.maximum(p[:, axis], q[:, axis]) <= frame_px)
            on_frame |= (np.minimum(p[:, axis], q[:, axis]) >= hi - frame_px)
        out.append(sides[long_enough & ~on_frame])
    segs = np.concatenate(out, axis=0) if out else np.zeros((0, 4))
    return snap_to_edges(segs, grad) if grad is not None else segs


def regions_of(polys: list[np.ndarray], mask: np.ndarray) -> list[int]:
    """For each polygon (n, 2) pixels: the label of the connected region of ``mask`` (H, W) uint8 that holds most
    of its pixels, or 0 where most of them are outside the mask."""
    n, labels = cv2.connectedComponents(mask, connectivity=8)
    h, w = mask.shape[:2]
    out = []
    for p in polys:
        lo = np.maximum(np.floor(p.min(axis=0)).astype(int), 0)
        hi = np.minimum(np.ceil(p.max(axis=0)).astype(int) + 1, [w, h])
        inside = np.zeros((hi[1] - lo[1], hi[0] - lo[0]), np.uint8)
        cv2.fillPoly(inside, [np.round(p - lo).astype(np.int32)], 1)
        counts = np.bincount(labels[lo[1]:hi[1], lo[0]:hi[0]][inside.astype(bool)], minlength=n)
        out.append(int(np.argmax(counts)) if counts.sum() else 0)
    return out
