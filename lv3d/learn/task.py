"""Metagol-style task files (format: prolog/mil_task.pl, docs/learner.md): learn one and get the
program's clauses back. The file is read as data by Prolog, never consulted as code."""

from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from . import engine
from .engine import LearnError


def learn_task(path: str | Path, *, time_limit: float | None = None, settings: dict | None = None) -> list[str]:
    """The clauses (portray_clause text) of the smallest program that proves every pos/1 example of
    the task file and no neg/1 one. InputError for a missing or malformed file; LearnError when the
    search reaches its time limit or finds no program within the file's size bounds."""
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "no such task file")
    opts = dict(settings or {})
    if time_limit is not None:
        if not time_limit > 0:
            raise InputError("--time-limit", f"must be positive, got {time_limit}")
        opts["time_limit"] = float(time_limit)
    ans = engine.query(f"lv3d_bridge:learn_task({engine.quote(str(path))}, {engine.settings_term(opts)}, Texts)",
                       where=str(path))
    if not ans:
        raise LearnError(f"{path}: no program within the task's max_clauses / max_literals proves every "
                         "positive and no negative")
    return [str(t) for t in ans[0]["Texts"]]
