"""Cones in the camera frame (metres), beside :mod:`lv3d.plane` and :mod:`lv3d.cylinder`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .plane import row_norms


@dataclass(frozen=True)
class Cone:
    """A cone's side in the camera frame: its ``apex``, unit ``axis`` from the apex towards the base,
    ``half_angle_deg`` between the axis and the side, and ``height`` (metres along the axis from the apex to the
    farthest point of the side it was measured on: the base where that is seen)."""

    apex: tuple[float, float, float]
    axis: tuple[float, float, float]
    half_angle_deg: float
    height: float

    @property
    def radius(self) -> float:
        """The radius at ``height`` (the base's, where the base's rim was seen)."""
        return float(self.height * np.tan(np.radians(self.half_angle_deg)))

    def radius_at(self, along: float) -> float:
        """The radius at ``along`` metres from the apex along the axis."""
        return float(along * np.tan(np.radians(self.half_angle_deg)))

    def local(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per point (m, 3): the distance along the axis from the apex (m,), the distance from the axis (m,), and
        the unit direction away from the axis (m, 3)."""
        a = np.asarray(self.axis, float)
        v = np.asarray(points, float) - np.asarray(self.apex)
        h = v @ a
        w = v - h[:, None] * a
        rho = row_norms(w)
        return h, rho, w / np.maximum(rho, 1e-12)[:, None]

    def residual(self, points: np.ndarray) -> np.ndarray:
        """Signed distances (m,) of ``points`` (m, 3) from the side's infinite surface (the nappe the axis points
        into), positive outside: rho cos(alpha) - h sin(alpha) for a point h along the axis and rho from it."""
        h, rho, _ = self.local(points)
        t = np.radians(self.half_angle_deg)
        return rho * np.cos(t) - h * np.sin(t)

    def normals(self, points: np.ndarray) -> np.ndarray:
        """The surface's outward unit normals (m, 3) at the points nearest ``points`` (m, 3): each makes the angle
        90 deg + half_angle with the axis and meets it."""
        _, _, u = self.local(points)
        t = np.radians(self.half_angle_deg)
        return np.cos(t) * u - np.sin(t) * np.asarray(self.axis, float)

    def to_dict(self) -> dict:
        return {"apex": list(self.apex), "axis": list(self.axis), "half_angle_deg": self.half_angle_deg,
                "height": self.height, "radius": self.radius}
