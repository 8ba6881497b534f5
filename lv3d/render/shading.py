"""Colour of every pixel: Lambertian shading under a directional light plus ambient, cast shadows,
per-face albedo of the solids, a wood-grain table, a tiled floor and a plain wall. All vectorised over
pixels; images are float RGB in 0..255 before sensor noise."""

from __future__ import annotations

import colorsys

import cv2
import numpy as np

from .appearance import paint_prints
from .noise import NoiseConfig
from .raycast import Hits, ray_planes
from .sampler import Layout


def object_albedo(n_faces: int, rng: np.random.Generator) -> np.ndarray:
    """(n_faces, 3) RGB albedo in 0..1: one random colour, each face brightened or darkened a different
    amount (a low-discrepancy sequence, so neighbouring face ids never get the same factor)."""
    h = rng.uniform(0, 1)
    rgb = np.array(colorsys.hsv_to_rgb(h, rng.uniform(0.2, 0.75), rng.uniform(0.55, 0.95)))
    phase = rng.uniform(0, 1)
    factor = 0.78 + 0.34 * ((np.arange(n_faces) * 0.618034 + phase) % 1.0)
    return np.clip(rgb[None, :] * factor[:, None], 0, 1)


def environment_colour(role: str, rng: np.random.Generator) -> np.ndarray:
    """Base RGB albedo (3,) in 0..1 of the table (a wood tone), the floor or the wall."""
    if role == "table":
        return np.array(colorsys.hsv_to_rgb(rng.uniform(0.05, 0.11), rng.uniform(0.35, 0.65), rng.uniform(0.45, 0.8)))
    if role == "floor":
        return np.array(colorsys.hsv_to_rgb(rng.uniform(0.0, 0.15), rng.uniform(0.0, 0.15), rng.uniform(0.3, 0.5)))
    return np.array(colorsys.hsv_to_rgb(rng.uniform(0.05, 0.6), rng.uniform(0.0, 0.12), rng.uniform(0.65, 0.85)))


def _wavy(x: np.ndarray, y: np.ndarray, rng: np.random.Generator, n: int, wavelength: tuple[float, float]) -> np.ndarray:
    """Sum of ``n`` random plane waves over coordinates (metres), scaled to about -1..1 (float32: the
    vectorised float32 sine is several times faster than float64)."""
    out = np.zeros(x.shape, np.float32)
    for _ in range(n):
        a = rng.uniform(0, 2 * np.pi)
        f = 2 * np.pi / rng.uniform(*wavelength)
        cx, cy, ph = (np.float32(c) for c in (f * np.cos(a), f * np.sin(a), rng.uniform(0, 2 * np.pi)))
        out += np.sin(cx * x + cy * y + ph)
    return out * np.float32(1 / np.sqrt(n))


