"""Faint straight edges inside a traced colour face: the line from one of its corners to a point of its outline (or
three lines from three corners to one point inside: a fork) across which the smoothed colour steps, found by the
mean signed step along the line (sensor noise averages out over its length, while a mean gradient magnitude keeps
it) against the same step on the lines shifted off it to either side (texture and shading vary smoothly, so they
step there as much)."""

from __future__ import annotations

import itertools
from typing import NamedTuple

import cv2
import numpy as np

from ..polygons import area
from .split import reflex_corners


def smoothed_gradients(chans: list[np.ndarray], sigma_px: float = 1.0) -> np.ndarray:
    """(C, 2, H, W) float32: the x and y derivatives (grey levels per pixel) of each channel (H, W) after a
    Gaussian blur of ``sigma_px``."""
    out = []
    for c in chans:
        s = cv2.GaussianBlur(c.astype(np.float32), (0, 0), sigma_px)
        out.append((cv2.Sobel(s, cv2.CV_32F, 1, 0, ksize=3) / 8.0, cv2.Sobel(s, cv2.CV_32F, 0, 1, ksize=3) / 8.0))
    return np.asarray(out)


def line_samples(a: np.ndarray, b: np.ndarray, sample_px: float, trim_px: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points every ``sample_px`` along the lines from ``a`` (n, 2) to ``b`` (n, 2), ``trim_px`` left out at each
    end: the points (m, 2), the line each belongs to (m,), each line's count (n,) and unit normal (n, 2)."""
    d = b - a
    length = np.hypot(d[:, 0], d[:, 1])
    u = d / np.maximum(length, 1e-9)[:, None]
    count = np.maximum(((length - 2 * trim_px) // sample_px).astype(int) + 1, 0)
    owner = np.repeat(np.arange(len(a)), count)
    t = trim_px + sample_px * (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count))
    return a[owner] + t[:, None] * u[owner], owner, count, np.stack([-u[:, 1], u[:, 0]], axis=1)


def line_steps(pts: np.ndarray, owner: np.ndarray, nrm: np.ndarray, samples: np.ndarray, grads: np.ndarray,
               shift_px: float) -> tuple[np.ndarray, np.ndarray]:
    """How the colour steps across lines, from their samples ``pts`` (m, 2) pixels, ``owner`` (m,) the line each
    belongs to, ``nrm`` (n, 2) each line's unit normal and ``samples`` (n,) each line's sample count:
    per line and channel the mean derivative across it, (n, C) (``grads``: :func:`smoothed_gradients`), and the
    largest such step over the channels on the lines shifted ``shift_px`` to either side, (n,)."""
    _, _, h, w = grads.shape
    steps = []  # per offset: (lines, channels) mean derivative across the line
    for offset in (0.0, -shift_px, shift_px):
        c = pts + offset * nrm[owner]
        uu = np.clip(np.round(c[:, 0]).astype(int), 0, w - 1)
        vv = np.clip(np.round(c[:, 1]).astype(int), 0, h - 1)
        g = grads[:, :, vv, uu]                                    # (C, 2, m)
        across = g[:, 0] * nrm[owner, 0] + g[:, 1] * nrm[owner, 1]  # (C, m)
        steps.append(np.stack([np.bincount(owner, weights=x, minlength=len(nrm)) for x in across], axis=1)
                     / np.maximum(samples, 1)[:, None])
    return steps[0], np.maximum(np.abs(steps[1]).max(axis=1), np.abs(steps[2]).max(axis=1))


def _outline_points(p: np.ndarray, step_px: float) -> tuple[np.ndarray, np.ndarray]:
    """Points (m, 2) every ``step_px`` along each side of ``p`` (n, 2), corners left out, and the side (m,)
    each lies on (side k runs from corner k to corner k + 1)."""
    pts, side = [], []
    for k in range(len(p)):
        a, b = p[k], p[(k + 1) % len(p)]
        length = float(np.hypot(*(b - a)))
        t = step_px * np.arange(1, int(length // step_px)) / max(length, 1e-9)
        pts.append(a + t[:, None] * (b - a))
        side.append(np.full(len(t), k))
    return np.concatenate(pts).reshape(-1, 2), np.concatenate(side).astype(int)


def _depth_inside(p: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Distance (m,) in pixels from each of ``pts`` (m, 2) to the outside of polygon ``p`` (n, 2), read off a
    distance transform of its rasterised box (0 outside it)."""
    lo = np.floor(p.min(axis=0)).astype(int) - 1
    hi = np.ceil(p.max(axis=0)).astype(int) + 2
    mask = np.zeros((hi[1] - lo[1], hi[0] - lo[0]), np.uint8)
    cv2.fillPoly(mask, [np.round(p - lo).astype(np.int32)], 1)
    depth = cv2.distanceTransform(mask, cv2.DIST_L2, 3)
    q = np.round(pts - lo).astype(int)
    h, w = depth.shape
    return depth[np.clip(q[:, 1], 0, h - 1), np.clip(q[:, 0], 0, w - 1)]


class StepLines(NamedTuple):
    """The lines :func:`step_cut` tries on one outline, measured once for any of its tests: each line runs from
    corner ``corner`` (k,) to outline point ``point`` (k,) (of ``points`` (m, 2), lying on side ``side`` (m,)),
    ``length`` (k,) px long, with its clear ``samples`` (k,), ``peak`` step (k,) and ``control`` (k,)."""

    points: np.ndarray
    side: np.ndarray
    corner: np.ndarray
    point: np.ndarray
    length: np.ndarray
    samples: np.ndarray
    peak: np.ndarray
    control: np.ndarray


def step_lines(poly: np.ndarray, grads: np.ndarray, shift_px: float = 6.0, step_px: float = 2.0,
               sample_px: float = 2.0, trim_px: float = 3.0, sigma_px: float = 1.0) -> StepLines | None:
    """The lines from each corner of ``poly`` (n, 2, pixels) to points every ``step_px`` along the sides not at
    that corner, measured as :func:`step_cut` describes, or None when there are none."""
    p = np.asarray(poly, np.float64)
    n = len(p)
    q, side = _outline_points(p, step_px)
    if n < 3 or not len(q):
        return None
    corner = np.repeat(np.arange(n), len(q))
    point = np.tile(np.arange(len(q)), n)
    ok = (side[point] != corner) & (side[point] != (corner - 1) % n)
    corner, point = corner[ok], point[ok]
    a, b = p[corner], q[point]
    length = np.hypot(*(b - a).T)
    long = length > 2 * trim_px + sample_px
    corner, point, a, b, length = corner[long], point[long], a[long], b[long], length[long]
    if not len(a):
        return None
    measured = _measure(p, a, b, grads, shift_px, sample_px, trim_px, shift_px + 2 * sigma_px + 1.0)
    return None if measured is None else StepLines(q, side, corner, point, length, *measured)


def _measure(p: np.ndarray, a: np.ndarray, b: np.ndarray, grads: np.ndarray, shift_px: float, sample_px: float,
             trim_px: float, clear_px: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Each line's (``a`` (k, 2) to ``b`` (k, 2)) count of samples at least ``clear_px`` inside polygon ``p``, its
    step over them (largest over the channels) and its control, each (k,) (:func:`line_steps`), or None when no
    sample is clear."""
    pts, owner, _, nrm = line_samples(a, b, sample_px, trim_px)
    clear = _depth_inside(p, pts) >= clear_px
    owner, pts = owner[clear], pts[clear]
    samples = np.bincount(owner, minlength=len(a))
    if not len(pts):
        return None
    step, control = line_steps(pts, owner, nrm, samples, grads, shift_px)
    return samples, np.abs(step).max(axis=1), control


def _margin(samples: np.ndarray, peak: np.ndarray, control: np.ndarray, min_samples: int, min_step: float,
            rel_step: float) -> np.ndarray:
    """How far each line's step exceeds ``rel_step`` times its control where the line passes (at least
    ``min_samples`` clear samples, a step of at least ``min_step`` and ``rel_step`` times its control), else -inf."""
    passes = (samples >= min_samples) & (peak >= min_step) & (peak >= rel_step * control)
    return np.where(passes, peak - rel_step * control, -np.inf)


def step_cut(poly: np.ndarray, grads: np.ndarray, min_area_px: float, shift_px: float = 6.0,
             min_step: float = 1.0, rel_step: float = 3.0, min_samples: int = 15, step_px: float = 2.0,
             sample_px: float = 2.0, trim_px: float = 3.0, sigma_px: float = 1.0,
             lines: StepLines | None = None) -> list[np.ndarray] | None:
    """The two parts of ``poly`` (n, 2, pixels) cut along the line from a corner to a point of a side not at that
    corner, where the colour steps across it, or None. ``grads``: :func:`smoothed_gradients` (blurred by
    ``sigma_px``) in the polygon's pixel frame. A line's step is, per channel, the mean derivative across it over
    its samples (every ``sample_px``, ``trim_px`` left out at each end) lying ``shift_px`` + 2 ``sigma_px`` + 1 px
    or more inside the outline, so that the outline's own edge and the shifted lines stay out; its control is the
    largest such step on the line shifted ``shift_px`` to either side. A cut needs at least ``min_samples`` clear
    samples, a step (largest over the channels) of at least ``min_step`` grey levels per pixel and ``rel_step``
    times its control, and parts of at least ``min_area_px``. Of the lines that pass, the one whose step exceeds
    ``rel_step`` times its control by most is taken. ``lines``: the outline's :func:`step_lines`, when measured
    already (with the same ``shift_px``, ``step_px``, ``sample_px``, ``trim_px`` and ``sigma_px``). On realsense
    renders (dev seeds 1000-1004, true outlines), the colour difference 2 px to either side of the faint edge
    between two faces of one colour was about 4 times that 6 px off where the edge could be seen at all (cube
    1004's top and front, 8.6 grey levels; a pentagonal prism's top and side, 10); of nine such edges, five stood
    out 2.2 times or less. Clean renders gain too (a thin top face whose edge is faint)."""
    p = np.asarray(poly, np.float64)
    n = len(p)
    if lines is None:
        lines = step_lines(p, grads, shift_px, step_px, sample_px, trim_px, sigma_px)
    if lines is None:
        return None
    q, side = lines.points, lines.side
    long = lines.length > 2 * trim_px + sample_px * min_samples
    score = np.where(long, _margin(lines.samples, lines.peak, lines.control, min_samples, min_step, rel_step),
                     -np.inf)
    for k in sorted(np.flatnonzero(np.isfinite(score)), key=lambda k: (-score[k], k)):
        i, j = int(lines.corner[k]), int(lines.point[k])
        s = int(side[j])
        ring = np.roll(p, -i, axis=0)  # corner i first; side s now runs from ring[s - i] to the next corner
        s = (s - i) % n
        first = np.concatenate([ring[:s + 1], q[j][None]])
        second = np.concatenate([q[j][None], ring[s + 1:], ring[:1]])
        if min(area(first), area(second)) >= min_area_px:
            return [first, second]
    return None


def fork_cut(poly: np.ndarray, grads: np.ndarray, min_area_px: float, shift_px: float = 6.0,
             min_step: float = 0.5, rel_step: float = 3.0, min_samples: int = 10, grid_px: float = 4.0,
             sample_px: float = 2.0, trim_px: float = 3.0, sigma_px: float = 1.0) -> list[np.ndarray] | None:
    """The three parts of a convex ``poly`` (n, 2, pixels) cut along three lines from three of its corners to one
    point inside, where the colour steps across each line, or None: a solid showing three faces of one colour,
    traced as its silhouette alone, whose three inner edges meet at a fork (a trihedral corner seen from outside).
    Each line is tested as in :func:`step_cut` (``min_samples`` clear samples, a step of ``min_step`` and
    ``rel_step`` times its control), leaving out its last ``2 * shift_px`` before the fork, where the shifted
    control lines cross the other two edges. The fork is searched on a grid every ``grid_px``, then about the best
    point every pixel; of the triples of corners whose three lines pass, the one whose weakest line exceeds its
    test by most is taken; each part must be at least ``min_area_px``. ``min_step`` is half step_cut's: three lines
    must pass together, and the faint edge between two sides of a pentagonal prism of one colour (clean dev seed
    4004, 2 grey levels apart) steps by 0.58 grey levels per pixel."""
    p = np.asarray(poly, np.float64)
    if len(p) < 5 or len(reflex_corners(p)):
        return None
    clear_px = shift_px + 2 * sigma_px + 1.0
    args = (grads, shift_px, min_step, rel_step, min_samples, sample_px, trim_px)
    lo, hi = p.min(axis=0), p.max(axis=0)
    gx, gy = np.meshgrid(np.arange(lo[0], hi[0], grid_px), np.arange(lo[1], hi[1], grid_px))
    coarse = np.stack([gx.ravel(), gy.ravel()], axis=1)
    best = _best_fork(p, coarse[_depth_inside(p, coarse) >= clear_px], *args, clear_px)
    if best is None:
        return None
    off = np.arange(-grid_px, grid_px + 1)
    fine = best[1] + np.stack(np.meshgrid(off, off), axis=-1).reshape(-1, 2)
    finer = _best_fork(p, fine[_depth_inside(p, fine) >= clear_px], *args, clear_px)
    if finer is not None and finer[0] > best[0]:
        best = finer
    return _fork_parts(p, best, min_area_px)


def _best_fork(p, cand, grads, shift_px, min_step, rel_step, min_samples, sample_px, trim_px, clear_px):
    """(score, fork point, corners) of the best fork among the points ``cand`` (m, 2), or None."""
    n, m = len(p), len(cand)
    if not m:
        return None
    a = np.repeat(p, m, axis=0)          # corner k's lines to every candidate: rows k * m .. k * m + m - 1
    b = np.tile(cand, (n, 1))
    length = np.hypot(*(b - a).T)
    # the fork's end is trimmed by 2 * shift_px: lines from the corner stop short of it
    u = (b - a) / np.maximum(length, 1e-9)[:, None]
    b_trim = b - u * max(2 * shift_px - trim_px, 0.0)
    measured = _measure(p, a, b_trim, grads, shift_px, sample_px, trim_px, clear_px)
    if measured is None:
        return None
    score = _margin(*measured, min_samples, min_step, rel_step).reshape(n, m)  # (corner, candidate)
    ok = np.isfinite(score)
    best = None
    for c in np.nonzero(ok.sum(axis=0) >= 3)[0]:
        corners = np.nonzero(ok[:, c])[0]
        for tri in itertools.combinations(corners, 3):
            s = float(score[list(tri), c].min())
            if best is None or s > best[0]:
                best = (s, cand[c], tri)
    return best


def _fork_parts(p: np.ndarray, fork: tuple, min_area_px: float) -> list[np.ndarray] | None:
    """The three parts of ``p`` cut from its corners ``fork[2]`` (increasing) to the point ``fork[1]``."""
    _, j, (i, k, l) = fork
    n = len(p)
    parts = []
    for s, e in ((i, k), (k, l), (l, i + n)):
        ring = [p[t % n] for t in range(s, e + 1)]
        parts.append(np.concatenate([np.asarray(ring), j[None]]))
    if min(area(q) for q in parts) < min_area_px:
        return None
    return parts


def side_cut(poly: np.ndarray, grads: np.ndarray, min_area_px: float, shift_px: float = 6.0,
             min_step: float = 1.0, rel_step: float = 20.0, min_samples: int = 15, step_px: float = 6.0,
             sample_px: float = 2.0, trim_px: float = 3.0, sigma_px: float = 1.0, coarse: int = 3
             ) -> list[np.ndarray] | None:
    """The two parts of ``poly`` (n, 2, pixels) cut along the line from a point of one side to a point of
    another, where the colour steps across it, or None: two faces of one colour whose shared edge ends on the
    outline's sides, not at its corners (the top and front of a cube whose left sides run on in one line).
    Each line is measured as in :func:`step_cut`. The ends are searched every ``step_px`` along the sides; the
    ``coarse`` lines whose step exceeds their control by most are then moved every pixel up to ``step_px`` along
    their sides, and the best that passes the test is taken (``min_samples`` clear samples, a step of
    ``min_step`` and ``rel_step`` times its control); the parts must be at least ``min_area_px``.
    ``rel_step`` is far above step_cut's: thousands of lines are tried, and noise steps on some. On noisy
    renders, lines that step 3 times their control are mostly noise, stepping up to about 15 times; on clean
    renders, whose faces are flat, true cuts step thousands of times their control."""
    p = np.asarray(poly, np.float64)
    n = len(p)
    q, side = _outline_points(p, step_px)
    if n < 3 or len(q) < 2:
        return None
    i, j = np.triu_indices(len(q), 1)
    ok = side[i] != side[j]
    i, j = i[ok], j[ok]
    clear_px = shift_px + 2 * sigma_px + 1.0
    measured = _lines_measured(p, q[i], q[j], grads, shift_px, sample_px, trim_px, clear_px, min_samples)
    if measured is None:
        return None
    a, b, samples, peak, control = measured
    rough = _margin(samples, peak, control, min_samples, min_step, 1.0)
    off = np.arange(-step_px, step_px + 1)
    best = None
    for k in np.argsort(-rough, kind="stable")[:coarse]:
        if not np.isfinite(rough[k]):
            break
        sa, sb = _side_of(p, a[k]), _side_of(p, b[k])
        ua, ub = (_unit(p[(s + 1) % n] - p[s]) for s in (sa, sb))
        fa = np.repeat(a[k] + off[:, None] * ua, len(off), axis=0)
        fb = np.tile(b[k] + off[:, None] * ub, (len(off), 1))
        fine = _lines_measured(p, fa, fb, grads, shift_px, sample_px, trim_px, clear_px, min_samples)
        if fine is None:
            continue
        score = _margin(*fine[2:], min_samples, min_step, rel_step)
        m = int(np.argmax(score))
        if np.isfinite(score[m]) and (best is None or score[m] > best[0]):
            best = (float(score[m]), fine[0][m], fine[1][m])
    if best is None:
        return None
    _, a, b = best
    sa, sb = _side_of(p, a), _side_of(p, b)
    if sa == sb:
        return None
    if sa > sb:
        a, b, sa, sb = b, a, sb, sa
    first = np.concatenate([a[None], p[sa + 1:sb + 1], b[None]])
    second = np.concatenate([b[None], p[sb + 1:], p[:sa + 1], a[None]])
    if min(area(first), area(second)) < min_area_px:
        return None
    # an end moved onto a corner repeats it
    return [q[np.hypot(*(q - np.roll(q, 1, axis=0)).T) > 1e-9] for q in (first, second)]


def _unit(d: np.ndarray) -> np.ndarray:
    return d / max(float(np.hypot(*d)), 1e-9)


def _side_of(p: np.ndarray, x: np.ndarray) -> int:
    """The side of ``p`` (side k runs from corner k to corner k + 1) nearest to the point ``x``."""
    a, b = p, np.roll(p, -1, axis=0)
    d = b - a
    t = np.clip(((x - a) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-9), 0.0, 1.0)
    return int(np.argmin(np.hypot(*(a + t[:, None] * d - x).T)))


def _lines_measured(p, a, b, grads, shift_px, sample_px, trim_px, clear_px, min_samples):
    """The lines from ``a`` (k, 2) to ``b`` (k, 2) long enough for ``min_samples`` samples, with their clear
    samples, steps and controls (:func:`_measure`): (a, b, samples, peak, control), or None."""
    long = np.hypot(*(b - a).T) > 2 * trim_px + sample_px * min_samples
    a, b = a[long], b[long]
    if not len(a):
        return None
    measured = _measure(p, a, b, grads, shift_px, sample_px, trim_px, clear_px)
    return None if measured is None else (a, b, *measured)
