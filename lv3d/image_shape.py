"""Image-plane shape facts: what colour alone can say of a face's polygon without a plane (docs/facts.md).

A face seen in colour alone has no plane, so its metric shape (``square``, ``rectangle``, ``regular`` on the
plane, grounding) is unknown; its image polygon still has corners and sides. Read in the image, the same
tests give image-plane shape: true of the face itself when it faces the camera (Logical Vision's 2D
scenes), distorted by perspective when it is seen obliquely. The corner facts say which kinds of corner the
polygon has: ``has_right_angle`` (a corner within ``RIGHT_ANGLE_DEG`` of 90), ``has_acute_angle`` (one
sharper than that), ``has_obtuse_angle`` (one blunter).

Confidences come from the measurement: each image corner angle and side length is Gaussian with grounding's
Laplace spread and its model-error floor (``grounding.Floors``), and a fact's probability is that of its
test under those Gaussians (Monte Carlo with fixed draws for the tests over several quantities).
"""

from __future__ import annotations

import functools

import numpy as np

from grounding import EQUAL_CORNERS_DEG, RIGHT_ANGLE_DEG, Floors

from .interval import probability_below

EQUAL_SIDES_RATIO = 1.12  # square / regular: longest side / shortest side at most this (grounding's metric test)
DRAWS = 256
# the facts this module gives, each (name, arity)
PREDICATES = (("square", 1), ("rectangle", 1), ("regular", 1),
              ("has_right_angle", 1), ("has_acute_angle", 1), ("has_obtuse_angle", 1))


@functools.cache
def _normals(n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    return rng.standard_normal((DRAWS, n)), rng.standard_normal((DRAWS, n))


def _p(x) -> float:
    return float(np.clip(x, 0.0, 1.0))


def image_shape(fid: str, corner_deg, corner_std, side_px, side_std) -> list[tuple[str, tuple[str], float, float]]:
    """Candidate facts ``(pred, (fid,), probability, value)`` of one face from its image polygon: its n
    interior corner angles (degrees) and n side lengths (pixels), each with its Laplace spread (before the
    floor). Value: the largest |corner - 90| (rectangle, has_right_angle: the smallest), the longest over the
    shortest side (square, regular), the sharpest or bluntest corner."""
    floors = Floors()
    c = np.asarray(corner_deg, float)
    cs = np.hypot(np.asarray(corner_std, float), floors.corner_deg)
    s = np.asarray(side_px, float)
    ss = np.hypot(np.asarray(side_std, float), floors.side_px)
    n = len(c)
    if n < 3 or len(s) != n:
        return []
    lo, hi = 90.0 - RIGHT_ANGLE_DEG, 90.0 + RIGHT_ANGLE_DEG
    p_acute = np.array([probability_below(lo, m, d) for m, d in zip(c, cs)])
    p_obtuse = np.array([1.0 - probability_below(hi, m, d) for m, d in zip(c, cs)])
    p_right = 1.0 - p_acute - p_obtuse
    out = [("has_right_angle", (fid,), _p(1.0 - np.prod(1.0 - p_right)), float(np.min(np.abs(c - 90.0)))),
           ("has_acute_angle", (fid,), _p(1.0 - np.prod(1.0 - p_acute)), float(np.min(c))),
           ("has_obtuse_angle", (fid,), _p(1.0 - np.prod(1.0 - p_obtuse)), float(np.max(c)))]
    zc, zs = _normals(n)
    cd = c[None] + zc * cs[None]
    sd = np.maximum(s[None] + zs * ss[None], 1e-6)
    equal = sd.max(1) / sd.min(1) <= EQUAL_SIDES_RATIO
    ratio = float(s.max() / max(s.min(), 1e-6))
    if n == 4:
        right = np.all(np.abs(cd - 90.0) < RIGHT_ANGLE_DEG, 1)
        out.append(("rectangle", (fid,), _p(right.mean()), float(np.max(np.abs(c - 90.0)))))
        out.append(("square", (fid,), _p((right & equal).mean()), ratio))
    regular = equal & (cd.max(1) - cd.min(1) < EQUAL_CORNERS_DEG)
    out.append(("regular", (fid,), _p(regular.mean()), ratio))
    return out


def polygon_angles(poly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interior corner angles (degrees) and side lengths of a convex polygon (n, 2) in order (vertex i's side
    runs to vertex i + 1)."""
    poly = np.asarray(poly, float)
    prev, nxt = np.roll(poly, 1, axis=0) - poly, np.roll(poly, -1, axis=0) - poly
    cos = np.sum(prev * nxt, 1) / np.maximum(np.linalg.norm(prev, axis=1) * np.linalg.norm(nxt, axis=1), 1e-12)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))), np.linalg.norm(nxt, axis=1)


def exact_image_shape(poly: np.ndarray) -> list[str]:
    """The image-plane shape facts that hold of a polygon (n, 2) exactly (ground truth, no spread)."""
    c, s = polygon_angles(poly)
    out = []
    if np.any(np.abs(c - 90.0) <= RIGHT_ANGLE_DEG):
        out.append("has_right_angle")
    if np.any(c < 90.0 - RIGHT_ANGLE_DEG):
        out.append("has_acute_angle")
    if np.any(c > 90.0 + RIGHT_ANGLE_DEG):
        out.append("has_obtuse_angle")
    equal = s.max() / max(s.min(), 1e-12) <= EQUAL_SIDES_RATIO
    if len(poly) == 4 and np.all(np.abs(c - 90.0) <= RIGHT_ANGLE_DEG):
        out.append("rectangle")
        if equal:
            out.append("square")
    if equal and c.max() - c.min() <= EQUAL_CORNERS_DEG:
        out.append("regular")
    return out
