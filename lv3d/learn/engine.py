"""The one SWI-Prolog engine of this process (pyswip), with the learner's shipped sources loaded.

pyswip drives a single embedded Prolog per process; every query here is read to the end (``list``)
before the next one starts, and Prolog's errors come back as :class:`LearnError` or
:class:`lv3d.errors.InputError` with the file and the problem.
"""

from __future__ import annotations

import re
import threading
from functools import lru_cache

from ..errors import InputError
from ..facts import PREDICATES

_LOCK = threading.Lock()


class LearnError(RuntimeError):
    """The learner could not answer: it ran out of time, or the task cannot be learned as given."""


@lru_cache(maxsize=1)
def prolog():
    """The process's Prolog, with mil, shape_bk and lv3d_bridge consulted once."""
    from pyswip import Prolog

    import prolog as sources

    for name in ("mil.pl", "shape_bk.pl", "lv3d_bridge.pl"):
        path = str(sources.source(name)).replace("\\", "/")
        list(Prolog.query(f"use_module('{quote(path)[1:-1]}')"))
    return Prolog


def quote(text: str) -> str:
    """``text`` as a quoted Prolog atom."""
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def plist(items) -> str:
    return "[" + ",".join(items) + "]"


def query(goal: str, where: str = "learner") -> list[dict]:
    """All answers of ``goal`` (a Prolog string), read to the end; a thrown error becomes
    LearnError (time limit, unlearnable task) or InputError(file, problem) (bad task/program file)."""
    pl = prolog()
    with _LOCK:
        answers = list(pl.query(f"lv3d_bridge:guard(({goal}), LV3DKind, LV3DWhere, LV3DMsg)"))
    for a in answers:
        kind, file, msg = (str(a.pop(k)) for k in ("LV3DKind", "LV3DWhere", "LV3DMsg"))
        if kind != "ok":
            if kind == "input":
                raise InputError(file or where, msg)
            raise LearnError(f"{where}: {msg}")
    return answers


def fact_pred_specs() -> str:
    """Every predicate of the fact contract as Name/Arity, a Prolog list."""
    return plist(f"{p}/{a}" for p, (a, _) in PREDICATES.items())


@lru_cache(maxsize=1)
def derived_uses() -> dict[str, frozenset[str]]:
    """Each derived predicate of prolog/shape_bk.pl: the fact predicates its rule rests on."""
    return {str(r["P"]): frozenset(str(u).split("/")[0] for u in r["U"])
            for r in query("shape_bk:derived_uses(P/_, U0), findall(X, (member(Q/B, U0), format(atom(X), '~w/~w', [Q, B])), U)")}


@lru_cache(maxsize=1)
def derived_preds() -> tuple[tuple[str, int], ...]:
    """The derived body predicates of prolog/shape_bk.pl, (name, arity)."""
    return tuple((r["P"], int(r["A"])) for r in query("shape_bk:derived(P/A)"))


def _value(v) -> str:
    if isinstance(v, bool):  # Prolog's true and false, not 1 and 0
        return "true" if v else "false"
    if isinstance(v, str):
        return quote(v)
    if isinstance(v, (list, tuple)):
        return plist(_value(x) for x in v)
    return repr(float(v) if isinstance(v, float) else int(v))


def settings_term(settings: dict | None) -> str:
    """A settings dict ({"max_clauses": 2, "combine": "min", "thresholds": [0.3, 0.5], ...}) as a
    Prolog option list."""
    if not settings:
        return "[]"
    out = []
    for k, v in settings.items():
        if not re.match(r"^[a-z][a-z_]*$", k):
            raise InputError("settings", f"bad setting name {k!r}")
        out.append(f"{k}({_value(v)})")
    return plist(out)
