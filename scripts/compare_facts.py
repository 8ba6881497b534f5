"""Whether two code versions wrote the same facts: every cached facts file of version NEW beside the one of
version OLD for the same images, modality, refine setting and perception seed, byte for byte.

    .venv/bin/python scripts/compare_facts.py RUNS OLD NEW     # e.g. RUNS=runs/rerun, OLD and NEW facts versions

A change meant to keep perception's output (a refactor, dead code removed) changes the facts version all the
same (lv3d/experiment/code_version.py), so every study's facts are computed anew; this says whether they are
those of the previous version, so that the calibration maps, fitted on them, still hold (the studies keep their
lv3d results wherever the facts are the same, lv3d/experiment/runner.result_key). The
facts versions are ``python -c "from lv3d.experiment.code_version import facts_version; print(facts_version())"``
at each commit.

The caches under RUNS hold ``.../facts/<key>/<version>/<variant>/<id>.json`` (experiments/README.md). A file of
NEW is paired with OLD's under the same key; where OLD has no folder of that key (another version of the code may
key the same frames otherwise), with OLD's folder of the same variant holding the same file names. Prints the files alike,
those that differ (the first ten named) and those with no counterpart; exits 1 where any differ.
"""

from __future__ import annotations

import argparse
import filecmp
import sys
from pathlib import Path


def variant_dirs(root: Path, version: str) -> list[Path]:
    """Every ``facts/<key>/<version>/<variant>`` folder under ``root``."""
    return sorted(p for p in root.rglob(f"facts/*/{version}/*") if p.is_dir())


def contents(d: Path) -> tuple[str, tuple[str, ...]]:
    """A facts folder's variant and the names of its files: what pairs two folders of one data under two keys."""
    return d.name, tuple(sorted(p.name for p in d.glob("*.json")))


def counterpart(new_dir: Path, old: str, old_by_contents: dict) -> Path | None:
    """OLD's folder for the facts of ``new_dir``: the same key and variant, else the first of OLD's folders
    (``old_by_contents``: :func:`contents` -> folder) with the same variant and file names."""
    same_key = new_dir.parent.parent / old / new_dir.name
    if same_key.is_dir():
        return same_key
    return old_by_contents.get(contents(new_dir))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", type=Path, help="folder holding the study caches (their facts/ folders)")
    ap.add_argument("old", help="the facts version compared against")
    ap.add_argument("new", help="the facts version checked")
    a = ap.parse_args(argv)
    if not a.runs.is_dir():
        print(f"compare_facts: {a.runs}: not a folder", file=sys.stderr)
        return 2
    new_dirs, old_dirs = variant_dirs(a.runs, a.new), variant_dirs(a.runs, a.old)
    if not new_dirs:
        print(f"compare_facts: {a.runs}: no facts of version {a.new}", file=sys.stderr)
        return 2
    old_by_contents: dict = {}
    for d in old_dirs:  # listed once, not once per folder of NEW
        old_by_contents.setdefault(contents(d), d)
    same, differ, alone = 0, [], 0
    for d in new_dirs:
        other = counterpart(d, a.old, old_by_contents)
        for f in sorted(d.glob("*.json")):
            g = other / f.name if other is not None else None
            if g is None or not g.is_file():
                alone += 1
            elif filecmp.cmp(f, g, shallow=False):
                same += 1
            else:
                differ.append(f)
    print(f"{same} facts files alike, {len(differ)} differ, {alone} without a counterpart of {a.old} "
          f"({len(new_dirs)} folders of {a.new})")
    for f in differ[:10]:
        print(f"  differs: {f}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
