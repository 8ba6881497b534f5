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
    parent = list(range(n))  # plain lists: numpy scalar indexing costs more than the work here

    def find(i: int) -> int:
        root = i
        while parent[root] != root:
            root = parent[root]
        while parent[i] != root:  # path compression
            parent[i], i = root, parent[i]
        return root

    for i, j in np.asarray(pairs, int).reshape(-1, 2).tolist():
        a, b = find(i), find(j)
        if a != b:
            parent[max(a, b)] = min(a, b)
    return np.array([find(i) for i in range(n)], int)


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
    # only pairs of nearly parallel segments can merge: the other tests run on those pairs alone, both ways
    i, j = np.nonzero(np.triu(np.abs(u @ u.T) >= np.cos(np.radians(angle_deg)), 1))

    def ok(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """For pairs (a, b): b's ends within ``dist_px`` of a's line, and b overlapping a or near its ends."""
        def along(axis: np.ndarray, pts: np.ndarray) -> np.ndarray:
            return axis[a, 0] * (pts[b, 0] - p0[a, 0]) + axis[a, 1] * (pts[b, 1] - p0[a, 1])

        on_line = (np.abs(along(nrm, p0)) <= dist_px) & (np.abs(along(nrm, p1)) <= dist_px)
        t0, t1 = along(u, p0), along(u, p1)
        gap = np.maximum(np.minimum(t0, t1) - length[a], -np.maximum(t0, t1))
        return on_line & (gap <= gap_px)

    both = ok(i, j) & ok(j, i)
    i, j = i[both], j[both]
    labels = union_find_labels(n, np.stack([i, j], axis=1))
    alone = np.bincount(labels, minlength=n)[labels] == 1
    out = list(segs[alone])
    for lab in np.unique(labels[~alone]):
        idx = np.nonzero(labels == lab)[0]
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
