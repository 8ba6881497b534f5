"""Edge fields: smooth images whose value is the distance (pixels) to the nearest image edge.
Computed with OpenCV outside jit and handed to the refinement as a plain array."""

from __future__ import annotations

import cv2
import numpy as np


def edge_distance_field(image: np.ndarray, *, low: float = 20.0, high: float = 60.0, blur_px: float = 0.0,
                        cap_px: float = 30.0) -> np.ndarray:
    """Distance (float32 pixels, (H, W)) from each pixel to the nearest Canny edge of ``image``.

    ``image``: (H, W) or (H, W, C) uint8; edges of every channel count, so faces that differ only in hue
    are separated. The distance is capped at ``cap_px`` (nothing beyond is a plausible edge for a side)
    and blurred with a Gaussian of ``blur_px`` so that its gradient is smooth at the edge itself.
    """
    img = np.asarray(image)
    if img.ndim == 2:
        img = img[..., None]
    if img.dtype != np.uint8:
        img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    edges = np.zeros(img.shape[:2], np.uint8)
    for c in range(img.shape[2]):
        ch = cv2.GaussianBlur(np.ascontiguousarray(img[..., c]), (5, 5), 1.0)
        edges |= cv2.Canny(ch, low, high, L2gradient=True)
    if not edges.any():
        return np.full(img.shape[:2], cap_px, np.float32)
    dist = cv2.distanceTransform(np.where(edges > 0, 0, 255).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    dist = np.minimum(dist, cap_px)
    if blur_px > 0:
        dist = cv2.GaussianBlur(dist, (0, 0), blur_px)
    return dist.astype(np.float32)


def normal_edge_field(depth: np.ndarray, intrinsics: tuple[float, float, float, float], *, smooth_px: float = 2.0,
                      low: float = 40.0, high: float = 100.0, cap_px: float = 30.0) -> np.ndarray:
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
    return edge_distance_field(img.astype(np.uint8), low=low, high=high, cap_px=cap_px)
