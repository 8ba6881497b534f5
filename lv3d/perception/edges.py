"""Edge map of a colour image (OpenCV Canny with thresholds from the image's own gradient statistics) and the
edge support of a polygon (how much of its perimeter lies on image edges)."""

from __future__ import annotations

from typing import NamedTuple

import cv2
import numpy as np

from .polygons import pixel_values, sample_boundary


def channels(color: np.ndarray) -> list[np.ndarray]:
    """The three colour channels, lightly denoised: edges between faces of equal brightness but different hue
    vanish in a grey image, so lines and edges are looked for in each channel."""
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise ValueError(f"colour must be (H, W, 3) uint8, got {color.shape} {color.dtype}")
    blurred = cv2.GaussianBlur(color, (3, 3), 0)
    return [np.ascontiguousarray(blurred[:, :, c]) for c in range(3)]


class ChannelEdges(NamedTuple):
    """A grey channel's Canny edges (H, W) uint8 in {0, 255}, and the 3x3 Sobel gradient they were found from:
    its x and y derivatives ``dx``, ``dy`` and ``magnitude`` (H, W) float32, in 8 times grey levels per pixel."""

    edges: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    magnitude: np.ndarray


def channel_edges(gray: np.ndarray, low_ratio: float = 0.5) -> ChannelEdges:
    """Canny edges of a grey channel (H, W) uint8 and their gradient. The high threshold is the 90th percentile of
    the gradient magnitude (clipped to [40, 400]), so that it adapts to contrast; the low one is ``low_ratio`` of
    it. Canny takes the same 3x3 Sobel gradient. The same in every run (numpy's square root is exact)."""
    dx = cv2.Sobel(gray, cv2.CV_32F, 1, 0, ksize=3)
    dy = cv2.Sobel(gray, cv2.CV_32F, 0, 1, ksize=3)
    mag = np.sqrt(dx * dx + dy * dy)  # not cv2.magnitude: its result changes in the last bit from call to call
    high = float(np.clip(np.percentile(mag[::4, ::4], 90), 40.0, 400.0))
    return ChannelEdges(cv2.Canny(gray, low_ratio * high, high, L2gradient=True), dx, dy, mag)


def edge_distance(edges: np.ndarray) -> np.ndarray:
    """Distance (pixels, float32, (H, W)) from each pixel to the nearest edge pixel."""
    return cv2.distanceTransform((edges == 0).astype(np.uint8), cv2.DIST_L2, 3)


def edge_support(poly: np.ndarray, dist: np.ndarray, tol_px: float = 2.0) -> float:
    """Fraction in [0, 1] of the polygon's perimeter within ``tol_px`` of an edge pixel."""
    pts = sample_boundary(poly, 1.0)
    return float(np.mean(pixel_values(dist, pts) <= tol_px)) if len(pts) else 0.0
