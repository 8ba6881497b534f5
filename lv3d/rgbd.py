"""One registered RGB-D frame and its loaders: this project's data set format and real camera frames
(PNG or 16-bit TIFF depth with a depth scale, intrinsics from JSON).

A camera frame larger than perception's working size is read at a whole fraction of its size
(:func:`working_factor`, :func:`to_working`): perception's settings and the calibration maps are made for frames
about ``WORK_SIDE_PX`` pixels across."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from .camera import Intrinsics
from .errors import InputError, read_json


@dataclass(frozen=True)
class RGBD:
    """``color``: (H, W, 3) uint8 RGB. ``depth``: (H, W) float32 metres, 0 where there is no reading.
    Colour and depth share one pixel grid (registered)."""

    color: np.ndarray
    depth: np.ndarray
    intrinsics: Intrinsics
    name: str = "frame"
    meta: dict = field(default_factory=dict, compare=False)
    scale: int = 1  # pixels of the image files per pixel of this frame (to_working); 1: read as it is

    @property
    def shape(self) -> tuple[int, int]:
        return self.depth.shape

    def points(self) -> tuple[np.ndarray, np.ndarray]:
        """Back-projected valid depth: camera-frame points (m, 3) in metres and their pixels (m, 2) as (u, v)."""
        v, u = np.nonzero(self.depth > 0)
        return self.intrinsics.back_project(u, v, self.depth[v, u]), np.stack([u, v], axis=1)


def _check_size(path: Path, what: str) -> None:
    """Refuse an image above lv3d.limits.MAX_PIXELS from its header, before decoding it."""
    from .limits import check_pixels

    try:
        from PIL import Image

        Image.MAX_IMAGE_PIXELS = None  # the bound is lv3d's own, checked below
        with Image.open(path) as im:
            w, h = im.size
    except Exception:  # a format PIL cannot read the header of: checked after decoding
        return
    check_pixels(w, h, path, what)


def _imread(path: Path, flags: int, what: str) -> np.ndarray | None:
    from .limits import check_pixels

    _check_size(path, what)
    img = cv2.imread(str(path), flags)
    if img is not None:
        check_pixels(img.shape[1], img.shape[0], path, what)
    return img


def read_color(path: Path) -> np.ndarray:
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "colour image not found")
    img = _imread(path, cv2.IMREAD_COLOR, "colour image")
    if img is None:
        raise InputError(path, "cannot read the colour image (corrupt or not an image)")
    return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)


# Plausible median depth of a frame, in metres: the working range of consumer RGB-D sensors (Kinect,
# RealSense, structured light and time of flight read from about 0.15 m to about 8 m). A median outside it
# means the depth was read in the wrong unit (millimetres taken as metres, or the reverse).
DEPTH_RANGE_M = (0.15, 8.0)


def read_depth(path: Path, depth_scale_m: float, scale_option: str = "--depth-scale") -> np.ndarray:
    """A 16-bit depth image (PNG or TIFF) times ``depth_scale_m`` -> float32 metres; 0 stays 'no reading'.
    A floating-point depth image (32- or 64-bit TIFF) holds metres already: the scale, which is that of
    integer depth units, does not apply to it. A median reading outside :data:`DEPTH_RANGE_M` is an
    InputError that suggests a scale (named as ``scale_option``, the option or key the user sets it with)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "depth image not found")
    raw = _imread(path, cv2.IMREAD_UNCHANGED, "depth image")
    if raw is None:
        raise InputError(path, "cannot read the depth image (corrupt or not an image)")
    if raw.ndim != 2:
        raise InputError(path, f"depth must have one channel, this image has shape {raw.shape}")
    if raw.dtype == np.uint16:
        depth = raw.astype(np.float32) * np.float32(depth_scale_m)
    elif raw.dtype in (np.float32, np.float64):
        depth = np.nan_to_num(raw.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
        depth[depth < 0] = 0
        valid = depth[depth > 0]
        if valid.size and not DEPTH_RANGE_M[0] <= float(np.median(valid)) <= DEPTH_RANGE_M[1]:
            raise InputError(path, f"median depth {float(np.median(valid)):.4g} is outside the {DEPTH_RANGE_M[0]:g}-"
                                   f"{DEPTH_RANGE_M[1]:g} m an RGB-D sensor reads; floating-point depth is read as "
                                   "metres (save millimetres as 16-bit integers, with their depth scale)")
    else:
        raise InputError(path, f"depth must be uint16 (or float32 metres), not {raw.dtype}")
    valid = depth[depth > 0]
    if valid.size == 0:
        raise InputError(path, "depth is all zero (no readings)")
    if raw.dtype == np.uint16:
        _check_depth_range(path, float(np.median(valid)), depth_scale_m, scale_option)
    return depth


def _check_depth_range(path: Path, median_m: float, scale: float, scale_option: str) -> None:
    lo, hi = DEPTH_RANGE_M
    if lo <= median_m <= hi:
        return
    # the power of ten per unit that puts the median nearest the middle of the range (geometric mean)
    raw_median = median_m / scale
    exponent = round(np.log10(np.sqrt(lo * hi)) - np.log10(raw_median))
    suggested = 10.0 ** min(exponent, 0)  # at most 1 m per unit
    if lo <= raw_median * suggested <= hi and suggested != scale:
        fix = f"try {scale_option} {suggested:g}" if scale_option.startswith("--") else \
            f"set {scale_option} to {suggested:g}"
        advice = f"wrong depth unit? {fix}"
    else:
        advice = f"check the depth unit ({scale_option})"
    raise InputError(path, f"median depth {median_m:.4g} m (at depth scale {scale:g} m per unit) is outside "
                           f"the {lo:g}-{hi:g} m an RGB-D sensor reads; {advice}")


# The size (pixels along the longer side) perception's settings and the calibration maps are made for: the
# Kinect and RealSense VGA streams of the real dev frames and the renderer's default, 640x480. Perception's
# image-side quantities are fractions of the image, but a grid cell's normal is smoothed over 5 cells, the
# thinnest face it reads is a few cells wide, and the calibration maps read face sizes in pixels: on a frame
# twice as wide every one of those would mean half as much, and the frame would cost four times as much.
WORK_SIDE_PX = 640


def working_factor(width: int, height: int) -> int:
    """The whole factor a ``width`` x ``height`` camera frame is read at (1/factor of its size): its longer side
    over ``WORK_SIDE_PX``, rounded, at least 1 (640x480 and 848x480: 1; 1280x720: 2; 1920x1080: 3). A frame
    smaller than the working size is read as it is: upsampling adds no reading."""
    return max(1, round(max(width, height) / WORK_SIDE_PX))


def to_working(frame: RGBD) -> RGBD:
    """``frame`` at its working size (:func:`working_factor`), itself where that is its size. Depth keeps every
    s-th reading of every s-th row (a reading is never averaged across a depth edge, and no reading is made up
    where the sensor had none); colour is low-passed (a Gaussian of s/2 pixels, against aliasing) and taken at
    the same pixels, so the two stay registered; the intrinsics are those of the smaller grid (pixel (u, v) of
    it is pixel (s u, s v) of the file). ``scale`` records s."""
    s = working_factor(frame.depth.shape[1], frame.depth.shape[0])
    if s == 1:
        return frame
    color = cv2.GaussianBlur(frame.color, (0, 0), 0.5 * s)[::s, ::s]
    depth = frame.depth[::s, ::s]
    k = frame.intrinsics
    small = Intrinsics(fx=k.fx / s, fy=k.fy / s, cx=k.cx / s, cy=k.cy / s, width=depth.shape[1], height=depth.shape[0])
    return RGBD(np.ascontiguousarray(color), np.ascontiguousarray(depth), small, frame.name, frame.meta,
                frame.scale * s)


def load_frame(color_path: Path, depth_path: Path | None, intrinsics: Intrinsics | None,
               depth_scale_m: float = 0.001, name: str | None = None, meta: dict | None = None,
               scale_option: str = "--depth-scale", working: bool = True) -> RGBD:
    """Load and validate one frame. Without ``depth_path`` the depth is all zeros (rgb-only use) and, without
    ``intrinsics`` too, the intrinsics are nominal (:meth:`Intrinsics.nominal`). ``scale_option`` names where
    the user sets the depth scale, for the error on depth in the wrong unit. With ``working`` (a camera frame),
    a frame larger than the working size is read at it (:func:`to_working`); without (a rendered data set's
    item, whose ground truth lies on the file's pixel grid), as it is."""
    color = read_color(color_path)
    h, w = color.shape[:2]
    if intrinsics is None:
        if depth_path is not None:
            raise InputError(depth_path, "no intrinsics given for this frame's depth")
        intrinsics = Intrinsics.nominal(w, h)
    if (intrinsics.width, intrinsics.height) != (w, h):
        raise InputError(color_path, f"image is {w}x{h} but the intrinsics are for "
                                     f"{intrinsics.width}x{intrinsics.height}")
    if not (isinstance(depth_scale_m, (int, float)) and not isinstance(depth_scale_m, bool)
            and 1e-6 < depth_scale_m <= 1.0):
        raise InputError(depth_path or color_path, f"{scale_option}: absurd depth scale {depth_scale_m!r} m per unit "
                                                   "(need above 1e-06 and at most 1)")
    if depth_path is None:
        depth = np.zeros((h, w), np.float32)
    else:
        depth = read_depth(depth_path, depth_scale_m, scale_option)
        if depth.shape != (h, w):
            raise InputError(depth_path, f"depth is {depth.shape[1]}x{depth.shape[0]} but colour is {w}x{h}")
    frame = RGBD(color, depth, intrinsics, name or Path(color_path).stem, meta or {})
    return to_working(frame) if working else frame


def read_intrinsics(path: Path, frame: str | None = None) -> tuple[Intrinsics, float]:
    """Intrinsics and depth scale from JSON. Accepts ``{"fx", "fy", "cx", "cy", "width", "height",
    "depth_scale_m"?}`` or the real-data layout ``{"width", "height", "frames": {name: {...}}}``."""
    path = Path(path)
    d = read_json(path, "intrinsics file")
    if not isinstance(d, dict):
        raise InputError(path, "intrinsics must be a JSON object")
    if "intrinsics" in d and isinstance(d["intrinsics"], dict):  # a data set's meta.json
        return Intrinsics.from_dict(d["intrinsics"], str(path)), _depth_scale(d, path, "depth_scale_m")
    if "frames" in d:
        frames = d["frames"]
        if not isinstance(frames, dict) or not all(isinstance(v, dict) for v in frames.values()):
            raise InputError(path, "frames: must map each frame's name to its intrinsics {fx, fy, cx, cy, ...}")
        if frame is None or frame not in frames:
            raise InputError(path, f"no intrinsics for frame {frame!r}; known: {', '.join(sorted(frames))}")
        entry = {"width": d.get("width"), "height": d.get("height"), **frames[frame]}
        return Intrinsics.from_dict(entry, str(path)), _depth_scale(entry, path, f"frames.{frame}.depth_scale_m")
    return Intrinsics.from_dict(d, str(path)), _depth_scale(d, path, "depth_scale_m")


def _depth_scale(d: dict, path: Path, key: str) -> float:
    """The entry's depth_scale_m (default 0.001: millimetres), a number in (1e-6, 1] metres per unit."""
    v = d.get("depth_scale_m", 0.001)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not 1e-6 < v <= 1.0:
        raise InputError(path, f"{key}: must be a number of metres per depth unit above 1e-06 and at most 1 "
                               f"(0.001 for millimetres), got {v!r}")
    return float(v)


def load_item(item_dir: Path) -> RGBD:
    """One item of an lv3d data set (color.png, depth.png, meta.json); ``meta`` holds the ground truth."""
    item_dir = Path(item_dir)
    meta_path = item_dir / "meta.json"
    meta = read_json(meta_path, "meta.json")
    if not isinstance(meta, dict) or "intrinsics" not in meta:
        raise InputError(meta_path, "no intrinsics")
    k = Intrinsics.from_dict(meta["intrinsics"], str(meta_path))
    return load_frame(item_dir / "color.png", item_dir / "depth.png", k, _depth_scale(meta, meta_path, "depth_scale_m"),
                      name=meta.get("id", item_dir.name), meta=meta, scale_option="depth_scale_m in meta.json",
                      working=False)


# Real frames in ../shared/data/real/pcl-kinect: name -> (colour file, depth file)
def real_frame_files(folder: Path) -> dict[str, tuple[Path, Path]]:
    folder = Path(folder)
    out = {}
    for c in sorted(folder.glob("*_rgb.*")):
        stem = c.name.rsplit("_rgb.", 1)[0]
        for cand in (f"{stem}_depth.tiff", f"{stem}_depth_mm.png", f"{stem}_depth.png"):
            if (folder / cand).is_file():
                out[stem] = (c, folder / cand)
                break
    return out


def load_real(folder: Path, name: str) -> RGBD:
    """A real frame from a folder laid out like ``../shared/data/real/pcl-kinect``, at its working size
    (:func:`to_working`)."""
    files = real_frame_files(folder)
    if name not in files:
        raise InputError(folder, f"no frame {name!r}; found: {', '.join(files) or 'none'}")
    k, scale = read_intrinsics(Path(folder) / "intrinsics.json", name)
    c, d = files[name]
    return load_frame(c, d, k, scale, name=name, scale_option=f"depth_scale_m of {name!r} in intrinsics.json")
