"""Euclidean distance transform that is the same in every run and at every thread count.

OpenCV's exact Euclidean transform (``DIST_MASK_PRECISE``) differs by one unit in the last place from call to
call on the same input (its vectorised and scalar paths round the square root differently). That is enough to
break ties between equal distances, so a watershed seeded by distance maxima, or a reach test at an integer
radius, could change from one run to the next. The transform's squared distances are integers (cells on a
grid), so rounding the square of OpenCV's answer recovers them exactly, and their square root is the same
everywhere. Beyond :data:`EXACT_LIMIT` cells float32 rounding could reach half a unit of the square, and
SciPy's exact transform (slower, about 5 times) is used instead.
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage

EXACT_LIMIT = 1000.0
"""Cells. Below it float32's error of OpenCV's distance squared stays well under 0.5."""


def euclidean_distance(mask: np.ndarray) -> np.ndarray:
    """Distance (cells, float32, ``mask``'s shape) from each nonzero cell of ``mask`` to the nearest zero cell;
    0 on zero cells. Reproducible bit for bit (see the module)."""
    m = np.ascontiguousarray(mask).astype(np.uint8, copy=False)
    if np.hypot(*m.shape) >= EXACT_LIMIT:
        return ndimage.distance_transform_edt(m).astype(np.float32)
    d = cv2.distanceTransform(m, cv2.DIST_L2, cv2.DIST_MASK_PRECISE).astype(np.float64)
    return np.sqrt(np.rint(d * d)).astype(np.float32)
