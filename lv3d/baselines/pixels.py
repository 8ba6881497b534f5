"""Frames as small pixel tensors for the statistical baselines.

Every baseline sees the same view of a frame: the central square crop of the image, downsampled
to ``size`` x ``size`` (no ground truth, no object crop: the baseline gets what the camera gives);
or, for a labelled object of a real frame, a square crop around it (:func:`crop_tensor`).
Channel layout (C, size, size), float32:

- ``rgb``: 3 channels, colour scaled to roughly zero mean, unit spread ((x/255 - 0.5) / 0.25);
- ``depth``: 1 channel, depth relative to the frame's median valid depth in units of 0.1 m,
  clipped to [-3, 3]; pixels without a reading are 0;
- ``rgbd``: the 3 colour channels then the depth channel.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..errors import InputError
from ..rgbd import RGBD

CHANNELS = {"rgb": 3, "depth": 1, "rgbd": 4}
DEPTH_UNIT_M = 0.1  # depth relief of a table-top object is centimetres to decimetres


def _square_crop(img: np.ndarray) -> np.ndarray:
    h, w = img.shape[:2]
    s = min(h, w)
    top, left = (h - s) // 2, (w - s) // 2
    return img[top:top + s, left:left + s]


def color_channels(color: np.ndarray, size: int) -> np.ndarray:
    """(H, W, 3) uint8 RGB -> (3, size, size) float32."""
    small = cv2.resize(_square_crop(color), (size, size), interpolation=cv2.INTER_AREA)
    return ((small.astype(np.float32) / 255.0 - 0.5) / 0.25).transpose(2, 0, 1)


def depth_channel(depth: np.ndarray, size: int) -> np.ndarray:
    """(H, W) float32 metres (0 = no reading) -> (1, size, size) float32, relative depth (see module doc)."""
    crop = _square_crop(depth).astype(np.float32)
    valid = crop > 0
    rel = np.zeros_like(crop)
    if valid.any():
        rel[valid] = np.clip((crop[valid] - np.median(crop[valid])) / DEPTH_UNIT_M, -3.0, 3.0)
    return cv2.resize(rel, (size, size), interpolation=cv2.INTER_AREA)[None]


def frame_tensor(frame: RGBD, modality: str, size: int = 64) -> np.ndarray:
    """One frame as (CHANNELS[modality], size, size) float32."""
    if modality not in CHANNELS:
        raise InputError("modality", f"unknown modality {modality!r}; choose one of {', '.join(CHANNELS)}")
    parts = []
    if modality in ("rgb", "rgbd"):
        parts.append(color_channels(frame.color, size))
    if modality in ("depth", "rgbd"):
        parts.append(depth_channel(frame.depth, size))
    return np.concatenate(parts, axis=0)


def crop_tensor(frame: RGBD, square: tuple[int, int, int], size: int = 64) -> np.ndarray:
    """The rgbd tensor (4, size, size) of the square ``(u0, v0, side)`` of ``frame`` (what lies outside the
    frame: black, no depth reading); depth relative to the crop's median valid depth."""
    u0, v0, side = square
    h, w = frame.depth.shape
    color = np.zeros((side, side, 3), np.uint8)
    depth = np.zeros((side, side), np.float32)
    a0, b0, a1, b1 = max(0, u0), max(0, v0), min(w, u0 + side), min(h, v0 + side)
    if a1 > a0 and b1 > b0:
        color[b0 - v0:b1 - v0, a0 - u0:a1 - u0] = frame.color[b0:b1, a0:a1]
        depth[b0 - v0:b1 - v0, a0 - u0:a1 - u0] = frame.depth[b0:b1, a0:a1]
    return np.concatenate([color_channels(color, size), depth_channel(depth, size)], axis=0)
