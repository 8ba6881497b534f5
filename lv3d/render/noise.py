"""Sensor and scene nuisances as named presets of independent knobs, and the functions that apply them.

Depth noise follows a stereo camera like the RealSense D435: sigma(z) = depth_sigma_base_m +
depth_sigma_k * z^2 (metres), about 1.5 mm at 0.5 m and 5 mm at 1.5 m with ``realsense``.
Every preset keeps the millimetre quantisation of a uint16 depth PNG. The ``kinect`` and ``realsense``
depth models add what a triangulating sensor does beyond that noise: no reading where the projector
(Kinect) or the second imager (RealSense) cannot see the point, a band of failed matches along depth
edges, and depth quantised in disparity, so that its step grows with z^2.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

import cv2
import numpy as np

from ..errors import InputError

PRESETS = ("clean", "mild", "realsense", "hard", "realistic", "kinect")


@dataclass(frozen=True)
class DepthModel:
    """A triangulating depth sensor: the second viewpoint (a projector or a second imager) sits
    ``baseline_m`` to the right of the camera (+x); depth comes from the disparity f b / z (pixels),
    measured in steps of ``disparity_step_px``."""

    baseline_m: float
    disparity_step_px: float


# Kinect v1: projector 7.5 cm beside the IR camera, disparity in 1/8 pixel; RealSense D435: 5.0 cm
# stereo baseline, disparity in 1/32 pixel. "ideal": no sensor geometry (depth as ray cast).
DEPTH_MODELS = {"ideal": None, "kinect": DepthModel(0.075, 1 / 8), "realsense": DepthModel(0.050, 1 / 32)}
EDGE_JUMP_M = 0.03  # a depth discontinuity: neighbours more than this far apart in depth (metres)


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
    # appearance and scene knobs that real table tops have (docs/dataset.md); all off by default
    printed_faces: float = 0.0         # share of the solids' faces printed with labels, bands and text-like rows
    face_hues: float = 0.0             # probability that a solid has a different hue on each face
    touching: float = 0.0              # probability of a second solid standing against the target, in contact
    stacked: float = 0.0               # probability of a box on the target, or of the target on a box
    small_table: float = 0.0           # probability of a table 3-20 cm larger than what stands on it (floor beyond)
    depth_model: str = "ideal"         # sensor geometry: "ideal", "kinect" or "realsense" (DEPTH_MODELS)
    edge_dropout_px: float = 0.0       # band of missing depth on the far side of depth edges (pixels at 640x480)

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
    # a RealSense D435 on a cluttered table of printed packaging: every knob on at a moderate level
    "realistic": dict(depth_sigma_base_m=0.001, depth_sigma_k=0.0018, hole_blobs=4, grazing_deg=78.0,
                      flying_pixels=0.3, color_sigma=4.0, blur_px=0.8, jpeg_quality=90, exposure=0.12,
                      occluder=0.3, clutter=2, distractor_lines=1, texture=0.15, table_grain=0.25, shadows=True,
                      printed_faces=0.6, face_hues=0.3, touching=0.5, stacked=0.3, small_table=0.5,
                      depth_model="realsense", edge_dropout_px=2.0),
    # a Kinect v1: structured-light depth (sigma 1.4 mm at 0.5 m, 4.4 mm at 1.5 m), a soft noisy colour
    # camera, printed objects
    "kinect": dict(depth_sigma_base_m=0.001, depth_sigma_k=0.0015, hole_blobs=3, grazing_deg=75.0,
                   flying_pixels=0.2, color_sigma=5.0, blur_px=1.0, jpeg_quality=85, exposure=0.15,
                   occluder=0.2, clutter=2, texture=0.1, table_grain=0.25, shadows=True,
                   printed_faces=0.6, face_hues=0.2, touching=0.3, stacked=0.3, small_table=0.3,
                   depth_model="kinect", edge_dropout_px=1.5),
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


_KINDS = {f.name: f.type for f in fields(NoiseConfig)}  # "float", "int", "bool" or "str" (annotations are strings)
_CHOICES = {"depth_model": tuple(DEPTH_MODELS)}


def _check_type(name: str, value) -> None:
    """An InputError unless ``value`` fits knob ``name``: a bool is no number, a float no count."""
    kind = _KINDS[name]
    is_bool = isinstance(value, bool)
    ok = {"bool": is_bool, "int": isinstance(value, int) and not is_bool,
          "float": isinstance(value, (int, float)) and not is_bool,
          "str": isinstance(value, str) and value in _CHOICES.get(name, ())}[kind]
    if not ok:
        says = {"bool": "true or false", "int": "a whole number", "float": "a number",
                "str": "one of " + ", ".join(_CHOICES.get(name, ()))}[kind]
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


def sensor_shadow(depth: np.ndarray, fx: float, baseline_m: float) -> np.ndarray:
    """(H, W) bool: the pixels whose point the sensor's second viewpoint, ``baseline_m`` to the right of
    the camera (+x, rectified), cannot see because a nearer surface hides it (a Kinect's projector
    shadow, a stereo pair's occlusion). ``depth``: ideal (H, W) metres, 0 = nothing; ``fx``: pixels.

    A point at column u with disparity D = fx b / z appears at column u - D in the second view; it is
    hidden when a pixel to its right lands left of it there (that pixel is then nearer). So the band
    lies left of every nearer object, on the far side of the depth edge, D_near - D_far pixels wide."""
    h, w = depth.shape
    z = depth.astype(np.float32, copy=False)
    valid = z > 0
    x2 = np.where(valid, np.arange(w, dtype=np.float32)[None, :] - np.float32(fx * baseline_m)
                  / np.where(valid, z, np.float32(1)), np.float32(np.inf))
    right_min = np.full((h, w), np.inf, np.float32)  # min of x2 over the pixels right of each pixel
    right_min[:, :-1] = np.minimum.accumulate(x2[:, :0:-1], axis=1)[:, ::-1]
    return valid & (right_min < x2 - np.float32(0.25))  # a quarter pixel: no self-shadow from rounding


def edge_dropout(depth: np.ndarray, width_px: float, rng: np.random.Generator) -> np.ndarray:
    """(H, W) bool: a ragged band, about ``width_px`` pixels wide (0.5-1.5 times that, varying along the
    edge), on the far side of every depth edge (a jump over EDGE_JUMP_M): there the matching window of
    a stereo or structured-light sensor straddles two depths and returns nothing."""
    h, w = depth.shape
    z = depth.astype(np.float32, copy=False)
    valid = z > 0
    reach = int(np.ceil(1.5 * width_px))
    if reach < 1:
        return np.zeros((h, w), bool)
    # the near side of each edge: pixels with a neighbour deeper by more than the jump
    near_edge = valid & (cv2.dilate(z, np.ones((3, 3), np.uint8)) - z > EDGE_JUMP_M)
    # the far side: pixels deeper by more than the jump than a near-side edge pixel within reach
    # (not than any pixel: a steep face would then count as its own far side)
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1, 2 * reach + 1))
    far = valid & (z - cv2.erode(np.where(near_edge, z, np.float32(1e3)), disc) > EDGE_JUMP_M)
    if not far.any():
        return far
    dist = cv2.distanceTransform((~near_edge).view(np.uint8), cv2.DIST_L2, 3)  # pixels to the nearest
    jitter = cv2.resize(rng.random((h // 8 + 2, w // 8 + 2), dtype=np.float32), (w, h),
                        interpolation=cv2.INTER_LINEAR)
    return far & (dist <= np.float32(width_px) * (np.float32(0.5) + jitter))


def quantise_disparity(z: np.ndarray, fx640: float, model: DepthModel) -> np.ndarray:
    """Depth (H, W) float32 metres (0 = none) rounded to the nearest whole disparity step: disparity
    d = fx640 b / z in steps of q, so the depth step is about z^2 q / (fx640 b) (Kinect, 615 px: 2.7 mm
    at 1 m, 6.1 mm at 1.5 m). ``fx640``: the focal length at 640x480 (the sensor's, whatever the render size)."""
    fb = np.float32(fx640 * model.baseline_m)
    q = np.float32(model.disparity_step_px)
    valid = z > 0
    d = np.round(fb / np.where(valid, z, np.float32(1)) / q) * q
    return np.where(valid & (d > 0), fb / np.maximum(d, q), np.float32(0)).astype(np.float32)


def noisy_depth(depth: np.ndarray, cos_incidence: np.ndarray | None, cfg: NoiseConfig,
                rng: np.random.Generator, fx: float | None = None,
                sensor_rng: np.random.Generator | None = None) -> np.ndarray:
    """Apply depth nuisances to ideal depth (H, W) float metres (0 = no hit); returns float32 metres
    quantised to whole millimetres. ``cos_incidence``: (H, W) cosine between view ray and surface normal
    (needed only when ``cfg.grazing_deg`` < 90). ``fx`` (pixels, this image) and ``sensor_rng`` are needed
    only by ``cfg.depth_model`` and ``cfg.edge_dropout_px`` (``sensor_rng`` keeps their draws apart from
    ``rng``'s, so they change nothing else)."""
    h, w = depth.shape
    f32 = np.float32  # float32 throughout: half the memory traffic of float64, and metres need no more
    model = DEPTH_MODELS[cfg.depth_model]
    lost = None  # readings the sensor's geometry loses, from the ideal depth
    if model is not None or cfg.edge_dropout_px > 0:
        if fx is None or sensor_rng is None:
            raise ValueError("the depth model and edge dropout need fx and sensor_rng")
        lost = np.zeros((h, w), bool)
        if model is not None:
            lost |= sensor_shadow(depth, fx, model.baseline_m)
        if cfg.edge_dropout_px > 0:
            lost |= edge_dropout(depth, cfg.edge_dropout_px * w / 640.0, sensor_rng)
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
    if model is not None:
        z = quantise_disparity(z, fx * 640.0 / w, model)
    if lost is not None:
        valid &= ~lost
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
