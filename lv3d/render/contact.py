"""Contact sheets: thumbnails of colour and depth side by side with a label, for a data set or for every
class under every noise preset (docs/contact_sheet.png: ``python -m lv3d.render.contact docs/contact_sheet.png``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import cv2
import numpy as np

from ..errors import InputError, read_json
from ..rgbd import load_item

DEPTH_RANGE_M = (0.3, 3.0)


def depth_colour(depth: np.ndarray) -> np.ndarray:
    """(H, W) metres -> (H, W, 3) uint8 RGB false colour, black where there is no reading."""
    lo, hi = DEPTH_RANGE_M
    d8 = np.clip((depth - lo) / (hi - lo) * 255.0, 0, 255).astype(np.uint8)
    img = cv2.applyColorMap(255 - d8, cv2.COLORMAP_TURBO)[:, :, ::-1]
    img[depth <= 0] = 0
    return img


def tile(label: str, color: np.ndarray, depth: np.ndarray, thumb_w: int = 160) -> np.ndarray:
    """One labelled tile (RGB uint8): colour and false-colour depth thumbnails side by side."""
    h, w = depth.shape
    th = int(round(thumb_w * h / w))
    c = cv2.resize(color, (thumb_w, th), interpolation=cv2.INTER_AREA)
    d = cv2.resize(depth_colour(depth), (thumb_w, th), interpolation=cv2.INTER_NEAREST)
    band = np.full((16, 2 * thumb_w, 3), 255, np.uint8)
    cv2.putText(band, label, (3, 12), cv2.FONT_HERSHEY_SIMPLEX, 0.38, (0, 0, 0), 1, cv2.LINE_AA)
    return np.concatenate([band, np.concatenate([c, d], axis=1)], axis=0)


def grid(tiles: list[np.ndarray], cols: int, gap: int = 4) -> np.ndarray:
    """Tiles of one size in rows of ``cols``, on white."""
    th, tw = tiles[0].shape[:2]
    rows = (len(tiles) + cols - 1) // cols
    out = np.full((rows * (th + gap) + gap, cols * (tw + gap) + gap, 3), 255, np.uint8)
    for i, t in enumerate(tiles):
        r, c = divmod(i, cols)
        out[gap + r * (th + gap):gap + r * (th + gap) + th, gap + c * (tw + gap):gap + c * (tw + gap) + tw] = t
    return out


# the PNG text key that marks a contact sheet as lv3d's own: only such a file is ever written over
SHEET_KEY = "lv3d-contact-sheet"


def is_own_sheet(path: Path) -> bool:
    """True when ``path`` is a PNG that lv3d wrote as a contact sheet (its text chunk ``SHEET_KEY``)."""
    from PIL import Image

    try:
        with Image.open(path) as im:
            return SHEET_KEY in getattr(im, "text", {})
    except OSError:
        return False


def write_png(path: Path, rgb: np.ndarray) -> Path:
    """Write ``rgb`` (H, W, 3) uint8 to ``path`` as a PNG marked as lv3d's (``SHEET_KEY``), through a temporary
    file beside it; an existing file at ``path`` that lv3d did not write is refused."""
    from PIL import Image, PngImagePlugin

    path = Path(path)
    if path.exists() and not is_own_sheet(path):
        raise InputError(path, "exists and is not a contact sheet lv3d wrote; choose another --out or remove it")
    path.parent.mkdir(parents=True, exist_ok=True)
    info = PngImagePlugin.PngInfo()
    info.add_text(SHEET_KEY, "1")
    tmp = path.with_name(f".{path.name}.partial-{os.getpid()}")
    try:
        Image.fromarray(np.ascontiguousarray(rgb)).save(tmp, format="PNG", pnginfo=info, compress_level=9)
        os.replace(tmp, path)
    except OSError as e:
        tmp.unlink(missing_ok=True)
        raise InputError(path, f"cannot write the PNG here ({e.strerror or e})") from None
    return path


def dataset_sheet(folder: Path, out: Path, max_items: int = 48, cols: int = 4) -> Path:
    """A contact sheet of the first ``max_items`` items of the data set in ``folder``, labelled id and class."""
    folder = Path(folder)
    mpath = folder / "manifest.json"
    if not mpath.is_file():
        raise InputError(folder, "not a data set (no manifest.json)")
    manifest = read_json(mpath, "data set manifest")
    try:
        items = manifest["items"]
    except (KeyError, TypeError) as e:
        raise InputError(mpath, f"not a valid data set manifest: {e}") from None
    if not items:
        raise InputError(mpath, "the data set has no items")
    tiles = []
    for it in items[:max_items]:
        f = load_item(folder / it["dir"])
        tiles.append(tile(f"{it['id']} {it['class']}", f.color, f.depth))
    return write_png(out, grid(tiles, cols))


def preset_sheet(out: Path, seed: int = 0, width: int = 320, height: int = 240, thumb_w: int = 128) -> Path:
    """Every class (columns) under every noise preset (rows), one seed per class so each column shows one
    scene getting harder."""
    from .frame import render_scene
    from .noise import PRESETS
    from .solids import CLASSES

    tiles = []
    for preset in PRESETS:
        for i, cls in enumerate(CLASSES):
            f, _ = render_scene(cls, seed + i, preset, width, height)
            tiles.append(tile(f"{cls} / {preset}", f.color, f.depth, thumb_w))
    return write_png(out, grid(tiles, len(CLASSES)))


if __name__ == "__main__":
    print(preset_sheet(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/contact_sheet.png")))
