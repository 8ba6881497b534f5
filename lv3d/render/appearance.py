"""What real objects look like beyond one flat colour: solids whose faces differ in hue, and faces
printed like packaging (label panels, bands, a round logo, rows of text-like blocks).

Prints are drawn in each face's own plane (metres), so they follow the face's perspective, lighting
and shadows exactly; they change the albedo only, never the geometry or the truth (a printed label is
no face). A face's frame: origin at the centroid of its vertices, ``s`` along its longest edge,
``t`` = normal x ``s`` in the face's plane. A curved face (a cylinder's, a cone's side, a sphere) is
printed on its unrolled surface: its frame is the object frame, and (s, t) are the arc length round the
axis and the height along it (:meth:`lv3d.render.curved.Curved.print_coords`), so a label wraps round a can.
"""

from __future__ import annotations

import colorsys
from dataclasses import dataclass

import numpy as np

from .curved import Curved
from .raycast import Hits, ray_planes
from .solids import Solid


def multi_hue_albedo(n_faces: int, rng: np.random.Generator) -> np.ndarray:
    """(n_faces, 3) RGB albedo in 0..1, a different hue on every face: hues step by the golden ratio of
    a turn (any two faces at least 0.09 of a turn apart for up to 8 faces), saturation 0.45-0.85 and
    value 0.5-0.95 drawn per face."""
    h0 = rng.uniform(0, 1)
    out = []
    for i in range(n_faces):
        h = (h0 + i * 0.618034) % 1.0
        out.append(colorsys.hsv_to_rgb(h, rng.uniform(0.45, 0.85), rng.uniform(0.5, 0.95)))
    return np.asarray(out, np.float64)


@dataclass(frozen=True)
class Shape:
    """A filled rectangle (``kind`` "rect", s0 <= s < s1, t0 <= t < t1) or ellipse ("ellipse", inscribed
    in that rectangle) in face coordinates (metres), of albedo ``rgb`` (0..1)."""

    kind: str
    s0: float
    s1: float
    t0: float
    t1: float
    rgb: tuple[float, float, float]


@dataclass(frozen=True)
class TextBlock:
    """Rows of text-like blocks: row r covers t0 + r pitch <= t < t0 + r pitch + letter_m; within it,
    ``words[r]`` lists (start, end) intervals along s (metres) cut into letters of pitch 0.7 letter_m
    with thin gaps between them."""

    t0: float
    pitch: float
    letter_m: float
    words: tuple[tuple[tuple[float, float], ...], ...]
    rgb: tuple[float, float, float]


@dataclass(frozen=True)
class Print:
    """The design printed on one face: ``frame`` (4, 4) maps face coordinates (s, t, 0) into the object
    frame; ``shapes`` are painted in order, then ``text``. ``wrap``: the curved surface whose unrolled
    coordinates (s, t) are (``frame`` is then the object frame), None for a planar face."""

    frame: np.ndarray
    shapes: tuple[Shape, ...]
    text: tuple[TextBlock, ...]
    wrap: Curved | None = None


def face_frame(solid: Solid, face: int) -> tuple[np.ndarray, np.ndarray]:
    """The frame of face ``face`` ((4, 4), face coordinates into the object frame) and the face's polygon
    (m, 2) in face coordinates (metres); of a curved face, the object frame and its unrolled rectangle."""
    if solid.curved is not None:
        if solid.curved.face_kinds()[face] != "plane":
            return np.eye(4), solid.curved.unrolled(face)
        face = solid.rep_facet(face)
    v = solid.vertices[list(solid.faces[face])]
    n = solid.normals()[face]
    edges = np.roll(v, -1, axis=0) - v
    e1 = edges[int(np.argmax(np.linalg.norm(edges, axis=1)))]
    e1 = e1 / np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    c = v.mean(axis=0)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = e1, e2, n, c
    return m, np.stack([(v - c) @ e1, (v - c) @ e2], axis=1)


def _value(rgb) -> float:
    return float(np.dot(rgb, [0.299, 0.587, 0.114]))


