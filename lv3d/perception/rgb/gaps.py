"""Gaps in an image edge closed: a line segment carried on past its end to the next segment its line meets, where
the colour still steps across the way there.

LSD stops where an edge's contrast dips (noise, blur, a textured background with the object's colour, two faces of
one shade), so a face's outline reaches the planar graph in pieces that leave its corners open. Carrying every
segment on a long way (build_graph's reach) joins texture to texture as readily and breaks clean faces; here a
segment is carried on only where the colour steps across the whole way there, as it steps across the segment
itself (step_edge.py's test: the mean signed derivative across the line, against the same on the lines shifted to
either side, where texture and shading step as much).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .segments import merge_collinear
from .step_edge import line_samples, line_steps


def _steps(a: np.ndarray, b: np.ndarray, grads: np.ndarray, shift_px: float, sample_px: float = 1.0,
           trim_px: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For lines from ``a`` (m, 2) to ``b`` (m, 2): per channel, the mean derivative across each line over its
    samples (every ``sample_px``, ``trim_px`` left out at each end), (m, C); the largest such step on the lines
    shifted ``shift_px`` to either side, (m,); and each line's sample count (m,)."""
    pts, owner, count, nrm = line_samples(a, b, sample_px, trim_px)
    step, control = line_steps(pts, owner, nrm, count, grads, shift_px)
    return step, control, count


def close_gaps(segs: np.ndarray, grads: np.ndarray, min_len_px: float = 10.0, max_gap_px: float = 60.0,
               rel_gap: float = 1.5, min_gap_px: float = 3.0, min_angle_deg: float = 12.0,
               reach_px: float = 10.0, rel_reach: float = 0.35, collinear_deg: float = 4.0,
               collinear_px: float = 2.0, shift_px: float = 5.0, min_step: float = 1.0,
               rel_step: float = 3.0, min_samples: int = 4) -> np.ndarray:
    """Segments (n, 4) with ends carried on across gaps in their edges, collinear pieces then merged
    (segments.merge_collinear). ``grads``: step_edge.smoothed_gradients of the image the segments were found in.

    Each end of a segment at least ``min_len_px`` long looks ahead along its line, from ``min_gap_px`` up to
    ``min(max_gap_px, rel_gap * length)``, for the nearest place where it meets another segment at least
    ``min_len_px`` long: that segment's line crossing at least ``min_angle_deg`` off, within its extent widened
    by ``min(reach_px, rel_reach * its length)`` (build_graph's reach), or that segment running on along the same
    line (within ``collinear_deg`` and ``collinear_px``). The end is carried there when the way there steps in
    colour: at least ``min_samples`` samples, a step (largest over the channels) of at least ``min_step`` grey
    levels per pixel and ``rel_step`` times the step on the lines shifted ``shift_px`` to either side, and in the
    direction the segment itself steps (the two step vectors over the channels agree in sign)."""
    out = segs.copy()
    p0, p1 = segs[:, :2], segs[:, 2:]
    length = np.hypot(*(p1 - p0).T)
    idx = np.nonzero(length >= min_len_px)[0]  # only long segments are carried on, or carried to
    if len(idx) < 2:
        return out
    p0, p1, length = p0[idx], p1[idx], length[idx]
    u = (p1 - p0) / length[:, None]
    n = len(idx)
    reach = np.minimum(reach_px, rel_reach * length)
    limit = np.minimum(max_gap_px, rel_gap * length)
    # each end of i (0: p0, looking back along -u; 1: p1, looking on along u) against the segments j near enough
    # to be met: any point of j within the end's look-ahead, found among points every ``probe_px`` along each
    probe_px = 5.0
    count = (length // probe_px).astype(int) + 2
    owner = np.repeat(np.arange(n), count)
    frac = (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)) / np.repeat(count - 1, count)
    probes = cKDTree(p0[owner] + frac[:, None] * (p1 - p0)[owner])
    radius = limit + reach_px + probe_px
    near = probes.query_ball_point(np.concatenate([p0, p1]), np.concatenate([radius, radius]))
    k = np.repeat(np.arange(2 * n), [len(x) for x in near])           # end k: segment k % n, end k // n
    key = np.unique(k * n + owner[np.concatenate(near).astype(int)])  # each (end, j) once, in that order
    k, j = key // n, key % n
    i, e = k % n, k // n
    i, e, j = i[j != i], e[j != i], j[j != i]
    if not len(i):
        return out
    ahead = np.where(e[:, None] == 0, -u[i], u[i])
    origin = np.where(e[:, None] == 0, p0[i], p1[i])
    # j's line crossing i's forward ray: origin + g ahead = p0_j + s u_j
    cross = ahead[:, 0] * u[j, 1] - ahead[:, 1] * u[j, 0]
    dx, dy = (p0[j] - origin).T
    with np.errstate(divide="ignore", invalid="ignore"):
        g = (dx * u[j, 1] - dy * u[j, 0]) / cross
        s = (dx * ahead[:, 1] - dy * ahead[:, 0]) / cross
    crossing = (np.abs(cross) >= np.sin(np.radians(min_angle_deg))) & (s >= -reach[j]) & (s <= length[j] + reach[j])
    # j running on along i's line: both its ends near the line, the nearer one ahead
    qx, qy = (p1[j] - origin).T
    running_on = (np.abs(cross) <= np.sin(np.radians(collinear_deg))) & \
        (np.abs(dx * ahead[:, 1] - dy * ahead[:, 0]) <= collinear_px) & \
        (np.abs(qx * ahead[:, 1] - qy * ahead[:, 0]) <= collinear_px)
    along = np.minimum(dx * ahead[:, 0] + dy * ahead[:, 1], qx * ahead[:, 0] + qy * ahead[:, 1])
    g = np.where(running_on, along, np.where(crossing, g, np.inf))
    met = (g >= min_gap_px) & (g <= limit[i])
    i, e, g, origin, ahead = i[met], e[met], g[met], origin[met], ahead[met]
    # the nearest meeting of each end
    order = np.lexsort((g, e, i))
    if not len(order):
        return out
    first = order[np.r_[True, (np.diff(i[order]) != 0) | (np.diff(e[order]) != 0)]]
    i, e, origin = i[first], e[first], origin[first]
    target = origin + g[first, None] * ahead[first]
    own, _, _ = _steps(p0[i], p1[i], grads, shift_px)  # how each end's segment itself steps
    step, control, samples = _steps(origin, target, grads, shift_px)
    # the way there is read in the direction the segment runs: an end carried back from p0 runs against it
    sign = np.where(e == 0, -1.0, 1.0)
    peak = np.abs(step).max(axis=1)
    agree = np.sum(sign[:, None] * step * own, axis=1) > 0
    ok = (samples >= min_samples) & (peak >= min_step) & (peak >= rel_step * control) & agree
    for k in np.nonzero(ok)[0]:
        out[idx[i[k]], 2 * e[k]:2 * e[k] + 2] = target[k]
    return merge_collinear(out)
