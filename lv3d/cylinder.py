"""Cylinders in the camera frame (metres), the curved counterpart of :mod:`lv3d.plane`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .plane import row_norms


@dataclass(frozen=True)
class Cylinder:
    """A cylinder in the camera frame: unit ``axis``, a ``point`` on the axis, ``radius`` (metres)."""

    axis: tuple[float, float, float]
    point: tuple[float, float, float]
    radius: float

    def radial(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distances (m,) of ``points`` (m, 3) from the axis, and the unit directions (m, 3) away from it."""
        a, c = np.asarray(self.axis), np.asarray(self.point)
        d = points - c
        d = d - (d @ a)[:, None] * a
        r = row_norms(d)
        return r, d / np.maximum(r, 1e-12)[:, None]

    def to_dict(self) -> dict:
        return {"axis": list(self.axis), "point": list(self.point), "radius": self.radius}