def _contrasting(rgb, rng: np.random.Generator) -> tuple[float, float, float]:
    """A print colour that stands out on ``rgb``: white a quarter of the time (labels), else another hue
    at least a quarter turn away, darker on light ground and lighter on dark ground."""
    if rng.random() < 0.25 and _value(rgb) < 0.7:
        return tuple(float(x) for x in colorsys.hsv_to_rgb(0.0, 0.0, rng.uniform(0.9, 1.0)))
    h = colorsys.rgb_to_hsv(*rgb)[0] + rng.uniform(0.25, 0.75)
    v = rng.uniform(0.15, 0.4) if _value(rgb) > 0.5 else rng.uniform(0.75, 1.0)
    return tuple(float(x) for x in colorsys.hsv_to_rgb(h % 1.0, rng.uniform(0.3, 0.9), v))


def _ink(rgb, rng: np.random.Generator) -> tuple[float, float, float]:
    """Text colour on ground ``rgb``: near black on light ground, near white on dark ground."""
    v = rng.uniform(0.04, 0.15) if _value(rgb) > 0.45 else rng.uniform(0.88, 1.0)
    return (v, v, v)


def _text(s0: float, s1: float, t0: float, t1: float, rgb, rng: np.random.Generator) -> TextBlock | None:
    """Rows of words filling part of the region [s0, s1] x [t0, t1] (metres); letters 4-12 mm tall."""
    letter = float(rng.uniform(0.004, 0.012))
    pitch = letter * float(rng.uniform(1.4, 1.9))
    if t1 - t0 < letter or s1 - s0 < 3 * letter:
        return None
    rows = min(int(rng.integers(1, 7)), int((t1 - t0 - letter) / pitch) + 1)
    words = []
    for _ in range(rows):
        end = s0 + (s1 - s0) * float(rng.uniform(0.5, 1.0))  # ragged right
        row, s = [], s0
        while True:
            w = letter * float(rng.uniform(1.5, 6.0))
            if s + w > end:
                break
            row.append((s, s + w))
            s += w + letter * float(rng.uniform(0.5, 0.9))
        words.append(tuple(row))
    return TextBlock(t0, pitch, letter, tuple(words), _ink(rgb, rng))


def design(solid: Solid, face: int, base_rgb, rng: np.random.Generator) -> Print:
    """A random packaging-like design for face ``face`` of ground colour ``base_rgb``: a label panel (half
    the faces) or a band across the face (three in ten), a round logo (a third), then one or two blocks
    of text rows (on the panel when there is one)."""
    frame, poly = face_frame(solid, face)
    lo, hi = poly.min(axis=0) * 0.9, poly.max(axis=0) * 0.9  # keep clear of the edges
    ext = hi - lo
    shapes: list[Shape] = []
    ground, region = tuple(float(x) for x in base_rgb), (lo[0], hi[0], lo[1], hi[1])
    pick = rng.random()
    if pick < 0.5:  # a label panel, 40-90 % of the face each way
        size = ext * rng.uniform(0.4, 0.9, 2)
        c = lo + size / 2 + rng.random(2) * (ext - size)
        rgb = _contrasting(ground, rng)
        (s0, t0), (s1, t1) = c - size / 2, c + size / 2
        shapes.append(Shape("rect", float(s0), float(s1), float(t0), float(t1), rgb))
        ground, region = rgb, (float(s0), float(s1), float(t0), float(t1))
    elif pick < 0.8:  # a band right across the face, 15-40 % of its height (or width)
        big = 1e3
        along_s = rng.random() < 0.7
        axis = 1 if along_s else 0
        w = ext[axis] * rng.uniform(0.15, 0.4)
        c = lo[axis] + w / 2 + rng.random() * (ext[axis] - w)
        rgb = _contrasting(ground, rng)
        shapes.append(Shape("rect", -big, big, c - w / 2, c + w / 2, rgb) if along_s
                      else Shape("rect", c - w / 2, c + w / 2, -big, big, rgb))
    if rng.random() < 0.35:  # a round logo
        r = float(min(ext) * rng.uniform(0.08, 0.25))
        c = lo + r + rng.random(2) * np.maximum(ext - 2 * r, 0)
        shapes.append(Shape("ellipse", c[0] - r, c[0] + r, c[1] - r, c[1] + r, _contrasting(ground, rng)))
    text = []
    if rng.random() < 0.85:
        s0, s1, t0, t1 = region
        for _ in range(int(rng.integers(1, 3))):
            ws, hs = (s1 - s0) * rng.uniform(0.3, 0.85), (t1 - t0) * rng.uniform(0.2, 0.6)
            a = s0 + rng.random() * (s1 - s0 - ws)
            b = t0 + rng.random() * (t1 - t0 - hs)
            block = _text(a, a + ws, b, b + hs, ground, rng)
            if block is not None:
                text.append(block)
    wrap = None
    if solid.curved is not None and solid.curved.face_kinds()[face] != "plane":
        wrap = solid.curved
    return Print(frame, tuple(shapes), tuple(text), wrap)


