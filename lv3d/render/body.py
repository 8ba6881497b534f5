"""A solid placed in the camera frame, and the clipping of its faces at the camera's near plane."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .solids import Solid


@dataclass(frozen=True)
class Body:
    """A solid in the camera frame: ``to_camera`` (4, 4) maps its object frame into the camera frame."""

    solid: Solid
    to_camera: np.ndarray

    def vertices(self) -> np.ndarray:
        """Camera-frame vertices (n, 3), metres (read-only, computed once)."""
        return self._vertices

    def normals(self) -> np.ndarray:
        """Camera-frame outward face normals (f, 3) (read-only, computed once)."""
        return self._normals

    @cached_property
    def _vertices(self) -> np.ndarray:
        v = self.solid.vertices @ self.to_camera[:3, :3].T + self.to_camera[:3, 3]
        v.setflags(write=False)
        return v

    @cached_property
    def _normals(self) -> np.ndarray:
        n = self.solid.normals() @ self.to_camera[:3, :3].T
        n.setflags(write=False)
        return n



def clip_near(poly: np.ndarray, z_near: float) -> np.ndarray:
    """The part of the planar polygon (n, 3) with z >= ``z_near`` (Sutherland-Hodgman against one plane)."""
    if poly[:, 2].min() >= z_near:  # the usual case: all in front
        return poly
    out = []
    for a, b in zip(poly, np.roll(poly, -1, axis=0)):
        ina, inb = a[2] >= z_near, b[2] >= z_near
        if ina:
            out.append(a)
        if ina != inb:
            out.append(a + (b - a) * (z_near - a[2]) / (b[2] - a[2]))
    return np.asarray(out).reshape(-1, 3)
