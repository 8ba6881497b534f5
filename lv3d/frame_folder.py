"""A folder of real RGB-D frames with labelled objects: the layout of ``../shared/data/real`` (its README),
which is also how users bring their own frames to lv3d.

| file | what |
|---|---|
| ``<frame>_rgb.png`` (or ``.tiff``/``.jpg``) | colour |
| ``<frame>_depth_mm.png`` (or ``_depth.png``/``_depth.tiff``) | depth, registered to colour |
| ``<frame>_label.png`` | optional: uint16 object masks, 0 = none, k = object k |
| ``intrinsics.json`` | ``{"width", "height", "frames": {frame: {"fx","fy","cx","cy","depth_scale_m"}}}`` |
| ``objects.csv`` | ``frame,object,u,v,shape[,partial,stacked,notes]``: one labelled object a row, (u, v) a pixel inside it |

A row that cannot be used (a malformed number, an unknown frame, a pixel outside the image, a class name
that is not a lower-case word) is not fatal: :meth:`FrameFolder.objects` returns it as a :class:`Problem`
naming the file and line, so that a study leaves it out and counts it. A folder that is not in this layout
at all (no objects.csv, no frames, no usable row) is an :class:`~lv3d.errors.InputError`. Measurements that
must see every labelled object (benchmarks/bench_real.py, lv3d.calibrate.real) read the folder strictly:
:meth:`FrameFolder.labels` makes the first row left out an InputError.
"""

from __future__ import annotations

import csv
import hashlib
import re
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import cv2
import numpy as np

from .errors import InputError
from .rgbd import RGBD, load_real, read_intrinsics, real_frame_files, working_factor

REQUIRED_COLUMNS = ("frame", "object", "u", "v", "shape")
# a class becomes the name of a learned predicate: a lower-case word
_CLASS = re.compile(r"^[a-z][a-z0-9_]*$")


@dataclass(frozen=True)
class LabelledObject:
    """One row of objects.csv: the object ``object`` of ``frame``, whose pixel (u, v) (column, row) lies
    inside it, of class ``shape``; ``partial``/``stacked`` as the README defines them (False when absent).
    ``line``: its line in objects.csv (0: not read from a file). (u, v) is a pixel of the frame as lv3d reads it
    (:meth:`FrameFolder.load`: a frame larger than perception's working size is read at 1/s of it,
    lv3d.rgbd.to_working); ``file_uv``, where that differs, is the pixel as objects.csv gives it."""

    frame: str
    object: int
    u: int
    v: int
    shape: str
    partial: bool
    stacked: bool
    line: int = 0
    file_uv: tuple[int, int] | None = None

    @property
    def key(self) -> str:
        return f"{self.frame}#{self.object}"

    @property
    def pixel(self) -> str:
        """The labelled pixel as objects.csv gives it, "(u, v)", for messages."""
        u, v = self.file_uv or (self.u, self.v)
        return f"({u}, {v})"


@dataclass(frozen=True)
class Problem:
    """A row of objects.csv left out, and why: ``str()`` is the one line a user reads."""

    path: Path
    line: int
    why: str

    def __str__(self) -> str:
        return f"{self.path}: line {self.line}: {self.why}"


