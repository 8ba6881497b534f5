"""The learner's settings: every option of prolog/mil.pl (its ``default/1``) and ``metarules``, each with
its type and range. :func:`check_settings` refuses an unknown name, a wrong type or a value out of range
with a one-line :class:`~lv3d.errors.InputError` naming the setting, before the learner runs.
"""

from __future__ import annotations

import math

from ..errors import InputError

# the metarules of prolog/mil.pl (metarule/4) a shape learner may name
METARULES = ("ident", "inverse", "precon", "postcon", "chain", "tailrec", "base", "conj", "part", "part2",
             "part_and", "part_pair", "has", "part_rel")
COMBINE = ("product", "min")
BIG = 10 ** 6

# name -> (kind, low, high, what it is); kinds: int, number, bool, choice, numbers, atoms, priors, metarules
SETTINGS: dict[str, tuple] = {
    "max_clauses": ("int", 1, 20, "bound on the number of clauses"),
    "min_clauses": ("int", 1, 20, "where the iterative deepening on clauses starts"),
    "max_literals": ("int", 1, 50, "bound on the body literals of all clauses together"),
    "max_inventions": ("int", 0, 5, "invented predicate symbols allowed"),
    "max_depth": ("int", 1, 1000, "bound on nested clause applications in one proof"),
    "functional": ("bool", None, None, "Metagol's functional check with the task's func_test/3"),
    "time_limit": ("number", 0, 86400, "seconds for a search (above 0)"),
    "threshold": ("number", 0, 1, "confidence at which an example is covered"),
    "combine": ("choice", COMBINE, None, "how a proof combines its facts' confidences"),
    "samples": ("int", 1, 10000, "random samples of the examples"),
    "sample_pos": ("int", 1, BIG, "positives per sample"),
    "sample_neg": ("int", 0, BIG, "negatives per sample"),
    "shrink_samples": ("bool", None, None, "where no sample gives a hypothesis, try smaller samples"),
    "solutions": ("int", 1, BIG, "hypotheses kept per sample"),
    "clause_penalty": ("number", 0, 10, "score lost per clause"),
    "disjunctions": ("int", 0, 10000, "best one-clause hypotheses paired (0: off)"),
    "thresholds": ("numbers", 0, 1, "candidate coverage thresholds"),
    "miss": ("number", 0, 1, "confidence of an absent fact in a near proof (0: off)"),
    "reference": ("atoms", None, None, "unlabelled atoms an extension is measured on"),
    "extra_literals": ("int", 0, 10, "consistent hypotheses kept up to this many literals longer"),
    "few_shot": ("int", 0, BIG, "tasks of at most this many positives are few-shot"),
    "size_principle": ("bool", None, None, "break ties of J by the size principle"),
    "extension_miss": ("number", 0, 1, "near proofs of uncovered reference objects"),
    "literal_prior": ("number", 0, 100, "log prior per body literal"),
    "predicate_prior": ("priors", 0, 100, "[[predicate, nats], ...]"),
    "seed": ("int", 0, 2 ** 32 - 1, "random seed (a study sets it per task)"),
    "metarules": ("metarules", None, None, "metarules, in search order"),
    "derived": ("bool", None, None, "shape learning: offer prolog/shape_bk.pl's derived predicates"),
    "arbiters": ("bool", None, None, "a model of several classes learns arbiters between rival classes"),
}
# the settings lv3d's Python side reads itself (lv3d.learn.model), which are no options of prolog/mil.pl
NOT_MIL = frozenset({"metarules", "derived", "arbiters"})
# Fact predicates no program uses as a body literal and no resemblance profile holds: object/1 holds for every
# target; horizontal/vertical say how a solid rests, not what it is, and a concept learned from one view with
# them fails on the next pose.
EXCLUDED = ("object", "horizontal", "vertical")


def _num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def check_settings(settings: dict | None, where: str = "settings", prefix: str = "") -> dict:
    """``settings`` checked (a copy; lists as lists); InputError naming ``where`` and ``prefix + name``."""
    if settings is None:
        return {}
    if not isinstance(settings, dict):
        raise InputError(where, f"{prefix.rstrip('.') or 'settings'}: must be a mapping, got {settings!r}")
    out = {}
    for name, value in settings.items():
        key = f"{prefix}{name}"
        if name not in SETTINGS:
            raise InputError(where, f"unknown learner setting {key!r}; known: {', '.join(sorted(SETTINGS))}")
        kind, lo, hi, what = SETTINGS[name]

        def bad(need: str):
            raise InputError(where, f"{key} ({what}): must be {need}, got {value!r}")

        if kind in ("int", "number"):
            ok = (isinstance(value, int) and not isinstance(value, bool)) if kind == "int" else _num(value)
            if not ok:
                bad("a whole number" if kind == "int" else "a number")
            low_ok = value > lo if name == "time_limit" else value >= lo
            if not (low_ok and value <= hi):
                bad(f"{'above' if name == 'time_limit' else 'from'} {lo} {'and at most' if name == 'time_limit' else 'to'} {hi}")
        elif kind == "bool":
            if not isinstance(value, bool):
                bad("true or false")
        elif kind == "choice":
            if value not in lo:
                bad("one of " + ", ".join(lo))
        elif kind == "numbers":
            if not isinstance(value, (list, tuple)) or not all(_num(v) and lo <= v <= hi for v in value):
                bad(f"a list of numbers from {lo} to {hi}")
            value = list(value)
        elif kind == "atoms":
            if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) and v for v in value):
                bad("a list of names")
            value = list(value)
        elif kind == "priors":
            if not isinstance(value, (list, tuple)) or not all(
                    isinstance(p, (list, tuple)) and len(p) == 2 and isinstance(p[0], str) and _num(p[1])
                    and lo <= p[1] <= hi for p in value):
                bad(f"a list of [predicate, nats] pairs, nats from {lo} to {hi}")
            value = [list(p) for p in value]
        elif kind == "metarules":
            if not isinstance(value, (list, tuple)) or not value:
                bad("a non-empty list of metarule names")
            for m in value:
                if m not in METARULES:
                    raise InputError(where, f"{key}: unknown metarule {m!r}; known: {', '.join(METARULES)}")
            value = list(value)
        out[name] = value
    return out
