"""Two runs of bench_real side by side: every figure of each, the change, and which way it went for its target.

    .venv/bin/python -m benchmarks.bench_real --json out/before.json      # one version of the code
    .venv/bin/python -m benchmarks.bench_real --json out/after.json       # the other
    .venv/bin/python -m benchmarks.compare_real out/before.json out/after.json
    .venv/bin/python -m benchmarks.compare_real out/before.json out/after.json --folders   # each folder too

The figures are those of ``bench_real --json`` (its module docstring defines them); a row is printed for each
figure and modality both runs measured. *better* / *worse*: the change moves the figure towards / away from
its target (for a figure without one, only the change is shown); a verdict ``ok`` / ``MISS`` says whether each
run meets the target. Where both runs hold the median ms of each stage (``stage_ms_median``), they follow. Timing figures depend on the machine's load: compare them only between runs made in one
sitting (or with farm-bench). Exit status 0, or 2 with one line naming the file when a file cannot be read as
bench_real's JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from benchmarks.bench_real import EXTRA_KEYS, KEYS, STAGES, TARGETS, verdict

FIGURES = KEYS + EXTRA_KEYS
SAME = 5e-4  # a change smaller than this (the JSON's figures are printed to 3 decimals) is no change


class BadRun(Exception):
    pass


def read_run(path: Path) -> dict:
    """bench_real's JSON at ``path``: {"pooled": {modality: {figure: value}}, "folders": {name: {...}}}."""
    try:
        doc = json.loads(Path(path).read_text())
    except (OSError, ValueError) as e:
        raise BadRun(f"{path}: cannot be read as JSON ({e})") from None
    if not (isinstance(doc, dict) and isinstance(doc.get("pooled"), dict) and isinstance(doc.get("folders"), dict)):
        raise BadRun(f"{path}: not the JSON of bench_real --json (it has no 'pooled' and 'folders' objects)")
    return doc


def direction(key: str, old: float, new: float) -> str:
    """'better', 'worse' or 'same' for the change of figure ``key`` from ``old`` to ``new``; '' where the figure
    has no target to say which way is better."""
    if abs(new - old) < (0.05 if key.startswith(("ms_", "cpu_ms")) else SAME):
        return "same"
    t = TARGETS.get(key)
    if t is None:
        return ""
    return "better" if (new > old) == (t[0] == ">=") else "worse"


def rows(a: dict, b: dict) -> list[tuple[str, str, float, float, str]]:
    """(figure, modality, value in a, value in b, direction) for every figure both scopes ``a`` and ``b``
    ({modality: {figure: value}}) measured."""
    out = []
    for key in FIGURES:
        for m in [m for m in a if m in b]:
            old, new = a[m].get(key), b[m].get(key)
            if isinstance(old, (int, float)) and isinstance(new, (int, float)):
                out.append((key, m, float(old), float(new), direction(key, float(old), float(new))))
    return out


def table(title: str, a: dict, b: dict) -> str:
    lines = [title, f"{'figure':24} {'modality':9} {'A':>14} {'B':>14} {'B - A':>9}  change   target"]
    for key, m, old, new, way in rows(a, b):
        fmt = "{:.1f}" if key.startswith(("ms_", "cpu_ms")) or key == "compile_s" else "{:.3f}"
        cell = lambda v: f"{fmt.format(v)} {verdict(key, m, v)}".rstrip()  # noqa: E731
        t = TARGETS.get(key)
        target = "-" if t is None else f"{t[0]} {t[1]:g} ({','.join(t[2])})"
        lines.append(f"{key:24} {m:9} {cell(old):>14} {cell(new):>14} {fmt.format(new - old):>9}  {way:7}  {target}")
    return "\n".join(lines)


def stage_table(a: dict, b: dict) -> str:
    """The median ms of each stage (bench_real's ``stage_ms_median``) in both scopes, per modality both have."""
    lines = []
    for m in [m for m in a if m in b and a[m].get(STAGES) and b[m].get(STAGES)]:
        sa, sb = a[m][STAGES], b[m][STAGES]
        names = list(sa) + [k for k in sb if k not in sa]
        lines.append(f"median ms by stage, {m} (A -> B): " +
                     ", ".join(f"{k} {sa.get(k, 0.0):.1f} -> {sb.get(k, 0.0):.1f}" for k in names))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="compare_real.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a", type=Path, help="bench_real --json of one run (A)")
    ap.add_argument("b", type=Path, help="bench_real --json of the other (B)")
    ap.add_argument("--folders", action="store_true", help="each folder both runs measured, as well as pooled")
    args = ap.parse_args(argv)
    try:
        a, b = read_run(args.a), read_run(args.b)
    except BadRun as e:
        print(f"compare_real.py: error: {e}", file=sys.stderr)
        return 2
    print(table(f"== pooled: A {args.a}, B {args.b}", a["pooled"], b["pooled"]))
    stages = stage_table(a["pooled"], b["pooled"])
    if stages:
        print(stages)
    if args.folders:
        for name in [n for n in a["folders"] if n in b["folders"]]:
            print(table(f"\n== {name}", a["folders"][name], b["folders"][name]))
    worse = [r for r in rows(a["pooled"], b["pooled"]) if r[4] == "worse" and not r[0].startswith(("ms_", "cpu_ms"))]
    print(f"\npooled, figures other than time: {len(worse)} worse"
          + (": " + ", ".join(f"{k} ({m})" for k, m, *_ in worse) if worse else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
