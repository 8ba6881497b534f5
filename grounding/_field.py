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
    u0, v0 = u.astype(int), v.astype(int)
    fu, fv = u - u0, v - v0
    top = img[v0, u0] * (1 - fu) + img[v0, u0 + 1] * fu
    bottom = img[v0 + 1, u0] * (1 - fu) + img[v0 + 1, u0 + 1] * fu
    return top * (1 - fv) + bottom * fv


def edge_distance_field(image: np.ndarray, *, low: float = 20.0, high: float = 60.0, cap_px: float = 30.0,
                        roi: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """Signed distance (float32 pixels, (H, W)) from each pixel to the tangent line of its nearest image edge.

    Edges are Canny edges of every channel of ``image`` ((H, W) or (H, W, C) uint8), so faces that differ
    only in hue are separated. Each edge pixel is moved to the sub-pixel peak of the gradient magnitude
    along its gradient direction, and every pixel gets its distance to the line through that point
    across the gradient. The sign says which side of the edge a pixel is on (towards the brighter side
    of the edge's strongest channel is positive); an edge's zero crossing is sub-pixel accurate and the
    field is linear across it, so bilinear sampling keeps both. Values are clipped to ``+-cap_px``.
    ``roi`` = (u0, v0, u1, v1) computes the field only inside that box (the rest is ``cap_px``): the
    polygons to refine usually cover a small part of the frame.
    """
    img = np.asarray(image)
    if roi is not None:
        h, w = img.shape[:2]
        u0, v0 = max(0, int(roi[0])), max(0, int(roi[1]))
        u1, v1 = min(w, int(np.ceil(roi[2]))), min(h, int(np.ceil(roi[3])))
        out = np.full((h, w), cap_px, np.float32)
        if u1 - u0 >= 8 and v1 - v0 >= 8:
            out[v0:v1, u0:u1] = edge_distance_field(img[v0:v1, u0:u1], low=low, high=high, cap_px=cap_px)
        return out
    if img.ndim == 2:
        img = img[..., None]
    if img.dtype != np.uint8:
        img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    h, w, nc = img.shape
    edges = np.zeros((h, w), np.uint8)
    gx = np.zeros((h, w), np.float32)
    gy = np.zeros((h, w), np.float32)
    mag = np.zeros((h, w), np.float32)
    for c in range(nc):
        ch = cv2.GaussianBlur(np.ascontiguousarray(img[..., c]), (5, 5), 1.0)
        edges |= cv2.Canny(ch, low, high, L2gradient=True)
        cx = cv2.Sobel(ch, cv2.CV_32F, 1, 0, ksize=3)
        cy = cv2.Sobel(ch, cv2.CV_32F, 0, 1, ksize=3)
        cm = cx * cx + cy * cy
        take = cm > mag
        gx[take], gy[take], mag[take] = cx[take], cy[take], cm[take]
    if not edges.any():
        return np.full((h, w), cap_px, np.float32)
    _, labels = cv2.distanceTransformWithLabels(np.where(edges > 0, 0, 255).astype(np.uint8), cv2.DIST_L2, 5,
                                                labelType=cv2.DIST_LABEL_PIXEL)
    ev, eu = np.nonzero(edges)  # raster order: label k is the k-th edge pixel
    g = np.stack([gx[ev, eu], gy[ev, eu]], 1)
    n = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-6)
    # sub-pixel peak of the gradient magnitude along the normal (parabola through three samples)
    m = np.sqrt(mag)
    pts = np.stack([eu, ev], 1).astype(np.float32)
    samples = [_bilinear(m, pts + k * n) for k in (-1.0, 0.0, 1.0)]
    curv = samples[0] - 2 * samples[1] + samples[2]
    offset = np.where(curv < -1e-6, 0.5 * (samples[0] - samples[2]) / np.where(curv < -1e-6, curv, -1.0), 0.0)
    sub = pts + np.clip(offset, -0.5, 0.5)[:, None] * n
    k = labels.ravel() - 1
    vv, uu = np.divmod(np.arange(h * w), w)
    signed = (uu - sub[k, 0]) * n[k, 0] + (vv - sub[k, 1]) * n[k, 1]
    return np.clip(signed, -cap_px, cap_px).reshape(h, w).astype(np.float32)


def normal_edge_field(depth: np.ndarray, intrinsics: tuple[float, float, float, float], *, smooth_px: float = 2.0,
                      low: float = 40.0, high: float = 100.0, cap_px: float = 30.0,
                      roi: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """Edge-distance field (float32 pixels, (H, W)) of a depth image: its edges are where the surface
    normal turns (a solid's edges, convex or concave) or the depth jumps (an outline).

    ``depth``: (H, W) metres, 0 = no reading. ``intrinsics``: fx, fy, cx, cy in pixels. Points are
    smoothed over ``smooth_px`` (normalised convolution, so holes do not drag them to zero) before the
    normals are taken from central differences.
    """
    z = np.asarray(depth, np.float32)
    valid = (z > 0) & np.isfinite(z)
    z = np.where(valid, z, 0.0).astype(np.float32)
    h, w = z.shape
    fx, fy, cx, cy = intrinsics
    u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
    pts = np.stack([(u - cx) / fx * z, (v - cy) / fy * z, z], -1)
    wsum = cv2.GaussianBlur(valid.astype(np.float32), (0, 0), smooth_px)
    pts = cv2.GaussianBlur(pts, (0, 0), smooth_px) / np.maximum(wsum, 1e-6)[..., None]
    du = np.zeros_like(pts)
    dv = np.zeros_like(pts)
    du[:, 1:-1] = pts[:, 2:] - pts[:, :-2]
    dv[1:-1] = pts[2:] - pts[:-2]
    n = np.cross(du, dv)
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
    img = np.clip((n + 1.0) * 127.5, 0, 255)
    # depth steps: log depth, so a jump of a given ratio looks the same near and far
    logz = np.log(np.maximum(pts[..., 2], 1e-3))
    img = np.concatenate([img, np.clip((logz - logz[valid].min()) * 400.0, 0, 255)[..., None]], -1) if valid.any() else img
    img[~valid] = 0
    return edge_distance_field(img.astype(np.uint8), low=low, high=high, cap_px=cap_px, roi=roi)
