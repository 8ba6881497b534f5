"""Which version of lv3d's own code a cached result was made with.

Facts and lv3d fold results are cached between runs; a cache keyed by settings alone would hand
back results of code that has since changed. Cached facts are therefore keyed by a digest of the
source files they depend on (:func:`facts_version`), so that a change to perception, grounding or the
fact writer recomputes them. An lv3d fold result is keyed by the facts it learned from (their
content, lv3d.experiment.data.facts_digest) and by a digest of the code that learns from them
(:func:`learning_version`): a change to the learner recomputes it, and so does a change to perception
that changes a fact, while one that leaves every fact as it was (a refactor, a faster way to the same
result) keeps it. Baseline results depend on none of that and are kept.
"""

from __future__ import annotations

import hashlib
from functools import lru_cache
from pathlib import Path

_ROOT = Path(__file__).resolve().parents[2]      # the checkout (or site-packages) holding lv3d/

# What the facts of an image depend on: perception, grounding, the fact writer, and the confidence calibration
# maps it applies (their file and the code that reads it: a refit changes every confidence).
FACT_SOURCES = ("lv3d/perception", "lv3d/describe.py", "lv3d/facts.py", "lv3d/pipeline.py", "lv3d/scene.py",
                "lv3d/plane.py", "lv3d/cylinder.py", "lv3d/sphere.py", "lv3d/cone.py", "lv3d/camera.py",
                "lv3d/rgbd.py", "lv3d/object_facts.py", "lv3d/frame_folder.py", "lv3d/image_shape.py",
                "lv3d/interval.py", "lv3d/outline_ellipse.py", "lv3d/calibration.py", "lv3d/data/calibration.json",
                "grounding")
# What learning from those facts depends on: the Python side of the learner and the Prolog files; and with the
# fact schema the learner turns facts into Prolog with, all the code that learns from given facts.
LEARNER_SOURCES = ("lv3d/learn", "prolog")
LEARNING_SOURCES = LEARNER_SOURCES + ("lv3d/facts.py",)


def _files(part: str) -> list[Path]:
    base = _ROOT / part  # lv3d/, grounding/ and prolog/ sit side by side in a checkout and when installed
    if base.is_file():
        return [base]
    return sorted(p for p in base.rglob("*") if p.suffix in (".py", ".pl") and p.is_file())


@lru_cache(maxsize=None)
def source_digest(parts: tuple[str, ...]) -> str:
    """A 12-hex digest of the contents of every .py/.pl file under ``parts`` (paths relative to
    the checkout; a part that is a file counts whatever its kind). Raises FileNotFoundError when a part
    is missing, rather than hashing nothing."""
    h = hashlib.sha256()
    for part in parts:
        files = _files(part)
        if not files:
            raise FileNotFoundError(f"no source files under {part} (looked in {_ROOT})")
        for p in files:
            h.update(p.relative_to(p.parent.parent).as_posix().encode())  # folder and name: a rename counts
            h.update(p.read_bytes())
    return h.hexdigest()[:12]


def facts_version() -> str:
    return source_digest(FACT_SOURCES)


def learner_version() -> str:
    """The version of all of lv3d's code an lv3d result depends on (facts and learner): the one reports name."""
    return source_digest(FACT_SOURCES + LEARNER_SOURCES)


def learning_version() -> str:
    """The version of the code that learns from given facts, part of an lv3d fold result's key."""
    return source_digest(LEARNING_SOURCES)
