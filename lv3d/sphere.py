"""Spheres in the camera frame (metres), beside :mod:`lv3d.plane` and :mod:`lv3d.cylinder`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .plane import row_norms


@dataclass(frozen=True)
class Sphere:
    """A sphere in the camera frame: its ``centre`` and ``radius`` (metres), and the ``side`` a face of it shows:
    1 its outside (a ball; the surface's normals point away from the centre), -1 its inside (a bowl seen over its
    rim; they point towards it)."""

    centre: tuple[float, float, float]
    radius: float
    side: float = 1.0

    def radial(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distances (m,) of ``points`` (m, 3) from the centre, and the unit directions (m, 3) away from it (the
        outward normals of the surface there)."""
        d = np.asarray(points, float) - np.asarray(self.centre)
        r = row_norms(d)
        return r, d / np.maximum(r, 1e-12)[:, None]

    def normals(self, points: np.ndarray) -> np.ndarray:
        """The unit normals (m, 3) of the side the sphere shows at ``points`` (m, 3): the radial directions, turned
        towards the centre for an inside."""
        return self.side * self.radial(points)[1]

    def residual(self, points: np.ndarray) -> np.ndarray:
        """Signed distances (m,) of ``points`` (m, 3) from the surface, positive outside."""
        return self.radial(points)[0] - self.radius

    def to_dict(self) -> dict:
        return {"centre": list(self.centre), "radius": self.radius, "side": self.side}


def algebraic_sphere(pts: np.ndarray) -> Sphere | None:
    """The linear least-squares sphere of points (m, 3): ``|p|^2 = 2 c . p + k`` in the four unknowns c and k
    (the radius is ``sqrt(k + |c|^2)``). None where that is not a sphere."""
    if len(pts) < 4:
        return None
    sol, *_ = np.linalg.lstsq(np.column_stack([2 * pts, np.ones(len(pts))]), np.einsum("ij,ij->i", pts, pts),
                              rcond=None)
    r2 = sol[3] + sol[:3] @ sol[:3]
    if not (np.all(np.isfinite(sol)) and r2 > 0):
        return None
    return Sphere(tuple(float(x) for x in sol[:3]), float(np.sqrt(r2)))
