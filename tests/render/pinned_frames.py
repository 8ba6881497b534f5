"""Fingerprints of pinned rendered frames, compared within what differs from one CPU to another.

The renderer is deterministic on one machine, but not to the bit across machines: numpy's and OpenCV's
vectorised float32 and transcendental functions round differently on CPUs with other instruction sets, so a
few colour values in a million land one level apart, a few depth readings one quantisation step apart, and the
truth's floats differ in their last digits. A sha256 of the bytes then fails on a machine of another kind
although nothing was changed. What the pinned tests ask instead: the frame's sums over a grid of blocks
(colour per channel, depth and its valid readings, face-mask pixels and ids) and its metadata as JSON agree with
the pinned ones within tolerances far below what any change to a scene, a noise model or a draw of the
renderer's generator moves (such a change moves every block).

The pins live in ``data/pinned_frames.json``. After a deliberate change to the renderer, rewrite them with

    .venv/bin/python -m tests.render.pinned_frames --write

and say in the commit why the pinned frames changed.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

PINS = Path(__file__).with_name("data") / "pinned_frames.json"
BLOCKS = (6, 8)  # rows x columns of the grid the sums are taken over
# tolerances, as fractions of the frame's pixel count: the sum over blocks of |difference| of ...
COLOUR_TOL = 1e-3    # ... colour values (levels): 0.1 % of the values one level apart
COUNT_TOL = 1e-3     # ... valid depth readings and face-mask pixels (pixels)
DEPTH_TOL_M = 1e-5   # ... depth sums (metres per pixel of the frame: 0.1 % of readings 1 cm apart)
FLOAT_TOL = 1e-6     # metadata floats, absolute (metres, unit vectors, degrees, pixels)


def _block_sums(a: np.ndarray) -> np.ndarray:
    """Sums of ``a`` (h, w) or (h, w, c) over BLOCKS, float64, shape (rows, cols) or (rows, cols, c)."""
    h, w = a.shape[:2]
    rows = np.array_split(np.arange(h), BLOCKS[0])
    cols = np.array_split(np.arange(w), BLOCKS[1])
    a = a.astype(np.float64)
    return np.array([[a[r[0]:r[-1] + 1, c[0]:c[-1] + 1].sum(axis=(0, 1)) for c in cols] for r in rows])


def _rounded(x):
    """The metadata with floats rounded to 9 decimals (-0.0 as 0.0), as JSON holds it."""
    if isinstance(x, float):
        return round(x, 9) + 0.0
    if isinstance(x, dict):
        return {k: _rounded(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_rounded(v) for v in x]
    return x


def fingerprint(color: np.ndarray, depth: np.ndarray, faces: np.ndarray, meta: dict) -> dict:
    """What a pin holds of one frame: block sums of colour (per channel), of depth (metres) and of its valid
    readings, of face-mask pixels and of their ids, the pixel count, and the metadata (floats rounded)."""
    d = np.nan_to_num(depth.astype(np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    return {"pixels": int(depth.size),
            "colour": _block_sums(color).tolist(),
            "depth_m": np.round(_block_sums(d), 6).tolist(),
            "depth_valid": _block_sums(d > 0).astype(int).tolist(),
            "face_pixels": _block_sums(faces > 0).astype(int).tolist(),
            "face_ids": _block_sums(faces).astype(int).tolist(),
            "meta": _rounded(json.loads(json.dumps(meta)))}


def _meta_differences(a, b, path: str = "meta") -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{path}: keys {sorted(set(a) ^ set(b))} in one only"]
        return [d for k in sorted(a) for d in _meta_differences(a[k], b[k], f"{path}.{k}")]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} items against {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _meta_differences(x, y, f"{path}[{i}]")]
    if path.endswith("pixels") and isinstance(a, int) and isinstance(b, int):
        # a pixel count: a pixel on a face's edge may fall to the other side on another CPU
        if abs(a - b) <= max(1.0, COUNT_TOL * abs(b)):
            return []
    elif isinstance(a, float) or isinstance(b, float):
        if isinstance(a, (int, float)) and isinstance(b, (int, float)) and math.isclose(a, b, rel_tol=0,
                                                                                         abs_tol=FLOAT_TOL):
            return []
    elif a == b:
        return []
    return [f"{path}: {a!r} against {b!r}"]


def differences(got: dict, pinned: dict) -> list[str]:
    """Where fingerprint ``got`` departs from ``pinned`` beyond the tolerances (empty: the same frame)."""
    n = pinned["pixels"]
    if got["pixels"] != n:
        return [f"pixels: {got['pixels']} against {n}"]
    out = []
    for key, tol in (("colour", COLOUR_TOL * n), ("depth_m", DEPTH_TOL_M * n), ("depth_valid", COUNT_TOL * n),
                     ("face_pixels", COUNT_TOL * n), ("face_ids", COUNT_TOL * n * 255)):
        diff = float(np.abs(np.asarray(got[key], float) - np.asarray(pinned[key], float)).sum())
        if diff > tol:
            out.append(f"{key}: block sums differ by {diff:.6g} in all (tolerance {tol:.6g})")
    return out + _meta_differences(got["meta"], pinned["meta"])


def load() -> dict:
    return json.loads(PINS.read_text())


# the pinned scenes: (preset, class, seed, width, height); the presets without realism knobs, and polyhedra
# under the realism knobs, where clutter and a touching solid are drawn by class index
PLAIN = [(p, c, s, w, h) for p in ("clean", "mild", "realsense", "hard")
         for c, s, w, h in (("cube", 0, 320, 240), ("hexagonal_prism", 1, 160, 120), ("tetrahedron", 2, 160, 120),
                            ("cuboid", 3, 640, 480), ("square_pyramid", 4, 160, 120))]
REALISM = [("realistic", "cube", 8, 160, 120), ("realistic", "square_pyramid", 4, 160, 120),
           ("kinect", "hexagonal_prism", 8, 160, 120)]


def key(preset: str, cls: str, seed: int, width: int, height: int) -> str:
    return f"{preset}-{cls}-{seed}-{width}x{height}"


def render_fingerprint(preset: str, cls: str, seed: int, width: int, height: int) -> dict:
    from lv3d.render import render_scene

    frame, faces = render_scene(cls, seed, preset, width, height)
    return fingerprint(frame.color, frame.depth, faces, frame.meta)


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if args != ["--write"]:
        print("usage: python -m tests.render.pinned_frames --write   (rewrites " + str(PINS) + ")", file=sys.stderr)
        return 2
    pins = {key(*case): render_fingerprint(*case) for case in PLAIN + REALISM}
    PINS.parent.mkdir(parents=True, exist_ok=True)
    PINS.write_text(json.dumps(pins, indent=None, separators=(",", ":")) + "\n")
    print(f"wrote {len(pins)} pinned frames to {PINS}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
