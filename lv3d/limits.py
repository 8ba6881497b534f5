"""Bounds on what lv3d reads and makes, so that no input can make it allocate without a limit a user
can see. Each is refused up front, with a one-line error that names it.

- :data:`MAX_PIXELS`: an image (colour or depth, read or rendered) holds at most this many pixels,
  2048 x 2048. Perception of one frame needs about 550 bytes per pixel of the frame it perceives at its peak (a
  640 x 480 frame about 170 MB), so the bound keeps one frame under about 2.3 GB: a rendered data set's item is
  perceived at its own size, a camera frame at perception's working size (lv3d.rgbd.to_working). A larger
  image can be downscaled (with its intrinsics) before lv3d reads it.
- :data:`MAX_DATASET_IMAGES`: a data set (``lv3d dataset make``, a study's ``data``) holds at most this
  many images (at 640 x 480 about 0.6 MB each on disk, 12 GB in all).
"""

from __future__ import annotations

MAX_PIXELS = 2048 * 2048
MAX_DATASET_IMAGES = 20_000


def check_pixels(width: int, height: int, where, what: str = "image") -> None:
    """An InputError unless a ``width`` x ``height`` image is within :data:`MAX_PIXELS`."""
    from .errors import InputError

    if width * height > MAX_PIXELS:
        raise InputError(where, f"{what} of {width}x{height} pixels is larger than the {MAX_PIXELS} pixels "
                                f"(2048x2048) lv3d reads (lv3d.limits.MAX_PIXELS); downscale it first")
