"""Is a colour face's outline an ellipse rather than a polygon? A can's lid, a ball's silhouette and a cone's base
are circles, seen as ellipses; the colour path outlines every face as a polygon of its corners, so such a face
comes out as a hexagon or an octagon whose "corners" are points of a smooth curve.

The outline is measured, not its polygon: the image's edge pixels near the face's polygon (within a band a
fraction of the face's size wide, where the curve between two polygon vertices runs). Two models of those points
are compared on the same points by the same robust measure, the RMS distance of the nearest ``keep`` share of
them:

- the face's polygon itself (its straight sides between its corners);
- an ellipse fitted to the points (OpenCV's ``fitEllipseAMS``), refitted once on the points near the first fit.

A polygon's sides follow straight edges within the edge map's noise while an ellipse cuts across its corners; a
curve's edge pixels bulge off the polygon's chords while an ellipse follows them. The evidence is the log of the
ratio of the two residuals (polygon over ellipse), read through a logistic (:func:`elliptical_probability`). The
ellipse must also fit the points closely in units of its own size (its residual over its semi-minor axis): an
ellipse through a polygon's outline cuts across its corners by a few per cent of its size (``EllipseSettings``).

Degenerate outlines (fewer than ``min_points`` edge pixels, an ellipse whose axes are not finite or collapse,
an ellipse much larger or smaller than the face) give no measurement (None), never NaN.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.spatial import cKDTree

from ...outline_ellipse import OutlineEllipse
from ..polygons import area, outline_distance, pair_dots


@dataclass(frozen=True)
class EllipseSettings:
    """Thresholds of the outline's ellipse test, in scale-free units.

    ``band_rel`` (of the face's equivalent radius sqrt(area / pi)): edge pixels this near the polygon's outline
    are its outline. A circle outlined by a hexagon of its points lies up to r (1 - cos 30 deg) = 0.134 r off its
    chords; 0.2 takes in the arcs of any polygon the colour path leaves (6 vertices or more) with room for their
    vertices lying a little inside the curve. ``band_px`` (pixels): the band is never narrower (Canny's edge sits
    up to a pixel or two off the true step).
    ``min_points`` (edge pixels): fewer give no fit (an ellipse has 5 parameters; a few dozen pixels are a few
    sides' worth at the smallest face the colour path keeps).
    ``keep`` (share of the points): each model's residual is the RMS over the nearest share of the points, so
    that stray edge pixels in the band (a print, a neighbour's edge reaching a corner) weigh on neither.
    ``min_coverage`` (share of the ellipse's perimeter): the points must lie around the ellipse, not on an arc
    of it: samples of the fitted ellipse with an edge point within ``cover_px`` pixels.
    ``area_ratio`` (ellipse area over polygon area, both ways): the fitted ellipse must be the face's own, not
    one through a few of its sides.
    ``log_ratio_mid`` (natural log of polygon residual over ellipse residual) and ``log_ratio_scale``: the
    logistic of the model comparison. The ellipse must beat the polygon, not tie with it: at 0.15 its residual is
    14 % below the polygon's. On clean renders a hexagon's outline ties (-0.06 to 0.0: the ellipse cuts across its
    corners as far as the aliased sides wander off the polygon), a ball's and a lid's beat it by 0.22 to 0.96.
    ``rel_rms_mid`` (ellipse residual over its semi-minor axis) and ``rel_rms_scale``: the logistic of how well
    the ellipse fits in units of its size. The best ellipse through a regular hexagon's outline misses it by
    about 4 % of its radius (through a square's by 7 %), through a polygon seen obliquely or outlined among stray
    edge pixels by more (rendered polyhedra's faces 0.07-0.25); a circle's outline only by the edge map's noise
    (rendered balls and lids 0.01-0.07 clean). The probability is the product of the two logistics: both must
    hold."""

    band_rel: float = 0.2
    band_px: float = 3.0
    min_points: int = 20
    keep: float = 0.9
    min_coverage: float = 0.8
    cover_px: float = 2.0
    area_ratio: float = 1.5
    log_ratio_mid: float = 0.15
    log_ratio_scale: float = 0.07
    rel_rms_mid: float = 0.08
    rel_rms_scale: float = 0.01


SETTINGS = EllipseSettings()


def ellipse_polygon(center, axes, angle_deg: float, n: int = 180) -> np.ndarray:
    """``n`` points (n, 2) around the ellipse (semi-axes ``axes``, the first along ``angle_deg``)."""
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    a, b = axes
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    x, y = a * np.cos(t), b * np.sin(t)
    return np.stack([center[0] + c * x - s * y, center[1] + s * x + c * y], axis=1)


def _ring(center, axes, angle_deg: float) -> np.ndarray:
    """The ellipse as a closed polyline of about one point a pixel (at least 64)."""
    return ellipse_polygon(center, axes, angle_deg, int(np.clip(2 * math.pi * axes[0], 64, 4096)))


def _curve_distance(points: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Distance (m,) from each of ``points`` (m, 2) to the closed polyline ``ring`` (k, 2) of short sides: to the
    two sides at the ring's point nearest each (a k-d tree), which holds the nearest side's foot."""
    k = len(ring)
    i = cKDTree(ring).query(points)[1]
    best = np.full(len(points), np.inf)
    for a, b in ((i - 1) % k, i), (i, (i + 1) % k):
        start, step = ring[a], ring[b] - ring[a]
        rel = points - start
        t = np.clip(pair_dots(rel, step) / np.maximum(pair_dots(step, step), 1e-12), 0.0, 1.0)
        best = np.minimum(best, np.hypot(*(rel - t[:, None] * step).T))
    return best


def _trimmed_rms(d: np.ndarray, keep: float) -> float:
    k = max(1, int(math.ceil(keep * len(d))))
    return float(np.sqrt(np.mean(np.sort(d)[:k] ** 2)))


def _fit(points: np.ndarray):
    """(center, (semi-major, semi-minor), angle) of the AMS ellipse through ``points``, or None."""
    try:
        (cu, cv), (w, h), ang = cv2.fitEllipseAMS(points.astype(np.float32).reshape(-1, 1, 2))
    except cv2.error:
        return None
    vals = (cu, cv, w, h, ang)
    if not all(math.isfinite(float(x)) for x in vals) or min(w, h) <= 1e-6:
        return None
    if w >= h:
        return (float(cu), float(cv)), (0.5 * float(w), 0.5 * float(h)), float(ang)
    return (float(cu), float(cv)), (0.5 * float(h), 0.5 * float(w)), float(ang) + 90.0


def outline_points(poly: np.ndarray, edges: np.ndarray, settings: EllipseSettings = SETTINGS) -> np.ndarray:
    """Edge pixels (m, 2) (u, v) of ``edges`` (H, W, nonzero = edge) within the band around ``poly``'s outline."""
    poly = np.asarray(poly, np.float64)
    if len(poly) < 3 or not np.all(np.isfinite(poly)):
        return np.zeros((0, 2))
    band = max(settings.band_px, settings.band_rel * math.sqrt(max(area(poly), 0.0) / math.pi))
    h, w = edges.shape[:2]
    u0, v0 = np.floor(poly.min(axis=0) - band - 1).astype(int)
    u1, v1 = np.ceil(poly.max(axis=0) + band + 1).astype(int)
    u0, v0, u1, v1 = max(u0, 0), max(v0, 0), min(u1, w - 1), min(v1, h - 1)
    if u1 < u0 or v1 < v0:
        return np.zeros((0, 2))
    # the band as a mask over the crop (a thick outline, a pixel wider than asked), then the exact distance test
    mask = np.zeros((v1 - v0 + 1, u1 - u0 + 1), np.uint8)
    cv2.polylines(mask, [np.round(poly - (u0, v0)).astype(np.int32).reshape(-1, 1, 2)], True, 1,
                  thickness=2 * int(math.ceil(band)) + 3)
    vv, uu = np.nonzero(edges[v0:v1 + 1, u0:u1 + 1] * mask)
    pts = np.stack([uu + u0, vv + v0], axis=1).astype(np.float64)
    if not len(pts):
        return pts
    return pts[outline_distance(pts, poly) <= band]


def fit_outline(poly: np.ndarray, points: np.ndarray, settings: EllipseSettings = SETTINGS) -> OutlineEllipse | None:
    """The ellipse through a face's outline ``points`` (m, 2) beside its polygon ``poly`` (n, 2), or None where
    there are too few points or no ellipse of the face's own size fits them."""
    poly = np.asarray(poly, np.float64)
    points = np.asarray(points, np.float64).reshape(-1, 2)
    if len(poly) < 3 or len(points) < max(settings.min_points, 5) or not np.all(np.isfinite(points)):
        return None
    fit = _fit(points)
    if fit is None:
        return None
    # refit on the points near the first fit: stray pixels in the band pull AMS's algebraic fit
    d = _curve_distance(points, _ring(*fit))
    near = points[d <= max(settings.band_px, 3.0 * _trimmed_rms(d, settings.keep))]
    if len(near) >= max(settings.min_points, 5):
        fit = _fit(near) or fit
    center, axes, angle = fit
    a_poly = area(poly)
    a_ell = math.pi * axes[0] * axes[1]
    if a_poly <= 0 or not (1.0 / settings.area_ratio <= a_ell / a_poly <= settings.area_ratio):
        return None
    ring = _ring(center, axes, angle)
    # coverage: the ellipse's own samples near an edge point (the points go round it, not along one arc)
    cover = float(np.mean(cKDTree(points).query(ring)[0] <= settings.cover_px))
    if cover < settings.min_coverage:
        return None
    rms_e = _trimmed_rms(_curve_distance(points, ring), settings.keep)
    rms_p = _trimmed_rms(outline_distance(points, poly), settings.keep)
    if not (math.isfinite(rms_e) and math.isfinite(rms_p)):
        return None
    return OutlineEllipse(center, axes, angle, rms_e, rms_p, int(len(points)), int(len(poly)))


def elliptical_probability(e: OutlineEllipse | None, settings: EllipseSettings = SETTINGS) -> float | None:
    """The probability that the outline is an ellipse rather than its polygon: the product of a logistic of
    ln(polygon residual / ellipse residual) (the ellipse beats the polygon) and one of the ellipse's residual
    over its semi-minor axis (it fits within the edge map's noise), ``EllipseSettings``; None without a
    measurement."""
    if e is None:
        return None

    def logistic(z: float) -> float:
        return 1.0 / (1.0 + math.exp(-max(min(z, 50.0), -50.0)))

    better = logistic((e.log_ratio - settings.log_ratio_mid) / settings.log_ratio_scale)
    close = logistic((settings.rel_rms_mid - e.rel_rms) / settings.rel_rms_scale)
    return float(better * close)


def measure_face(poly: np.ndarray, edges: np.ndarray, settings: EllipseSettings = SETTINGS) -> OutlineEllipse | None:
    """:func:`fit_outline` on the edge pixels of ``edges`` around ``poly`` (:func:`outline_points`)."""
    return fit_outline(poly, outline_points(poly, edges, settings), settings)