def natural_key(name: str) -> list:
    """learn2 before learn10."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def _yes_no(text: str | None) -> bool:
    s = (text or "").strip().lower()
    if s in ("", "no", "n", "false", "0"):
        return False
    if s in ("yes", "y", "true", "1"):
        return True
    raise ValueError(f"expected yes or no, not {text!r}")


def read_label_image(path: Path, shape: tuple[int, int]) -> np.ndarray | None:
    """A ground-truth mask image (uint16 ids, one channel, ``shape`` (h, w)) or None where there is no file."""
    path = Path(path)
    if not path.is_file():
        return None
    lab = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if lab is None or lab.ndim != 2:
        raise InputError(path, "cannot read the label image as one channel of object ids")
    if lab.shape != tuple(shape):
        raise InputError(path, f"label image is {lab.shape[1]}x{lab.shape[0]}, the frame {shape[1]}x{shape[0]}")
    return lab


def is_frame_folder(path: Path) -> bool:
    return Path(path).is_dir() and (Path(path) / "objects.csv").is_file()


def frame_files(path: Path, labelled: bool = True) -> dict:
    """The frames of a real-layout folder (lv3d.rgbd.real_frame_files: name -> its files), after checking the
    folder: it exists, holds intrinsics.json, with ``labelled`` objects.csv too, and at least one frame (a colour
    image with its depth). An InputError naming the folder otherwise."""
    path = Path(path)
    if not path.is_dir():
        raise InputError(path, "not a folder")
    for name in ("objects.csv", "intrinsics.json") if labelled else ("intrinsics.json",):
        if not (path / name).is_file():
            what = "labelled frames" if labelled else "frames"
            raise InputError(path, f"no {name} (a folder of {what} needs the layout of docs/real_frames.md)")
    files = real_frame_files(path)
    if not files:
        raise InputError(path, "no frames (<frame>_rgb.png with <frame>_depth_mm.png)")
    return files


class FrameFolder:
    """A real-layout folder, validated on opening (:func:`frame_files`): it exists, holds intrinsics.json,
    objects.csv and at least one frame (a colour image with its depth)."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.files = frame_files(self.path)

    @property
    def frames(self) -> list[str]:
        return sorted(self.files, key=natural_key)

    @property
    def name(self) -> str:
        return self.path.name

    @cached_property
    def _read(self) -> tuple[list[LabelledObject], list[Problem]]:
        path = self.path / "objects.csv"
        try:
            text = path.read_text(encoding="utf-8-sig")
        except (OSError, UnicodeDecodeError) as e:
            raise InputError(path, f"cannot read: {e}") from None
        reader = csv.DictReader(text.splitlines())
        columns = [c.strip() for c in reader.fieldnames or []]
        missing = [c for c in REQUIRED_COLUMNS if c not in columns]
        if missing:
            raise InputError(path, f"line 1: needs the columns {', '.join(REQUIRED_COLUMNS)}; missing "
                                   f"{', '.join(missing)}")
        reader.fieldnames = columns
        sizes: dict[str, tuple[int, int] | None] = {}
        objects, problems, seen = [], [], {}
        for line, row in enumerate(reader, start=2):
            if not any((v or "").strip() for v in row.values() if isinstance(v, str)):
                continue  # a blank line
            try:
                obj = self._row(row, line, sizes)
            except ValueError as e:
                problems.append(Problem(path, line, str(e)))
                continue
            if obj.key in seen:
                problems.append(Problem(path, line, f"frame {obj.frame!r} object {obj.object} is labelled "
                                                    f"twice (first on line {seen[obj.key]})"))
                continue
            seen[obj.key] = line
            objects.append(obj)
        if not objects:
            raise InputError(path, "no usable row" + (f" ({problems[0]})" if problems else " (the file is empty)"))
        return objects, problems

    def _row(self, row: dict, line: int, sizes: dict) -> LabelledObject:
        def whole(key: str) -> int:
            raw = (row.get(key) or "").strip()
            try:
                return int(raw)
            except ValueError:
                raise ValueError(f"{key}: expected a whole number, got {raw!r}") from None

        frame = (row.get("frame") or "").strip()
        if frame not in self.files:
            raise ValueError(f"unknown frame {frame!r} (no {frame}_rgb.* with its depth in {self.path})")
        obj, u, v = whole("object"), whole("u"), whole("v")
        shape = (row.get("shape") or "").strip()
        if not _CLASS.match(shape):
            raise ValueError(f"shape: a class is a lower-case word (letters, digits, _), got {shape!r}")
        if frame not in sizes:
            sizes[frame] = self._size(frame)
        w, h = sizes[frame]
        if not (0 <= u < w and 0 <= v < h):
            raise ValueError(f"pixel ({u}, {v}) lies outside the {w}x{h} frame {frame!r}")
        partial, stacked = _yes_no(row.get("partial")), _yes_no(row.get("stacked"))
        s = working_factor(w, h)
        if s == 1:
            return LabelledObject(frame, obj, u, v, shape, partial, stacked, line)
        # pixel (j, i) of the frame as read is pixel (s j, s i) of the file: the nearest one, within the frame
        uw, vw = min(round(u / s), (w - 1) // s), min(round(v / s), (h - 1) // s)
        return LabelledObject(frame, obj, uw, vw, shape, partial, stacked, line, (u, v))

    def _size(self, frame: str) -> tuple[int, int]:
        """The frame's size in its files (intrinsics.json)."""
        k, _ = read_intrinsics(self.path / "intrinsics.json", frame)
        return k.width, k.height

    def objects(self) -> tuple[list[LabelledObject], list[Problem]]:
        """Every usable labelled object (in file order) and the rows left out."""
        objects, problems = self._read
        return list(objects), list(problems)

    def labels(self, shapes: tuple[str, ...] | None = None) -> dict[str, list[LabelledObject]]:
        """{frame: its labelled objects in file order}, strictly: the first row :meth:`objects` leaves out, or
        of a shape not in ``shapes`` (when given), is an InputError naming the file and line."""
        objects, problems = self._read
        if problems:
            raise InputError(problems[0].path, f"line {problems[0].line}: {problems[0].why}")
        out: dict[str, list[LabelledObject]] = {}
        for obj in objects:
            if shapes is not None and obj.shape not in shapes:
                raise InputError(self.path / "objects.csv", f"line {obj.line}: shape {obj.shape!r} is not one of "
                                                            f"{', '.join(shapes)}")
            out.setdefault(obj.frame, []).append(obj)
        return out

    def load(self, frame: str) -> RGBD:
        """The frame as lv3d reads it: at perception's working size (lv3d.rgbd.to_working)."""
        return load_real(self.path, frame)

    def label_image(self, frame: str, shape: tuple[int, int]) -> np.ndarray | None:
        """The frame's ground-truth masks (uint16 ids) or None where it has none, on the pixels of the frame as
        :meth:`load` reads it (``shape``): a label image of a larger frame is taken at every s-th pixel, as
        its depth is."""
        w, h = self._size(frame)
        s = working_factor(w, h)
        path = self.path / f"{frame}_label.png"
        lab = read_label_image(path, (h, w))
        if lab is not None and s > 1:
            lab = np.ascontiguousarray(lab[::s, ::s])
        if lab is not None and lab.shape != tuple(shape):
            raise InputError(path, f"label image is {lab.shape[1]}x{lab.shape[0]} as read, the frame "
                                   f"{shape[1]}x{shape[0]}")
        return lab

    def signature(self) -> str:
        """A digest of what the folder holds: the bytes of objects.csv, intrinsics.json and each frame's colour and
        depth files, with their names. Cached facts of the folder are reused while it holds the same; a copy of it
        elsewhere, or the same files written anew, is the same folder."""
        h = hashlib.sha256()
        for name in ("objects.csv", "intrinsics.json"):
            h.update((self.path / name).read_bytes())
        for frame in self.frames:
            for p in self.files[frame]:
                h.update(p.name.encode())
                h.update(hashlib.sha256(p.read_bytes()).digest())
        return h.hexdigest()[:16]


def scene_atom(name: str) -> str:
    """A Prolog atom ([a-z][a-zA-Z0-9_]*) naming a frame or an example: ``name`` itself when it is one,
    else its lower-cased letters and digits joined by _ (prefixed with f when it does not start with a
    letter) and 6 hex digits of its hash, so that two names never map to one atom."""
    if re.fullmatch(r"[a-z][a-zA-Z0-9_]*", name):
        return name
    base = re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_")
    if not base or not base[0].isalpha():
        base = "f" + (f"_{base}" if base else "")
    return f"{base}_{hashlib.sha1(name.encode()).hexdigest()[:6]}"
