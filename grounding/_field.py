"""Edge fields: images whose value is the signed distance (pixels) to the nearest image edge, zero on it.
Computed with OpenCV outside jit and handed to the refinement as a plain array."""

from __future__ import annotations

import cv2
import numpy as np


def _bilinear(img: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Bilinear samples of a (H, W) image at (n, 2) pixel positions, clamped to the image."""
    h, w = img.shape
    u = np.clip(uv[:, 0], 0, w - 1.001)
    v = np.clip(uv[:, 1], 0, h - 1.001)
    # floor in the positions' own dtype: mixing in int32 would promote float32 positions to float64
    u0, v0 = np.floor(u), np.floor(v)
    fu, fv = u - u0, v - v0
    flat, at = img.ravel(), v0.astype(np.int32) * w + u0.astype(np.int32)
    top = flat[at] * (1 - fu) + flat[at + 1] * fu
    bottom = flat[at + w] * (1 - fu) + flat[at + w + 1] * fu
    return top * (1 - fv) + bottom * fv


Box = tuple[float, float, float, float]


def edge_distance_field(image: np.ndarray, *, low: float = 20.0, high: float = 60.0, cap_px: float = 30.0,
                        roi: Box | list[Box] | None = None) -> np.ndarray:
    """Signed distance (float32 pixels, (H, W)) from each pixel to the tangent line of its nearest image edge.

    Edges are Canny edges of every channel of ``image`` ((H, W) or (H, W, C) uint8), so faces that differ
    only in hue are separated. Each edge pixel is moved to the sub-pixel peak of the gradient magnitude
    along its gradient direction, and every pixel gets its distance to the line through that point
    across the gradient. The sign says which side of the edge a pixel is on (towards the brighter side
    of the edge's strongest channel is positive); an edge's zero crossing is sub-pixel accurate and the
    field is linear across it, so bilinear sampling keeps both. Values are clipped to ``+-cap_px``.
    ``roi`` = (u0, v0, u1, v1), or a list of such boxes that do not overlap, computes the field only inside
    them, each box on its own (the rest is ``cap_px``): the polygons to refine usually cover a small part of
    the frame.
    """
    img = np.asarray(image)
    if roi is not None:
        h, w = img.shape[:2]
        out = np.full((h, w), cap_px, np.float32)
        for box in (roi if isinstance(roi, list) else [roi]):
            u0, v0 = max(0, int(box[0])), max(0, int(box[1]))
            u1, v1 = min(w, int(np.ceil(box[2]))), min(h, int(np.ceil(box[3])))
            if u1 - u0 >= 8 and v1 - v0 >= 8:
                out[v0:v1, u0:u1] = edge_distance_field(img[v0:v1, u0:u1], low=low, high=high, cap_px=cap_px)
        return out
    if img.ndim == 2:
        img = img[..., None]
    if img.dtype != np.uint8:
        img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    h, w, nc = img.shape
    # one blur and one pair of Sobel derivatives per channel serve both Canny (which would otherwise take
    # its own, with the same replicated border) and the gradient directions; derivatives of uint8 with
    # ksize 3 are exact in int16
    blur = cv2.GaussianBlur(np.ascontiguousarray(img), (5, 5), 1.0)
    dxs = cv2.split(cv2.Sobel(blur, cv2.CV_16S, 1, 0, ksize=3, borderType=cv2.BORDER_REPLICATE))
    dys = cv2.split(cv2.Sobel(blur, cv2.CV_16S, 0, 1, ksize=3, borderType=cv2.BORDER_REPLICATE))
    edges = cv2.Canny(dxs[0], dys[0], low, high, L2gradient=True)
    for c in range(1, nc):
        edges |= cv2.Canny(dxs[c], dys[c], low, high, L2gradient=True)
    nz = cv2.findNonZero(edges)  # raster order: label k is the k-th edge pixel (as np.nonzero, 3x quicker)
    if nz is None:
        return np.full((h, w), cap_px, np.float32)
    eu, ev = nz.reshape(-1, 2).T.astype(np.intp)
    _, labels = cv2.distanceTransformWithLabels(cv2.bitwise_not(edges), cv2.DIST_L2, 5,
                                                labelType=cv2.DIST_LABEL_PIXEL)
    # each edge pixel's gradient is that of its strongest channel (the first on ties), compared by squared
    # magnitudes, exact in int32; read at the edge pixels only
    at = ev * w + eu
    gx = np.stack([x.ravel().take(at) for x in dxs]).astype(np.int32)
    gy = np.stack([y.ravel().take(at) for y in dys]).astype(np.int32)
    pick = (np.argmax(gx * gx + gy * gy, axis=0), np.arange(len(at)))
    g = np.stack([gx[pick], gy[pick]], 1).astype(np.float32)
    n = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-6)
    # the strongest channel's gradient magnitude at every pixel: dx^2 + dy^2 < 2^24 is exact in float32, so
    # this is sqrt(float32(the int32 maximum)) bit for bit, in fewer passes over the box
    m = None
    for x, y in zip(dxs, dys):
        sq = x.astype(np.float32)
        sq *= sq
        y2 = y.astype(np.float32)
        y2 *= y2
        sq += y2
        m = sq if m is None else np.maximum(m, sq, out=m)
    np.sqrt(m, out=m)
    # sub-pixel peak of the gradient magnitude along the normal (parabola through three samples)
    pts = np.stack([eu, ev], 1).astype(np.float32)
    samples = _bilinear(m, np.concatenate([pts - n, pts, pts + n])).reshape(3, -1)
    curv = samples[0] - 2 * samples[1] + samples[2]
    offset = np.where(curv < -1e-6, 0.5 * (samples[0] - samples[2]) / np.where(curv < -1e-6, curv, -1.0), 0.0)
    sub = pts + np.clip(offset, -0.5, 0.5)[:, None] * n
    # each pixel's signed distance to the line through its nearest edge point: u n_u + v n_v - sub . n
    c = np.sum(sub * n, axis=1, dtype=np.float32)
    # in place, in the same order of operations: each full-box temporary costs as much as the arithmetic
    k = np.subtract(labels, 1, out=labels)
    nu, nv = np.ascontiguousarray(n.T)
    signed = nu.take(k)
    signed *= np.arange(w, dtype=np.float32)[None, :]
    tmp = nv.take(k)
    tmp *= np.arange(h, dtype=np.float32)[:, None]
    signed += tmp
    signed -= c.take(k, out=tmp)
    return np.clip(signed, -cap_px, cap_px, out=signed)


def normal_edge_field(depth: np.ndarray, intrinsics: tuple[float, float, float, float], *, smooth_px: float = 2.0,
                      low: float = 40.0, high: float = 100.0, cap_px: float = 30.0,
                      roi: Box | list[Box] | None = None) -> np.ndarray:
    """Edge-distance field (float32 pixels, (H, W)) of a depth image: its edges are where the surface
    normal turns (a solid's edges, convex or concave) or the depth jumps (an outline).

    ``depth``: (H, W) metres, 0 = no reading. ``intrinsics``: fx, fy, cx, cy in pixels. Points are
    smoothed over ``smooth_px`` (normalised convolution, so holes do not drag them to zero) before the
    normals are taken from central differences. ``roi`` as :func:`edge_distance_field` takes it: each box's
    normals are computed on a window around it just wide enough that the field inside the box is the one the
    whole frame would give.
    """
    z = np.asarray(depth, np.float32)
    valid = (z > 0) & np.isfinite(z)
    z = np.where(valid, z, np.float32(0.0))
    h, w = z.shape
    wsum = cv2.GaussianBlur(valid.astype(np.float32), (0, 0), smooth_px)
    # depth steps are read as log depth above the frame's nearest (smoothed) reading
    near = None
    if valid.any():
        zs = cv2.GaussianBlur(z, (0, 0), smooth_px) / np.maximum(wsum, 1e-6)
        near = float(np.log(np.maximum(zs[valid].min(), 1e-3)))
    args = (z, valid, wsum, near, intrinsics, smooth_px)
    if roi is None:
        return edge_distance_field(_normal_image((0, 0, w, h), *args), low=low, high=high, cap_px=cap_px)
    out = np.full((h, w), cap_px, np.float32)
    # the smoothing kernel's reach and the central differences, with room to spare
    margin = int(np.ceil(4 * smooth_px)) + 4
    for box in (roi if isinstance(roi, list) else [roi]):
        u0, v0 = max(0, int(box[0])), max(0, int(box[1]))  # as edge_distance_field reads a box
        u1, v1 = min(w, int(np.ceil(box[2]))), min(h, int(np.ceil(box[3])))
        if u1 - u0 < 8 or v1 - v0 < 8:
            continue
        win = (max(0, u0 - margin), max(0, v0 - margin), min(w, u1 + margin), min(h, v1 + margin))
        img = _normal_image(win, *args)
        du, dv = u0 - win[0], v0 - win[1]
        out[v0:v1, u0:u1] = edge_distance_field(img[dv:dv + v1 - v0, du:du + u1 - u0], low=low, high=high,
                                                cap_px=cap_px)
    return out


def _normal_image(win: tuple[int, int, int, int], z: np.ndarray, valid: np.ndarray, wsum: np.ndarray,
                  near: float | None, intrinsics: tuple[float, float, float, float], smooth_px: float) -> np.ndarray:
    """The uint8 image :func:`normal_edge_field` finds edges in, over the window (u0, v0, u1, v1): the smoothed
    surface normal's three components and, where the frame has readings, log depth above ``near``."""
    u0, v0, u1, v1 = win
    fx, fy, cx, cy = intrinsics
    zc, valid_c = z[v0:v1, u0:u1], valid[v0:v1, u0:u1]
    u, v = np.meshgrid(np.arange(u0, u1, dtype=np.float32), np.arange(v0, v1, dtype=np.float32))
    pts = np.stack([(u - cx) / fx * zc, (v - cy) / fy * zc, zc], -1)
    pts = cv2.GaussianBlur(pts, (0, 0), smooth_px) / np.maximum(wsum[v0:v1, u0:u1], 1e-6)[..., None]
    du = np.zeros_like(pts)
    dv = np.zeros_like(pts)
    du[:, 1:-1] = pts[:, 2:] - pts[:, :-2]
    dv[1:-1] = pts[2:] - pts[:-2]
    # du x dv and its length written out, the same numbers as np.cross and np.linalg.norm (the same products, the
    # squares added left to right as numpy's reduce adds them) at a fraction of their cost on an image
    n = np.empty_like(du)
    n[..., 0] = du[..., 1] * dv[..., 2] - du[..., 2] * dv[..., 1]
    n[..., 1] = du[..., 2] * dv[..., 0] - du[..., 0] * dv[..., 2]
    n[..., 2] = du[..., 0] * dv[..., 1] - du[..., 1] * dv[..., 0]
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    n /= np.maximum(np.sqrt(x * x + y * y + z * z), 1e-12)[..., None]
    # the channels written into one image, each by the operations (in float32) that clipping them apart and
    # stacking them would do: the stacked copy of the window costs as much as its arithmetic
    img = np.empty(n.shape[:2] + (3 if near is None else 4,), np.float32)
    rgb = img[..., :3]
    np.add(n, 1.0, out=rgb)
    rgb *= 127.5
    np.clip(rgb, 0, 255, out=rgb)
    if near is not None:
        logz = np.log(np.maximum(pts[..., 2], 1e-3))
        logz -= near
        logz *= 400.0
        np.clip(logz, 0, 255, out=img[..., 3])
    np.copyto(img, 0, where=~valid_c[..., None])
    return img.astype(np.uint8)
