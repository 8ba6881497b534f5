"""Edge map of a colour image (OpenCV Canny with thresholds from the image's own gradient statistics) and the
edge support of a polygon (how much of its perimeter lies on image edges)."""

from __future__ import annotations

import cv2
import numpy as np

from .polygons import pixel_values, sample_boundary


def to_gray(color: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8 RGB -> (H, W) uint8 grey, lightly denoised (sensor noise makes spurious edges)."""
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise ValueError(f"colour must be (H, W, 3) uint8, got {color.shape} {color.dtype}")
    gray = cv2.cvtColor(color, cv2.COLOR_RGB2GRAY)
    return cv2.GaussianBlur(gray, (3, 3), 0)


def channels(color: np.ndarray) -> list[np.ndarray]:
    """The three colour channels, lightly denoised: edges between faces of equal brightness but different hue
    vanish in a grey image, so lines and edges are looked for in each channel."""
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise ValueError(f"colour must be (H, W, 3) uint8, got {color.shape} {color.dtype}")
    blurred = cv2.GaussianBlur(color, (3, 3), 0)
    return [np.ascontiguousarray(blurred[:, :, c]) for c in range(3)]


def color_edge_map(color: np.ndarray) -> np.ndarray:
    """Union of the per-channel Canny edges (H, W) uint8 in {0, 255}."""
    out = None
    for ch in channels(color):
        e = edge_map(ch)
        out = e if out is None else np.maximum(out, e)
    return out


def edge_map(gray: np.ndarray, low_ratio: float = 0.5) -> np.ndarray:
    """Canny edges (H, W) uint8 in {0, 255}. The high threshold is the 90th percentile of the gradient
    magnitude (clipped to [40, 400]), so that it adapts to contrast; the low one is ``low_ratio`` of it."""
    return edges_and_gradient(gray, low_ratio)[0]


def edges_and_gradient(gray: np.ndarray, low_ratio: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """:func:`edge_map` and the Sobel gradient magnitude (H, W) float32 it was thresholded from."""
    gx = cv2.Sobel(gray, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(gray, cv2.CV_32F, 0, 1, ksize=3)
    mag = cv2.magnitude(gx, gy)
    high = float(np.clip(np.percentile(mag[::4, ::4], 90), 40.0, 400.0))  # Canny uses the same 3x3 Sobel
    return cv2.Canny(gray, low_ratio * high, high, L2gradient=True), mag


def edge_distance(edges: np.ndarray) -> np.ndarray:
    """Distance (pixels, float32, (H, W)) from each pixel to the nearest edge pixel."""
    return cv2.distanceTransform((edges == 0).astype(np.uint8), cv2.DIST_L2, 3)


def edge_support(poly: np.ndarray, dist: np.ndarray, tol_px: float = 2.0) -> float:
    """Fraction in [0, 1] of the polygon's perimeter within ``tol_px`` of an edge pixel."""
    pts = sample_boundary(poly, 1.0)
    return float(np.mean(pixel_values(dist, pts) <= tol_px)) if len(pts) else 0.0
