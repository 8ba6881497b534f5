"""Faces of the background, told by their colour: a colour-only face whose chromaticity is the chromaticity of the
image's border (the floor, the wall, their texture and the shadows cast on them) is not a face of the object.

Without depth, a textured floor closes cycles of its own against the object's outline (strips between the
silhouette and a ripple of the texture, a shadow, a painted line), and they group with the object's faces. Their
chromaticity (each channel over the sum of the three) is the floor's, whatever their shading: a shadow darkens the
floor but keeps its hue. The object's own faces, whatever their shading, keep the object's.

An object may be of the floor's own hue, though (a wooden block on a wooden table). Its faces are then told by
their texture: a flat-shaded face is smoother than the floor of its hue around it, whose grain, ripples and shadow
edges go on under a shadow or a strip cut off by the texture (smooth_faces).
"""

from __future__ import annotations

import cv2
import numpy as np

from ..polygons import rasterize


def chromaticity(color: np.ndarray) -> np.ndarray:
    """(H, W, 2) float32: the red and green share of each pixel of ``color`` (H, W, 3) uint8 RGB in its sum."""
    c = color.astype(np.float32)
    total = c[..., 0] + c[..., 1] + c[..., 2]  # c.sum(axis=2), the same numbers, a fraction of its cost on an image
    return c[..., :2] / np.maximum(total, 1.0)[..., None]


def border_chromaticity(chroma: np.ndarray, band_px: int = 8, stride: int = 2) -> np.ndarray:
    """(n, 2): the chromaticity of every ``stride``-th pixel in the band ``band_px`` wide along the image's border."""
    b = band_px
    parts = [chroma[:b], chroma[-b:], chroma[b:-b, :b], chroma[b:-b, -b:]]
    return np.concatenate([p[::stride, ::stride].reshape(-1, 2) for p in parts])


def face_chromaticity(poly: np.ndarray, chroma: np.ndarray, erode_px: int = 2, min_px: int = 20) -> np.ndarray:
    """(2,): the median chromaticity of the pixels inside ``poly`` (n, 2) pixels, ``erode_px`` clear of its outline
    (blur mixes the neighbours' colours in there), or of all its pixels where fewer than ``min_px`` are clear."""
    h, w = chroma.shape[:2]
    lo = np.maximum(np.floor(poly.min(axis=0)).astype(int) - 1, 0)
    hi = np.minimum(np.ceil(poly.max(axis=0)).astype(int) + 2, [w, h])
    mask = np.zeros((hi[1] - lo[1], hi[0] - lo[0]), np.uint8)
    cv2.fillPoly(mask, [np.round(poly - lo).astype(np.int32)], 1)
    inner = cv2.erode(mask, np.ones((2 * erode_px + 1, 2 * erode_px + 1), np.uint8))
    pick = inner if np.count_nonzero(inner) >= min_px else mask
    pixels = chroma[lo[1]:hi[1], lo[0]:hi[0]][pick.astype(bool)]
    return np.median(pixels, axis=0) if len(pixels) else np.full(2, np.nan)


def log_gradient(color: np.ndarray) -> np.ndarray:
    """(H, W) float32: the gradient magnitude of log grey level of ``color`` (H, W, 3) uint8 RGB (Sobel, per px):
    a texture's contrast whatever the shading that scales it."""
    grey = np.log(cv2.cvtColor(color, cv2.COLOR_RGB2GRAY).astype(np.float32) + 8.0)
    return np.hypot(cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3), cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)) / 8.0


def smooth_faces(polys: list[np.ndarray], hues: list[np.ndarray], which: list[bool], chroma: np.ndarray,
                 texture: np.ndarray, radius: float = 0.01, max_ratio: float = 0.2, erode_px: int = 2,
                 min_px: int = 20, min_reference_px: int = 200) -> list[bool]:
    """For each face ``polys[i]`` (n, 2) pixels with ``which[i]`` true: whether it is much smoother than the rest of
    the image of its chromaticity ``hues[i]``. Its mean ``texture`` (log_gradient) ``erode_px`` clear of its
    outline is at most ``max_ratio`` of the mean over the pixels within ``radius`` of its chromaticity in
    ``chroma`` (H, W, 2) that lie on none of ``polys`` (grown by ``erode_px``); at least ``min_px`` and
    ``min_reference_px`` pixels. False where ``which[i]`` is false.

    Why: on dev renders (seeds 200000+, 20 and 40 per class) the faces of objects of the table's hue that
    background_faces took for floor had a ratio of at most 0.01 on ``clean`` and 0.18-0.97 on ``mild``; the
    floor's own faces (shadows, strips cut by the grain) at least 0.58 on ``clean``, 0.39 on ``mild`` and 0.30 on
    ``realsense``, where image noise makes both alike and nothing is rescued."""
    h, w = chroma.shape[:2]
    k = np.ones((2 * erode_px + 1, 2 * erode_px + 1), np.uint8)
    on_faces = np.zeros((h, w), bool)
    masks = []
    for p, want in zip(polys, which):
        m = rasterize(p, (h, w))
        on_faces |= m
        masks.append(cv2.erode(m.view(np.uint8), k).view(bool) if want else None)
    free = ~cv2.dilate(on_faces.view(np.uint8), k).view(bool)
    # each channel as an image of its own: arithmetic on the interleaved channels' strided views costs twice as much
    red, green = np.ascontiguousarray(chroma[..., 0]), np.ascontiguousarray(chroma[..., 1])
    out = []
    for m, c in zip(masks, hues):
        if m is None or np.count_nonzero(m) < min_px or not np.isfinite(c).all():
            out.append(False)
            continue
        ref = free & (np.hypot(red - c[0], green - c[1]) <= radius)
        n_ref = np.count_nonzero(ref)
        out.append(bool(n_ref >= min_reference_px and texture[m].mean() <= max_ratio * texture[ref].mean()))
    return out


def background_faces(hues: list[np.ndarray], chroma: np.ndarray, radius: float = 0.01,
                     min_share: float = 0.1) -> list[bool]:
    """For each face's median chromaticity (2,) in ``hues`` (face_chromaticity in the image whose ``chromaticity``
    is ``chroma`` (H, W, 2)): whether the face is background, its chromaticity within ``radius`` of at least
    ``min_share`` of the border's pixels (border_chromaticity)."""
    border = border_chromaticity(chroma)
    out = []
    for c in hues:
        near = np.hypot(border[:, 0] - c[0], border[:, 1] - c[1]) <= radius
        out.append(bool(np.isfinite(c).all() and np.mean(near) >= min_share))
    return out
