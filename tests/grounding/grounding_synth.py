"""Synthetic images and depth with exact answers, for the grounding tests.

Every test uses a 480 x 640 edge field so that one compiled program serves the whole folder.
"""

from __future__ import annotations

import cv2
import numpy as np

H, W = 480, 640
INTR = (600.0, 600.0, 319.5, 239.5)
SS = 8  # supersampling factor of the synthetic renderings: edges land where the true polygon is


def render_polygons(polygons, colours, background=(30, 30, 30)) -> np.ndarray:
    """An anti-aliased (H, W, 3) uint8 image of filled polygons (pixel centres at integers)."""
    big = np.zeros((H * SS, W * SS, 3), np.uint8)
    big[:] = background
    for poly, col in zip(polygons, colours):
        p = (np.asarray(poly, np.float64) + 0.5) * SS - 0.5
        cv2.fillPoly(big, [np.round(p * 16).astype(np.int32)], col, lineType=cv2.LINE_8, shift=4)
    return cv2.resize(big, (W, H), interpolation=cv2.INTER_AREA)


def project(x: np.ndarray) -> np.ndarray:
    fx, fy, cx, cy = INTR
    return np.stack([fx * x[:, 0] / x[:, 2] + cx, fy * x[:, 1] / x[:, 2] + cy], 1)


def plane_through(a, b, c) -> np.ndarray:
    """(n, d) of the plane through three points, n towards the camera."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    d = -n @ a
    return np.r_[n, d] if d > 0 else -np.r_[n, d]


def sample_face(corners: np.ndarray, n: int, rng, sigma=(0.001, 0.0018)) -> np.ndarray:
    """``n`` camera-frame points inside a convex 3D polygon, with depth noise sigma(z) = a + b z^2 along the ray."""
    w = rng.dirichlet(np.ones(len(corners)), n)
    p = w @ corners
    z = p[:, 2]
    s = sigma[0] + sigma[1] * z * z
    return p * ((z + rng.normal(0, 1, n) * s) / z)[:, None]


def wedge(theta_deg: float = 90.0, half_width: float = 0.06, length: float = 0.1, depth: float = 0.8,
          yaw_deg: float = 20.0):
    """Two square-ish faces of a convex solid meeting along one edge with interior dihedral ``theta_deg``,
    both facing the camera: (3D corners (4, 3) of each face, metres, camera frame; adjacency)."""
    t = np.radians(theta_deg)
    a = np.array([0.0, -1.0, 0.0])
    b = np.array([0.0, -np.cos(t), np.sin(t)])
    na, nb = np.array([0.0, 0.0, -1.0]), np.array([0.0, np.sin(t), np.cos(t)])  # outward normals
    m = (na + nb) / np.linalg.norm(na + nb)
    ang = np.arctan2(m[1], -m[2])  # rotate about x so that the normals' bisector looks at the camera
    rx = np.array([[1, 0, 0], [0, np.cos(ang), np.sin(ang)], [0, -np.sin(ang), np.cos(ang)]])
    ry_ = np.radians(yaw_deg)
    ry = np.array([[np.cos(ry_), 0, np.sin(ry_)], [0, 1, 0], [-np.sin(ry_), 0, np.cos(ry_)]])
    rot = ry @ rx
    e0, e1 = np.array([-half_width, 0, 0]), np.array([half_width, 0, 0])
    fa = np.array([e0, e1, e1 + length * a, e0 + length * a])
    fb = np.array([e1, e0, e0 + length * b, e1 + length * b])
    shift = np.array([0.0, 0.0, depth])
    return [fa @ rot.T + shift, fb @ rot.T + shift], [(0, 1)]
