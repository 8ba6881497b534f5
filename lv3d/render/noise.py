"""Sensor and scene nuisances as named presets of independent knobs, and the functions that apply them.

Depth noise follows a stereo camera like the RealSense D435: sigma(z) = depth_sigma_base_m +
depth_sigma_k * z^2 (metres), about 1.5 mm at 0.5 m and 5 mm at 1.5 m with ``realsense``.
Every preset keeps the millimetre quantisation of a uint16 depth PNG.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

import cv2
import numpy as np

from ..errors import InputError

PRESETS = ("clean", "mild", "realsense", "hard")


@dataclass(frozen=True)
class NoiseConfig:
    """Knobs of one noise setting. Lengths in metres, sizes in pixels, intensities in uint8 levels."""

    preset: str = "clean"
    depth_sigma_base_m: float = 0.0    # depth noise sigma at z = 0 (metres)
    depth_sigma_k: float = 0.0         # depth noise grows as k * z^2 (1/metre)
    hole_blobs: int = 0                # number of random blobs without a depth reading
    hole_radius_px: float = 6.0        # mean blob radius at 640x480 (pixels; scaled with the image)
    grazing_deg: float = 90.0          # no depth where the view ray meets the surface beyond this angle
    flying_pixels: float = 0.0         # fraction of depth-edge pixels given a depth between fore and background
    color_sigma: float = 0.0           # additive Gaussian colour noise (uint8 levels)
    blur_px: float = 0.0               # Gaussian blur sigma of the colour image at 640x480 (pixels)
    jpeg_quality: int = 0              # JPEG round trip of the colour image; 0 = none
    exposure: float = 0.0              # log-normal sigma of a global brightness gain
    occluder: float = 0.0              # probability of a foreground object partly hiding the target
    clutter: int = 0                   # number of other solids beside the target (never touching it)
    distractor_lines: int = 0          # painted lines on the table
    texture: float = 0.0               # strength of blotchy texture on the table and the objects, 0..1
    table_grain: float = 0.15          # contrast of the table's wood grain (part of every scene)
    shadows: bool = False              # cast shadows of the directional light (edges that are no face edges)

    def to_dict(self) -> dict:
        return asdict(self)


_PRESET_KNOBS = {
    "clean": {},
    "mild": dict(depth_sigma_base_m=0.0005, depth_sigma_k=0.0008, hole_blobs=2, grazing_deg=85.0,
                 flying_pixels=0.1, color_sigma=2.0, blur_px=0.5, jpeg_quality=95, exposure=0.05,
                 clutter=1, table_grain=0.2, shadows=True),
    "realsense": dict(depth_sigma_base_m=0.001, depth_sigma_k=0.0018, hole_blobs=5, grazing_deg=78.0,
                      flying_pixels=0.3, color_sigma=4.0, blur_px=0.8, jpeg_quality=90, exposure=0.12,
                      occluder=0.3, clutter=2, distractor_lines=1, texture=0.15, table_grain=0.25, shadows=True),
    "hard": dict(depth_sigma_base_m=0.002, depth_sigma_k=0.004, hole_blobs=12, hole_radius_px=9.0,
                 grazing_deg=70.0, flying_pixels=0.6, color_sigma=8.0, blur_px=1.3, jpeg_quality=70,
                 exposure=0.25, occluder=0.7, clutter=4, distractor_lines=4, texture=0.4, table_grain=0.4, shadows=True),
}


def noise_config(preset: str = "clean", /, **overrides) -> NoiseConfig:
    """The knobs of ``preset`` with any of them overridden, e.g. ``noise_config("clean", clutter=2)``."""
    if preset not in PRESETS:
        raise InputError("noise", f"unknown noise preset {preset!r}; known: {', '.join(PRESETS)}")
    names = {f.name for f in fields(NoiseConfig)} - {"preset"}
    bad = sorted(set(overrides) - names)
    if bad:
        raise InputError("noise", f"unknown noise knob {bad[0]!r}; known: {', '.join(sorted(names))}")
    for name, value in overrides.items():
        _check_type(name, value)
    cfg = replace(NoiseConfig(preset=preset), **_PRESET_KNOBS[preset])
    return replace(cfg, **overrides)


_KINDS = {f.name: f.type for f in fields(NoiseConfig)}  # "float", "int" or "bool" (annotations are strings here)


def _check_type(name: str, value) -> None:
    """An InputError unless ``value`` fits knob ``name``: a bool is no number, a float no count."""
    kind = _KINDS[name]
    is_bool = isinstance(value, bool)
    ok = {"bool": is_bool, "int": isinstance(value, int) and not is_bool,
          "float": isinstance(value, (int, float)) and not is_bool}[kind]
    if not ok:
        says = {"bool": "true or false", "int": "a whole number", "float": "a number"}[kind]
        raise InputError("noise", f"knob {name!r} takes {says}, got {value!r}")


def as_config(noise: str | NoiseConfig) -> NoiseConfig:
    """A preset name or a NoiseConfig -> NoiseConfig."""
    if isinstance(noise, NoiseConfig):
        return noise
    if isinstance(noise, str):
        return noise_config(noise)
    raise InputError("noise", f"expected a preset name or NoiseConfig, got {type(noise).__name__}")


def gaussian(shape: tuple[int, ...], rng: np.random.Generator, sigma: float = 1.0) -> np.ndarray:
    """Normal float32 samples of ``shape`` with mean 0 and standard deviation ``sigma``, seeded from
    ``rng``. OpenCV's generator (per thread, reseeded here on every call, so still reproducible) is
    several times faster than numpy's (a 16-bit quantile table lookup was tried: no faster)."""
    cv2.setRNGSeed(int(rng.integers(1, 2**31 - 1)))
    out = np.empty((int(np.prod(shape)), 1), np.float32)  # one channel: a scalar std applies to channel 0 only
    cv2.randn(out, 0.0, float(sigma))
    return out.reshape(shape)


