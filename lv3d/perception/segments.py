"""Line segments of a grey image: OpenCV's line segment detector, then collinear duplicates merged.

A segment array is (n, 4) float64 pixels: (u0, v0, u1, v1).
"""

from __future__ import annotations

import cv2
import numpy as np


def detect_segments(gray: np.ndarray, min_len_px: float = 8.0) -> np.ndarray:
    """Segments (n, 4) of a (H, W) uint8 grey image, at least ``min_len_px`` long, in a deterministic order."""
    lsd = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD)
    lines = lsd.detect(gray)[0]
    if lines is None:
        return np.zeros((0, 4))
    segs = lines.reshape(-1, 4).astype(np.float64)
    length = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    segs = segs[length >= min_len_px]
    return segs[np.lexsort((segs[:, 1], segs[:, 0]))]


def detect_color_segments(channels: list[np.ndarray], min_len_px: float = 8.0) -> np.ndarray:
    """Segments (n, 4) found in any of the given grey channels, collinear duplicates merged."""
    segs = np.concatenate([detect_segments(c, min_len_px) for c in channels], axis=0)
    return merge_collinear(segs)


def union_find_labels(n: int, pairs: np.ndarray) -> np.ndarray:
    """Connected-component label (smallest member index) of each of ``n`` items joined by ``pairs`` (m, 2)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pairs = np.asarray(pairs, int).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(pairs), np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    # name each component by its smallest member: components are numbered in order of first member already
    first = np.full(comp.max(initial=-1) + 1, n, int)
    np.minimum.at(first, comp, np.arange(n))
    return first[comp]


def merge_collinear(segs: np.ndarray, angle_deg: float = 4.0, dist_px: float = 2.0,
                    gap_px: float = 6.0) -> np.ndarray:
    """Merge segments that lie on one line (directions within ``angle_deg``, each end of one within ``dist_px``
    of the other's line) and overlap or leave a gap under ``gap_px``: LSD splits one image edge into pieces and
    finds both sides of a thin line. Each group becomes the total-least-squares line through its end points,
    clipped to their extent."""
    n = len(segs)
    if n < 2:
        return segs.copy()
    p0, p1 = segs[:, :2], segs[:, 2:]
    d = p1 - p0
    length = np.hypot(d[:, 0], d[:, 1])
    u = d / length[:, None]
    nrm = np.stack([-u[:, 1], u[:, 0]], axis=1)
    cosang = np.abs(u @ u.T)
    close_dir = cosang >= np.cos(np.radians(angle_deg))
    # distance of j's ends to i's line, and their positions along it
    def along(axis: np.ndarray, pts: np.ndarray) -> np.ndarray:
        dx = pts[None, :, 0] - p0[:, None, 0]
        dy = pts[None, :, 1] - p0[:, None, 1]
        return axis[:, None, 0] * dx + axis[:, None, 1] * dy

    on_line = (np.abs(along(nrm, p0)) <= dist_px) & (np.abs(along(nrm, p1)) <= dist_px)
    t0, t1 = along(u, p0), along(u, p1)
    lo, hi = np.minimum(t0, t1), np.maximum(t0, t1)
    gap = np.maximum(lo - length[:, None], -hi)
    near = gap <= gap_px
    ok = close_dir & on_line & near
    ok = ok & ok.T
    i, j = np.nonzero(np.triu(ok, 1))
    labels = union_find_labels(n, np.stack([i, j], axis=1))
    out = []
    for lab in np.unique(labels):
        idx = np.nonzero(labels == lab)[0]
        if len(idx) == 1:
            out.append(segs[idx[0]])
            continue
        pts = np.concatenate([p0[idx], p1[idx]], axis=0)
        w = np.concatenate([length[idx], length[idx]])
        c = (pts * w[:, None]).sum(0) / w.sum()
        cov = ((pts - c) * w[:, None]).T @ (pts - c)
        evals, evecs = np.linalg.eigh(cov)
        direction = evecs[:, 1]
        t = (pts - c) @ direction
        a, b = c + t.min() * direction, c + t.max() * direction
        out.append(np.concatenate([a, b]))
    out = np.array(out)
    return out[np.lexsort((out[:, 1], out[:, 0]))]
