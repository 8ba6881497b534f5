"""The ellipse fitted to a face's outline in the image (pixels), beside its polygon: what colour perception
measures of a round outline (lv3d/perception/rgb/ellipse.py fits it), the 2D counterpart of :mod:`lv3d.cylinder`."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class OutlineEllipse:
    """The ellipse fitted to a face's outline and how it compares with the face's polygon: ``center`` (u, v)
    pixels, ``axes`` (semi-major, semi-minor) pixels, ``angle_deg`` (OpenCV's rotation of the first axis),
    ``rms_px`` / ``polygon_rms_px`` the two residuals (trimmed RMS, pixels), ``points`` the edge pixels used,
    ``vertices`` the polygon's."""

    center: tuple[float, float]
    axes: tuple[float, float]
    angle_deg: float
    rms_px: float
    polygon_rms_px: float
    points: int
    vertices: int

    @property
    def log_ratio(self) -> float:
        """ln(polygon residual / ellipse residual); residuals floored at 0.05 px (below the edge map's
        precision), so the ratio stays finite."""
        return float(math.log(max(self.polygon_rms_px, 0.05) / max(self.rms_px, 0.05)))

    @property
    def rel_rms(self) -> float:
        """The ellipse's residual over its semi-minor axis: how well it fits, in units of its size."""
        return float(self.rms_px / max(self.axes[1], 1e-9))

    def to_dict(self) -> dict:
        return {"center": [round(c, 2) for c in self.center], "axes": [round(a, 2) for a in self.axes],
                "angle_deg": round(self.angle_deg, 2), "rms_px": round(self.rms_px, 3),
                "polygon_rms_px": round(self.polygon_rms_px, 3), "points": self.points, "vertices": self.vertices}