def noisy_depth(depth: np.ndarray, cos_incidence: np.ndarray | None, cfg: NoiseConfig,
                rng: np.random.Generator) -> np.ndarray:
    """Apply depth nuisances to ideal depth (H, W) float metres (0 = no hit); returns float32 metres
    quantised to whole millimetres. ``cos_incidence``: (H, W) cosine between view ray and surface normal
    (needed only when ``cfg.grazing_deg`` < 90)."""
    h, w = depth.shape
    f32 = np.float32  # float32 throughout: half the memory traffic of float64, and metres need no more
    z = depth.astype(np.float32)  # a copy: changed in place below
    valid = z > 0
    if cfg.flying_pixels > 0:
        # pixels on depth discontinuities take a mix of fore- and background, as stereo matching does
        hi = cv2.dilate(z, np.ones((3, 3), np.uint8))  # z is 0 where invalid
        lo = cv2.erode(np.where(valid, z, f32(1e3)), np.ones((3, 3), np.uint8))
        cand = np.flatnonzero(valid & (hi - lo > 0.03) & (lo < 1e3))
        # random numbers only for the few edge pixels, not the whole frame
        cand = cand[rng.random(len(cand), dtype=np.float32) < cfg.flying_pixels]
        lo_c, hi_c = lo.ravel()[cand], hi.ravel()[cand]
        z.ravel()[cand] = lo_c + rng.random(len(cand), dtype=np.float32) * (hi_c - lo_c)
    if cfg.depth_sigma_base_m > 0 or cfg.depth_sigma_k > 0:
        sigma = z * z
        sigma *= f32(cfg.depth_sigma_k)
        sigma += f32(cfg.depth_sigma_base_m)
        sigma *= gaussian((h, w), rng)
        z += sigma
    if cfg.grazing_deg < 90.0 and cos_incidence is not None:
        valid &= cos_incidence > np.cos(np.radians(cfg.grazing_deg))
    if cfg.hole_blobs > 0:
        holes = np.zeros((h, w), np.uint8)
        scale = w / 640.0
        for _ in range(cfg.hole_blobs):
            c = (int(rng.integers(0, w)), int(rng.integers(0, h)))
            ax = tuple(max(1, int(cfg.hole_radius_px * scale * rng.uniform(0.4, 1.8))) for _ in range(2))
            cv2.ellipse(holes, c, ax, float(rng.uniform(0, 180)), 0, 360, 1, -1)
        valid &= holes == 0
    valid &= z > 0
    z *= f32(1000)
    np.round(z, out=z)
    z /= f32(1000)
    z[~valid] = 0
    return np.clip(z, f32(0), f32(65.535), out=z)


def noisy_color(color: np.ndarray, cfg: NoiseConfig, rng: np.random.Generator) -> np.ndarray:
    """Apply colour nuisances (exposure, blur, sensor noise, JPEG) to an (H, W, 3) float image in 0..255;
    returns uint8 RGB."""
    img = color.astype(np.float32, copy=False)
    gain = float(np.exp(rng.normal(0.0, cfg.exposure))) if cfg.exposure > 0 else 1.0
    if cfg.blur_px > 0:
        s = cfg.blur_px * img.shape[1] / 640.0
        r = max(1, int(np.ceil(2.5 * s)))  # OpenCV's default kernel reaches 4 sigma: weights there are < 1e-3
        kernel = cv2.getGaussianKernel(2 * r + 1, s, cv2.CV_32F)
        img = cv2.sepFilter2D(img, -1, kernel * np.float32(gain), kernel)  # blur and exposure in one pass
    elif gain != 1.0:
        img = img * np.float32(gain)
    # one pass: add the noise, round to nearest (ties to even, as np.round) and saturate to 0..255
    noise = gaussian(img.shape, rng, cfg.color_sigma) if cfg.color_sigma > 0 else np.zeros_like(img)
    out = cv2.add(img, noise, dtype=cv2.CV_8U)
    if cfg.jpeg_quality > 0:
        ok, buf = cv2.imencode(".jpg", cv2.cvtColor(out, cv2.COLOR_RGB2BGR),
                               [cv2.IMWRITE_JPEG_QUALITY, int(cfg.jpeg_quality)])
        out = cv2.cvtColor(cv2.imdecode(buf, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
    return out
