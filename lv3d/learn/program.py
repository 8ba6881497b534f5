"""A learned program: readable Prolog clauses for one target, saved as a .pl file a person can
read and loaded back as data (checked to call only known predicates, never run as code)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError
from ..facts import PREDICATES, SCHEMA
from . import engine

_TARGET = re.compile(r"^[a-z][a-zA-Z0-9_]*$")


def known_predicates() -> list[tuple[str, int]]:
    """Every predicate a program body may call: the fact contract's and the derived ones."""
    return [(p, a) for p, (a, _) in PREDICATES.items()] + list(engine.derived_preds())


@dataclass(frozen=True)
class Program:
    """Clauses (portray_clause text, each ending in '.') defining ``target/1``; ``score`` is what
    the learner measured on its training examples: j (balanced accuracy J less the size penalty),
    soft, tp, n_pos, fp, n_neg."""

    target: str
    clauses: tuple[str, ...]
    score: dict = field(default_factory=dict)
    modality: str | None = None
    settings: dict = field(default_factory=dict)
    label: str | None = None  # the class it answers when that is not ``target`` (a fact predicate's name)

    def __str__(self) -> str:
        return "\n".join(self.clauses)

    @property
    def answers(self) -> str:
        """The class this program answers: its label, else its target."""
        return self.label or self.target

    def to_pl(self) -> str:
        head = [f"% lv3d program: target {self.target}/1, facts {SCHEMA}, modality {self.modality}",
                f"% target: {self.target}"]
        if self.label and self.label != self.target:
            head.append(f"% label: {self.label} (learned as {self.target}: {self.label} names a body predicate)")
        if self.score:
            s = self.score
            head.append(f"% training: covers {s.get('tp')}/{s.get('n_pos')} positives, "
                        f"{s.get('fp')}/{s.get('n_neg')} negatives; J = {s.get('j', 0):.3f}"
                        + (f"; threshold {s['threshold']:g}" if "threshold" in s else ""))
        if self.settings:
            head.append("% settings: " + ", ".join(f"{k}={v}" for k, v in sorted(self.settings.items())))
        return "\n".join(head) + "\n\n" + "\n".join(self.clauses) + "\n"

    def save(self, path: Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".pl.tmp")
        tmp.write_text(self.to_pl())
        tmp.replace(path)  # nothing half-written
        return path

    @classmethod
    def load(cls, path: Path, target: str | None = None) -> "Program":
        """Read a program file; the target is ``target``, else the header's ``% target:``, else the
        file's stem. InputError (naming the file) when it is malformed or calls an unknown predicate."""
        path = Path(path)
        if not path.is_file():
            raise InputError(path, "no such program file")
        try:
            text = path.read_text()
        except (OSError, UnicodeDecodeError) as e:
            raise InputError(path, f"cannot be read: {e}") from None
        m = re.search(r"^%\s*target:\s*(\S+)", text, re.M)
        lab = re.search(r"^%\s*label:\s*([a-z][a-zA-Z0-9_]*)", text, re.M)
        modality = re.search(r"modality (\w+)", text)
        target = target or (m.group(1) if m else path.stem)
        if not _TARGET.match(target):
            raise InputError(path, f"target {target!r} is not a predicate name")
        from .task import validate_file

        validate_file(path)  # read first in a process of its own: no file can crash this one's Prolog
        known = engine.plist(f"{p}/{a}" for p, a in known_predicates())
        ans = engine.query(f"lv3d_bridge:check_program({engine.quote(str(path))}, {known}, {target}, Texts)",
                           where=str(path))
        if not ans:
            raise InputError(path, "could not be read as a program")
        return cls(target, tuple(str(t) for t in ans[0]["Texts"]),
                   modality=modality.group(1) if modality and modality.group(1) != "None" else None,
                   label=lab.group(1) if lab else None)