def wood_warp(xt: np.ndarray, yt: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The slow wobble (metres) of the wood grain's stripes at table coordinates (metres)."""
    f32 = np.float32
    return f32(0.012) * _wavy(xt * f32(0.2), yt, rng, 3, (0.1, 0.4)) + f32(0.004) * _wavy(xt, yt, rng, 2, (0.03, 0.08))


def wood_grain(yt: np.ndarray, warp: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Wood grain in 0..1: stripes along the table's x at table coordinate ``yt`` (metres), shifted by
    ``warp`` (metres, from :func:`wood_warp`)."""
    f32 = np.float32
    period = rng.uniform(0.008, 0.025)
    g = np.sin(f32(2 * np.pi / period) * (yt + warp))
    g = f32(0.5) + f32(0.5) * g
    out = g * g
    out *= g
    out *= f32(0.7)
    out += f32(0.15) + f32(0.15) * np.sin(f32(2 * np.pi / (period * 0.37)) * (yt + f32(0.7) * warp))
    return out


def _coords(hits: Hits, idx: np.ndarray, cam_to_frame: np.ndarray, n: int = 3) -> tuple[np.ndarray, ...]:
    """The first ``n`` coordinates (x, y, z), each (m,) float32 metres, in some frame of the hit points at
    flat pixel indices ``idx``; ``cam_to_frame`` (4, 4) maps camera-frame points into that frame."""
    z = hits.depth.ravel()[idx]
    rx, ry = (c.ravel()[idx] for c in ray_planes(hits.depth.shape, hits.rays))
    a = cam_to_frame.astype(np.float32)
    return tuple(z * (a[i, 0] * rx + a[i, 1] * ry + a[i, 2]) + a[i, 3] for i in range(n))


class _LowRes:
    """Hit points on every ``step``-th pixel in each direction, for the slowly varying textures: they are
    computed on a fraction of the pixels and upsampled bilinearly (their wavelengths span many pixels)."""

    def __init__(self, hits: Hits, step: int):
        self.shape = hits.depth.shape
        self.z = hits.depth[::step, ::step]
        self.rx, self.ry = (np.ascontiguousarray(c[::step, ::step]) for c in ray_planes(self.shape, hits.rays))

    def coords(self, cam_to_frame: np.ndarray) -> tuple[np.ndarray, ...]:
        """(x, y, z), each (H/step, W/step) float32 metres, in the frame ``cam_to_frame`` (4, 4) maps into."""
        a = cam_to_frame.astype(np.float32)
        return tuple(self.z * (a[i, 0] * self.rx + a[i, 1] * self.ry + a[i, 2]) + a[i, 3] for i in range(3))

    def plane_coords(self, cam_to_frame: np.ndarray) -> tuple[np.ndarray, ...]:
        """Like :meth:`coords`, but of the points where the rays meet the plane z = 0 of that frame
        (not of what they hit): smooth across silhouettes, so upsampling blends nothing unrelated. Rays
        that never meet the plane get the camera centre."""
        a = cam_to_frame.astype(np.float32)
        # z = 0 in the frame: a[2] . (t * ray) + a[2, 3] = 0
        den = a[2, 0] * self.rx + a[2, 1] * self.ry + a[2, 2]
        t = np.where(den * a[2, 3] < 0, -a[2, 3] / np.where(den == 0, np.float32(1), den), np.float32(0))
        return tuple(t * (a[i, 0] * self.rx + a[i, 1] * self.ry + a[i, 2]) + a[i, 3] for i in range(3))

    def up(self, field: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """The low-resolution ``field`` upsampled to full resolution, at flat pixel indices ``idx``."""
        h, w = self.shape
        return cv2.resize(field, (w, h), interpolation=cv2.INTER_LINEAR).ravel()[idx]


def _table(hits: Hits, low: _LowRes, idx: np.ndarray, cam_to_table: np.ndarray, cfg: NoiseConfig,
           rng: np.random.Generator) -> np.ndarray:
    """Texture factor (m,) of the table at flat pixel indices ``idx``: wood grain and painted lines."""
    f32 = np.float32
    xl, yl, _ = low.plane_coords(cam_to_table)  # the table top's plane
    warp = low.up(wood_warp(xl, yl, rng), idx)
    xt, yt = _coords(hits, idx, cam_to_table, 2)
    m = f32(1.0) - f32(cfg.table_grain) * wood_grain(yt, warp, rng)
    for _ in range(cfg.distractor_lines):
        ang = rng.uniform(0, np.pi)
        dist = np.abs(f32(np.cos(ang)) * xt + f32(np.sin(ang)) * yt - f32(rng.uniform(-0.25, 0.25)))
        paint = f32(rng.choice([0.15, 1.9]))  # dark or light paint, relative to the wood
        m = np.where(dist < f32(rng.uniform(0.002, 0.006)), paint, m)
    return m


def shade(hits: Hits, layout: Layout, roles: list[str], albedo: list[np.ndarray], light_cam: np.ndarray,
          cfg: NoiseConfig, rng: np.random.Generator, prints: list | None = None) -> np.ndarray:
    """(H, W, 3) float32 RGB 0..255 of the scene. ``roles``: per body 'table', 'floor', 'wall' or an object
    role; ``albedo``: per body (faces, 3) albedo in 0..1 (a curved solid: per facet). Albedo and Lambert
    term are per face (flat faces, directional light), looked up through ``hits.gface``, but per pixel on
    curved faces (``hits.curved_normal``); printed designs (``prints``, see
    :func:`lv3d.render.appearance.paint_prints`) replace the albedo where they are; textures scale it
    per pixel."""
    f32 = np.float32
    ambient = rng.uniform(0.28, 0.42)
    # colour = albedo (per face, RGB) * intensity (per pixel, grey), with intensity =
    # (255 ambient + diffuse * (1 - shadow)) * texture; one (H, W, 3) lookup and one product
    alb_lut = np.concatenate(albedo + [np.full((1, 3), 0.16 / ambient)]).astype(np.float32)  # last: nothing hit
    lambert = np.append(np.clip(hits.face_normal @ light_cam, 0.0, None), 0.0)
    diffuse = (255 * (1.0 - ambient) * 1.1 * lambert).astype(np.float32)
    gface = hits.gface  # -1 (nothing hit) picks the last rows
    intensity = np.take(diffuse, gface)
    if len(hits.curved_idx):  # curved faces: the true surface's normal at every pixel, smooth
        lam = np.clip(hits.curved_normal @ light_cam, 0.0, None)
        intensity.ravel()[hits.curved_idx] = (255 * (1.0 - ambient) * 1.1 * lam).astype(np.float32)
    if np.any(hits.shadow):
        intensity *= f32(1.0) - hits.shadow
    intensity += f32(255 * ambient)
    mod = np.ones(hits.depth.shape, np.float32).ravel()
    body = hits.body.ravel()
    w2c = layout.world_to_camera
    c2w = np.linalg.inv(w2c)
    half = _LowRes(hits, 2)  # blotches: 2-8 cm, also on the solids up close
    quarter = _LowRes(hits, 4)  # wood warp (>= 3 cm, on the table) and the wall's shading (>= 0.5 m)
    for i, role in enumerate(roles):
        if role not in ("floor", "wall", "table"):
            continue
        idx = np.flatnonzero(body == i)
        if role == "floor":
            x, y = _coords(hits, idx, c2w, 2)
            mod[idx] = f32(0.9) + f32(0.1) * ((np.floor(x / f32(0.3)) + np.floor(y / f32(0.3))) % 2)
        elif role == "wall":
            x, y, z = quarter.coords(c2w)
            mod[idx] = f32(0.95) + f32(0.05) * quarter.up(_wavy(x + y, z, rng, 2, (0.5, 2.0)), idx)
        else:
            mod[idx] = _table(hits, quarter, idx, np.linalg.inv(w2c @ layout.table_to_world), cfg, rng)
    if cfg.texture > 0:  # on the table and the solids (roles after the background)
        first_solid = next(i for i, r in enumerate(roles) if r not in ("table", "floor", "wall"))
        idx = np.flatnonzero((body >= first_solid) | (body == roles.index("table")))
        x, y, z = half.coords(c2w)
        blotch = f32(0.5) + f32(0.5) * np.tanh(f32(1.5) * _wavy(x + f32(0.7) * z, y - f32(0.5) * z, rng, 4,
                                                                 (0.02, 0.08)))
        mod[idx] *= f32(1.0) - f32(cfg.texture) * half.up(blotch, idx)
    intensity *= mod.reshape(hits.depth.shape)
    img = np.take(alb_lut, gface, axis=0)
    if prints:
        paint_prints(img, hits, prints)
    img *= intensity[..., None]
    return np.clip(img, 0, 255, out=img)