def design_prints(solid: Solid, albedo: np.ndarray, share: float, rng: np.random.Generator) -> dict[int, Print]:
    """Designs for the faces of ``solid`` (albedo (faces, 3)), each face printed with probability ``share``."""
    out = {}
    for i in range(solid.n_faces):
        if rng.random() < share:
            out[i] = design(solid, i, albedo[i], rng)
    return out


def _inside_text(s: np.ndarray, t: np.ndarray, b: TextBlock) -> np.ndarray:
    rel = (t - np.float32(b.t0)) / np.float32(b.pitch)
    row = np.floor(rel).astype(np.int64)
    on = (rel - row) * np.float32(b.pitch) < np.float32(b.letter_m)
    out = np.zeros(s.shape, bool)
    letter = np.float32(0.7 * b.letter_m)
    for r, words in enumerate(b.words):
        if not words:
            continue
        sel = on & (row == r)
        if not sel.any():
            continue
        bounds = np.asarray(words, np.float32).ravel()
        in_word = np.searchsorted(bounds, s[sel], side="right") % 2 == 1
        starts = bounds[0::2][np.maximum(np.searchsorted(bounds[0::2], s[sel], side="right") - 1, 0)]
        in_letter = ((s[sel] - starts) % letter) < np.float32(0.8) * letter  # thin gaps between letters
        out[np.flatnonzero(sel)[in_word & in_letter]] = True
    return out


def paint_prints(albedo: np.ndarray, hits: Hits, prints: list[tuple[int, np.ndarray, Print]]) -> None:
    """Paint printed designs into ``albedo`` ((H, W, 3) float per-pixel albedo, changed in place).
    ``prints``: (flat face index into ``hits``' face tables, camera-to-face (4, 4) transform, design)."""
    if not prints:
        return
    flat = albedo.reshape(-1, 3)
    gface = hits.gface.ravel()
    lut = np.full(len(hits.face_normal) + 1, -1, np.int64)  # flat face -> position in prints (last: none)
    for j, (g, _, _) in enumerate(prints):
        lut[g] = j
    sel = np.flatnonzero(np.take(lut, gface) >= 0)
    if len(sel) == 0:
        return
    which = lut[gface[sel]]
    order = np.argsort(which, kind="stable")
    sel, which = sel[order], which[order]
    cuts = np.searchsorted(which, np.arange(len(prints) + 1))
    z_all = hits.depth.ravel()
    rx_all, ry_all = (c.ravel() for c in ray_planes(hits.depth.shape, hits.rays))
    for j, (_, cam_to_face, pr) in enumerate(prints):
        idx = sel[cuts[j]:cuts[j + 1]]
        if len(idx) == 0:
            continue
        z, rx, ry = z_all[idx], rx_all[idx], ry_all[idx]
        a = cam_to_face.astype(np.float32)
        if pr.wrap is None:
            s, t = (z * (a[i, 0] * rx + a[i, 1] * ry + a[i, 2]) + a[i, 3] for i in range(2))
        else:
            s, t = pr.wrap.print_coords(*(z * (a[i, 0] * rx + a[i, 1] * ry + a[i, 2]) + a[i, 3] for i in range(3)))
        col = flat[idx]
        for sh in pr.shapes:
            if sh.kind == "rect":
                m = (s >= sh.s0) & (s < sh.s1) & (t >= sh.t0) & (t < sh.t1)
            else:
                cs, ct = (sh.s0 + sh.s1) / 2, (sh.t0 + sh.t1) / 2
                rs, rt = (sh.s1 - sh.s0) / 2, (sh.t1 - sh.t0) / 2
                m = ((s - np.float32(cs)) / np.float32(rs)) ** 2 + ((t - np.float32(ct)) / np.float32(rt)) ** 2 <= 1
            col[m] = sh.rgb
        for b in pr.text:
            col[_inside_text(s, t, b)] = b.rgb
        flat[idx] = col
