"""The support plane (table, desk, floor): seeded RANSAC, preferring a large plane that faces up in the image
over a wall or a cabinet front, then a least-squares refit.

RANSAC is done here in numpy rather than with open3d's ``segment_plane``: open3d draws its samples in parallel
threads, so even seeded (``o3d.utility.random.seed``) its model changes slightly from run to run, and perception
must be reproducible bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from matplotlib.path import Path

from ...plane import Plane, column_means
from .ranges import check_ranges


def refine(points: np.ndarray) -> Plane:
    """Least-squares plane through points (m, 3): the smallest principal direction of their scatter."""
    c = column_means(points)
    q = points - c
    _, vecs = np.linalg.eigh(q.T @ q)  # 3x3 scatter: cheaper than an SVD of all the points
    n = vecs[:, 0]
    return Plane.from_arrays(n, -float(n @ c))


def ransac_plane(points: np.ndarray, dist_m: float, rng: np.random.Generator, iterations: int = 128,
                 normals: np.ndarray | None = None, max_angle_deg: float = 25.0,
                 score_points: int = 600) -> tuple[Plane, np.ndarray]:
    """The plane with most inliers among ``iterations`` random triples of points (m, 3) metres, refitted by
    least squares until its inlier set is stable. Inliers lie within ``dist_m``; with ``normals`` (m, 3) their
    normal must also be within ``max_angle_deg`` of the plane's (zero normals never count).
    Returns the plane and the boolean inlier mask (m,)."""
    m = len(points)
    tri = rng.integers(0, m, size=(iterations, 3))
    a = points[tri[:, 0]]
    ab, ac = points[tri[:, 1]] - a, points[tri[:, 2]] - a
    n = np.empty_like(ab)  # ab x ac written out: np.cross costs more than the product on these small arrays
    n[:, 0] = ab[:, 1] * ac[:, 2] - ab[:, 2] * ac[:, 1]
    n[:, 1] = ab[:, 2] * ac[:, 0] - ab[:, 0] * ac[:, 2]
    n[:, 2] = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]
    norm = np.sqrt(np.einsum("ij,ij->i", n, n))
    good = norm > 1e-12
    n = n[good] / norm[good, None]
    d = -np.einsum("ij,ij->i", n, a[good])
    if len(n) == 0:
        return refine(points), np.ones(m, bool)
    cos_min = np.cos(np.radians(max_angle_deg))
    # score the hypotheses on a fixed subset of at most score_points points (preemptive RANSAC)
    sub = np.arange(m) if m <= score_points else np.sort(rng.choice(m, score_points, replace=False))
    dist = points[sub] @ n.T                                     # (s, k), made |distance| in place
    dist += d[None, :]
    inl = np.abs(dist, out=dist) <= dist_m
    if normals is not None:
        cos = normals[sub] @ n.T
        inl &= np.abs(cos, out=cos) >= cos_min
    best = int(np.argmax(np.count_nonzero(inl, axis=0)))
    plane = Plane.from_arrays(n[best], d[best])
    mask = np.zeros(m, bool)
    for _ in range(4):
        r = points @ plane.n
        r += plane.offset
        new = np.abs(r, out=r) <= dist_m
        if normals is not None:
            c = normals @ plane.n
            new &= np.abs(c, out=c) >= cos_min
        if np.count_nonzero(new) < 3 or np.array_equal(new, mask):
            mask = new
            break  # a stable inlier set refits to the same plane
        mask = new
        plane = refine(np.compress(mask, points, axis=0))
    return plane, mask


@dataclass(frozen=True)
class SensorNoise:
    """The depth sensor's noise as the depth stage allows for it: the inlier distance at depth z (metres), the
    farthest a reading may lie from a plane, sphere, cone or cylinder and still be on it, is
    ``base_m + per_m2 * z**2`` clipped to [``min_m``, ``max_m``]; the support's noise band and the snapping of
    polygon sides onto planes' intersections are multiples of it.

    ``base_m`` / ``per_m2`` (metres / metres per square metre of depth): a triangulating sensor (structured light,
    active stereo) reads depth from disparity, so its depth error is the disparity error times z^2 / (focal
    length x baseline) and grows as z^2; 4 mm + 4 mm/m^2 gives 6 mm at 0.7 m and 8 mm at 1 m, which holds a
    face's readings on the Kinect and RealSense dev frames together with the sensors' depth steps and slow
    warps across a face. On those frames the distance scaled by 0.6 splits faces (boxes with more than 3 faces
    0.101 -> 0.188) and by 1.5 merges a can's facets into fewer, flatter planes (cylinders read 0.662 -> 0.594;
    docs/perception.md, "The sensor's noise is a model").
    ``min_m`` / ``max_m`` (metres): the distance stays within 5 mm to 3 cm, so within 0.5 to 2.6 m of the
    camera; the labelled objects of the dev frames stand at 0.5 to 1.1 m, and the z^2 law is not carried far
    beyond them.

    A model of the sensor, not a measurement of the frame: :func:`~lv3d.perception.depth.cloud.slope_noise`
    measures the frame's pixel-to-pixel noise from second differences, which reads 0 on depth stored in whole
    millimetres (over half of those differences are 0 on the real dev frames). A sensor far from these (a
    time-of-flight camera, a noisier stereo pair) takes its own values: ``--set sensor.base_m=...`` in the
    benchmarks, ``lv3d.depth`` in a study's configuration (lv3d.experiment.config).
    """

    base_m: float = 0.004
    per_m2: float = 0.004
    min_m: float = 0.005
    max_m: float = 0.03

    def __post_init__(self) -> None:
        check_ranges(self, positive=("min_m", "max_m"))
        for name in ("base_m", "per_m2"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not 0 <= v < np.inf:
                raise ValueError(f"{name} is a number of at least 0, got {v!r}")
        if self.min_m > self.max_m:
            raise ValueError(f"min_m ({self.min_m!r}) must not exceed max_m ({self.max_m!r})")

    def inlier_m(self, z_m: float) -> float:
        """The inlier distance (metres) at depth ``z_m`` (metres)."""
        return float(np.clip(self.base_m + self.per_m2 * z_m ** 2, self.min_m, self.max_m))


SENSOR = SensorNoise()


def support_plane(points: np.ndarray, seed: int = 0, max_planes: int = 4, min_up: float = 0.3,
                  min_frac: float = 0.08, max_points: int = 4000, min_share: float = 0.35,
                  stand_rel: float = 0.1, min_standing: float = 0.01, inner: float = 0.85,
                  sensor: SensorNoise = SENSOR) -> Plane | None:
    """The support plane of camera-frame points (m, 3) metres, or None if no plane holds ``min_frac`` of them.

    Up to ``max_planes`` planes are peeled off by RANSAC; the candidates are those whose normal points up in the
    image (``-n_y >= min_up``, camera y is down). The support is chosen by what stands on it: the candidate with
    the most points on no plane found (objects) just above it, between its inlier distance and ``stand_rel`` of
    the scene's median depth, over the inner part of its extent (inside the convex hull of its inliers, seen along
    its normal, scaled by ``inner`` about its centre: what rises at its far edge is a wall or a cabinet). The lower parts of the objects on a table lie there; the floor beneath a small table has only the
    table's legs there, and an object's top face only what is stacked on it. Where no candidate has
    ``min_standing`` of the points standing on it (an empty table), the nearest of the candidates holding
    ``min_share`` of the largest one's points wins (a table stands above the floor). Without an upward plane
    the largest plane wins. Inlier distances are ``sensor``'s (:class:`SensorNoise`)."""
    rng = np.random.default_rng(seed)
    if len(points) > max_points:
        points = points[np.sort(rng.choice(len(points), max_points, replace=False))]
    if len(points) < 50:
        return None
    dist_m = sensor.inlier_m(float(np.median(points[:, 2])))
    remaining = points
    found: list[tuple[Plane, int]] = []
    inliers: list[np.ndarray] = []
    for _ in range(max_planes):
        if len(remaining) < min_frac * len(points):
            break
        if any(-p.normal[1] >= min_up and min_share * c > len(remaining) for p, c in found):
            break  # no plane left could hold min_share of an upward one found: none of them could win
        plane, mask = ransac_plane(remaining, dist_m, rng, iterations=200)
        count = int(np.count_nonzero(mask))
        if count < min_frac * len(points):
            break
        found.append((plane, count))
        inliers.append(remaining[mask])
        remaining = remaining[~mask]
    up = [(p, c) for p, c in found if -p.normal[1] >= min_up]
    if up and len(remaining):
        top = stand_rel * float(np.median(points[:, 2]))
        cands = [(p, q) for (p, _), q in zip(found, inliers) if -p.normal[1] >= min_up]
        # readings of a plane's own surface lie within a few noise widths of it at its own depth (a far floor's
        # noise is wider than the inlier distance at the scene's median depth): objects stand beyond twice that
        standing = [_standing(p, q, remaining, max(dist_m, 2 * sensor.inlier_m(float(np.median(q[:, 2])))), top,
                              [c for c in cands if c[0] is not p], inner) for p, q in cands]
        if max(standing) >= min_standing * len(points):
            return up[int(np.argmax(standing))][0]
    if up:
        # the top face of a large object near the camera faces up too: a support must also be among the
        # larger upward planes (>= min_share of the largest), and of those the nearest wins
        most = max(c for _, c in up)
        return min((p for p, c in up if c >= min_share * most), key=lambda p: p.offset)
    return found[0][0] if found else None


