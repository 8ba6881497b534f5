"""How every benchmark says whether a figure meets its target: ``ok`` or ``MISS`` beside the target."""

from __future__ import annotations


def meets(op: str, target: float, value: float) -> bool:
    """Whether ``value`` meets ``op target`` (``op``: ">=" or "<=")."""
    if op not in (">=", "<="):
        raise ValueError(f"a target's comparison is '>=' or '<=', got {op!r}")
    return value >= target if op == ">=" else value <= target


def mark(ok: bool) -> str:
    return "ok" if ok else "MISS"


def beside(op: str, target: float, value: float, fmt: str = "g", unit: str = "") -> str:
    """``"target OP T UNIT: ok"`` or ``... MISS``: the words a benchmark prints after a figure."""
    return f"target {op} {target:{fmt}}{unit}: {mark(meets(op, target, value))}"
