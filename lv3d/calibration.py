"""The confidence calibration maps lv3d ships: ``lv3d/data/calibration.json``, with the provenance of its fit.

The maps turn grounding's raw probability of each candidate fact into a calibrated confidence
(grounding.Calibration; docs/grounding.md). They are fitted, and the file written, by

    lv3d calibrate fit ROWS.pkl ... --real REAL.pkl ...

on candidate facts of perceived rendered dev scenes (``lv3d calibrate rows``) and labelled real frames
(``lv3d calibrate real``; lv3d.calibrate makes them, and nothing at run time imports it); the file's
``provenance`` names the command, the data (file, rows, scenes, sha256, the command that made it), the code version (git commit and the files that differed from it) and a
sha256 of each group of sources the raw probabilities and measurements depend on (``SOURCES``).
:func:`stale_sources` compares those with the code in use: a map fitted on another perception reads its inputs
from another distribution, and the fit should be rerun.

File layout: ``{"format": FORMAT, "provenance": {...}, "checks": {...}, "table": {modality: {key: map}},
"final": {modality: final maps}}``, ``table`` and ``final`` as grounding.calibrate_with takes them.
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

from .errors import InputError, read_json

DATA = Path(__file__).resolve().parent / "data" / "calibration.json"
FORMAT = 1  # the layout of the file this code reads; a file of another layout is refused


def _sources() -> dict[str, Path]:
    import grounding

    here = Path(__file__).resolve().parent
    return {"grounding": Path(grounding.__file__).resolve().parent, "lv3d/perception": here / "perception",
            "lv3d/describe.py": here / "describe.py"}


# the sources the fitted rows depend on: grounding (raw probabilities; its calibration module only applies the
# maps and is left out), perception (the faces) and describe (candidates and their measurements)
SOURCES = ("grounding", "lv3d/perception", "lv3d/describe.py")
_NOT_SOURCES = ("_calibration.py",)


def source_digests() -> dict[str, str]:
    """{source group: sha256 over its Python files' relative paths and contents} for ``SOURCES``."""
    out = {}
    for name, path in _sources().items():
        h = hashlib.sha256()
        files = sorted(path.rglob("*.py")) if path.is_dir() else [path]
        for f in files:
            if f.name in _NOT_SOURCES or "__pycache__" in f.parts:
                continue
            h.update(str(f.relative_to(path.parent)).encode())
            h.update(f.read_bytes())
        out[name] = h.hexdigest()
    return out


def read(path: str | Path = DATA) -> dict:
    """The calibration file at ``path``, checked: one-line InputError for a missing, malformed or foreign file."""
    data = read_json(path, "calibration file")
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        got = data.get("format") if isinstance(data, dict) else None
        raise InputError(path, f"calibration file of format {got!r}, this code reads format {FORMAT} "
                               "(refit with lv3d calibrate fit)")
    for part in ("table", "final", "provenance"):
        if not isinstance(data.get(part), dict):
            raise InputError(path, f"calibration file without its {part!r} part")
    return data


def stale_sources(path: str | Path = DATA) -> list[str]:
    """The source groups (``SOURCES``) whose code differs from the code the file's maps were fitted on."""
    fitted = read(path)["provenance"].get("sources_sha256", {})
    now = source_digests()
    return [name for name in SOURCES if fitted.get(name) != now[name]]


@functools.cache
def _load(path: str):
    import grounding

    data = read(path)
    return grounding.Calibration(data["table"], data["final"])


def shipped(path: str | Path = DATA):
    """The maps of the calibration file at ``path`` (default: the shipped one) as a grounding.Calibration,
    read once."""
    return _load(str(Path(path).resolve()))


def calibrate(modality: str, key: str, p: float, x: dict | None = None) -> float:
    """The shipped maps' calibrated probability of a candidate fact (grounding.Calibration.calibrate)."""
    return shipped().calibrate(modality, key, p, x)