def _over(plane: Plane, inliers: np.ndarray, points: np.ndarray, shrink: float = 1.0) -> np.ndarray:
    """Which of ``points`` (m, 3) lie over the convex hull of ``inliers`` (k, 3) of ``plane``, seen along its
    normal, the hull scaled by ``shrink`` about its centre (m,) bool."""
    if len(inliers) < 3 or len(points) == 0:
        return np.zeros(len(points), bool)
    n = plane.n
    a = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    hull = cv2.convexHull(np.stack([inliers @ a, inliers @ b], axis=1).astype(np.float32))[:, 0, :].astype(np.float64)
    c = hull.mean(axis=0)
    hull = c + shrink * (hull - c)
    return Path(hull).contains_points(np.stack([points @ a, points @ b], axis=1))


def _standing(plane: Plane, inliers: np.ndarray, others: np.ndarray, low_m: float, high_m: float,
              rivals: list[tuple[Plane, np.ndarray]], inner: float) -> int:
    """How many of the points ``others`` (m, 3) stand on ``plane``: between ``low_m`` and ``high_m`` above it (on
    the camera's side), over the convex hull of its ``inliers`` (k, 3), and not beneath a rival plane (below it
    and over its inliers' hull: the sides of a table stand on the floor, but hold up the table)."""
    h = others @ plane.n + plane.offset
    near = others[(h > low_m) & (h <= high_m)]
    keep = _over(plane, inliers, near, inner)
    for p, q in rivals:
        keep &= ~((near @ p.n + p.offset < -low_m) & _over(p, q, near))
    return int(np.count_nonzero(keep))
