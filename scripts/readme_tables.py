"""Rewrite the figures in experiments/README.md's study tables, and in the top-level README's seed-protocol table,
from the committed reports (experiments/results/<study>/results.csv), so that the tables are never typed by hand.

    .venv/bin/python scripts/readme_tables.py            # print what would change
    .venv/bin/python scripts/readme_tables.py --write    # rewrite both READMEs

Each study's section (its ``### heading``) holds one table, whose layout is kept: row and column labels stay
as written; only the figures are recomputed, as the runner's report computes them (lv3d/experiment/report.py:
per fold the mean binary accuracy over the class tasks, then the mean over folds; multi-class likewise).
- The seed protocol's table has a row per system and columns ``<condition>: mean`` / ``<condition>: multi``
  (``mean ± std``).
- Every other table has a row per condition, in the study's order, and a column per system
  (``mean / multi``). Column labels are system names, optionally followed by words in parentheses.
- A study's replicates (section ``### <Study heading>: replicates``, first header cell ``data seed``: the seed
  protocol's and the ten classes') have a row per (data seed, condition), seed 0 being the study itself and seed s
  the report ``experiments/results/<study>_seed<s>/``, and a column per lv3d system (``mean / multi``).
- The top-level README's seed-protocol table (header ``| system | clean | realsense noise |``) has a row per lv3d
  system and the best CNN, the best pretrained network and the best decision tree of each condition (highest mean
  binary accuracy), each cell ``mean / multi``, the best baseline's modality in parentheses.
"""

from __future__ import annotations

import argparse
import csv
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lv3d.experiment.stats import mean_std

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "experiments" / "README.md"
TOP_README = ROOT / "README.md"
TOP_HEADER = "| system | clean | realsense noise |"
# row label prefix -> the systems it picks among
BEST = {"best CNN": "cnn-", "best pretrained network": "effnet-", "best decision tree": "tree-"}
# section heading -> (study, its table's first header cell)
SECTIONS = {
    "### Seed protocol": ("seed_protocol", "system"),
    "### Learning curve": ("learning_curve", "positives"),
    "### Few-shot": ("few_shot", "positives"),
    "### Ablations": ("ablations", "condition"),
    "### Ablations on real frames": ("real_ablations", "condition"),
    "### Real objects": ("real_objects", "positives"),
    "### Real objects, Kinect table-tops alone": ("real_objects_osd", "positives"),
    "### Real objects, RealSense clutter alone": ("real_objects_ycb", "positives"),
    "### Real objects across sensors": ("real_across_sensors", "positives"),
    "### Ten classes": ("ten_classes", "noise"),
    "### Ten classes: learning curve": ("ten_classes_curve", "positives"),
}
# section heading -> the study whose replicates its table holds
REPLICATES = {"### Seed protocol: replicates": "seed_protocol", "### Ten classes: replicates": "ten_classes"}
NOISE = {"k": "noise_depth", "p": "noise_occlusion", "colour sigma": "noise_color",
         "clutter objects": "noise_clutter", "exposure": "noise_lighting"}


def summary(study: str) -> dict[str, dict[str, tuple[float, float, float, float]]]:
    """condition -> system -> (mean binary %, its std over folds, multi-class %, its std), conditions in file order."""
    path = ROOT / "experiments" / "results" / study / "results.csv"
    if not path.is_file():
        raise SystemExit(f"error: {path}: not found")
    acc: dict = defaultdict(lambda: defaultdict(lambda: defaultdict(dict)))
    with path.open(newline="") as f:
        for r in csv.DictReader(f):
            acc[r["condition"]][r["system"]][int(r["fold"])][r["task"]] = float(r["accuracy"])
    out: dict = {}
    for cond, systems in acc.items():
        out[cond] = {}
        for s, folds in systems.items():
            binary = mean_std([np.mean([v for t, v in tasks.items() if t != "multiclass"]) for tasks in folds.values()])
            multi = mean_std([tasks["multiclass"] for tasks in folds.values() if "multiclass" in tasks])
            out[cond][s] = tuple(100 * v for v in binary + multi)
    return out


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _system(label: str) -> str:
    return re.sub(r"\s*\(.*\)$", "", label.replace("*", "")).strip()


def _pm(mean: float, std: float) -> str:
    return f"{mean:.1f} ± {std:.1f}"


def rewrite_table(lines: list[str], study: str) -> list[str]:
    """The table ``lines`` (header, rule, rows) with its figures recomputed from ``study``'s results."""
    s = summary(study)
    header = _cells(lines[0])
    out = lines[:2]
    if study == "seed_protocol":
        for line in lines[2:]:
            cells = _cells(line)
            bold = cells[0].startswith("**")
            row = [cells[0]]
            for col in header[1:]:
                cond, kind = (x.strip() for x in col.split(":"))
                m, sd, mm, msd = s[f"noise={cond}"][_system(cells[0])]
                v = _pm(m, sd) if kind == "mean" else _pm(mm, msd)
                row.append(f"**{v}**" if bold else v)
            out.append("| " + " | ".join(row) + " |")
        return out
    conds = list(s)
    if len(lines) - 2 != len(conds):
        raise SystemExit(f"error: {README}: the {study} table has {len(lines) - 2} rows, its results {len(conds)} conditions")
    for line, cond in zip(lines[2:], conds):
        label = _cells(line)[0]
        row = [label] + [f"{s[cond][_system(c)][0]:.1f} / {s[cond][_system(c)][2]:.1f}" if _system(c) in s[cond]
                         else "–" for c in header[1:]]  # a system not run in this condition
        out.append("| " + " | ".join(row) + " |")
    return out


def rewrite_replicates(lines: list[str], study: str) -> list[str]:
    """The replicates table ``lines`` of ``study``: row label ``<seed>[ (...)]``, then the condition, then a cell per
    system."""
    header = _cells(lines[0])
    out = lines[:2]
    for line in lines[2:]:
        cells = _cells(line)
        seed = int(cells[0].split()[0])
        s = summary(study if seed == 0 else f"{study}_seed{seed}")[f"noise={cells[1]}"]
        row = cells[:2] + [f"{s[_system(c)][0]:.1f} / {s[_system(c)][2]:.1f}" for c in header[2:]]
        out.append("| " + " | ".join(row) + " |")
    return out


def rewrite(text: str) -> str:
    lines = text.split("\n")
    section = None
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("### "):
            section = line.strip()
        if line.startswith("| ") and i + 1 < len(lines) and lines[i + 1].startswith("|---"):
            first = _cells(line)[0]
            study = None
            if section in REPLICATES and first == "data seed":
                study = "replicates"
            elif section in SECTIONS and SECTIONS[section][1] == first:
                study = SECTIONS[section][0]
            elif section == "### Noise sweeps" and first in NOISE:
                study = NOISE[first]
            j = i + 2
            while j < len(lines) and lines[j].startswith("|"):
                j += 1
            if study == "replicates":
                lines[i:j] = rewrite_replicates(lines[i:j], REPLICATES[section])
            elif study is not None:
                lines[i:j] = rewrite_table(lines[i:j], study)
            i = j
            continue
        i += 1
    return "\n".join(lines)


def rewrite_top(text: str) -> str:
    """The top-level README ``text`` with its seed-protocol table's figures recomputed."""
    lines = text.split("\n")
    if TOP_HEADER not in lines:
        raise SystemExit(f"error: {TOP_README}: no table with the header {TOP_HEADER!r}")
    i = lines.index(TOP_HEADER)
    s = summary("seed_protocol")
    conds = [f"noise={c.split()[0]}" for c in _cells(TOP_HEADER)[1:]]
    j = i + 2
    while j < len(lines) and lines[j].startswith("|"):
        cells = _cells(lines[j])
        label = cells[0]
        bold = label.startswith("**")
        row = [label]
        prefix = next((p for k, p in BEST.items() if label.startswith(k)), None)  # None: an lv3d system's row
        for cond in conds:
            if prefix is None:
                m, _, mm, _ = s[cond][_system(label)]
                v = f"{m:.1f} / {mm:.1f}"
            else:
                best = max((x for x in s[cond] if x.startswith(prefix)), key=lambda x: (s[cond][x][0], x))
                v = f"{s[cond][best][0]:.1f} / {s[cond][best][2]:.1f} ({best[len(prefix):]})"
            row.append(f"**{v}**" if bold else v)
        lines[j] = "| " + " | ".join(row) + " |"
        j += 1
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--write", action="store_true", help="rewrite both READMEs (default: print a diff)")
    a = ap.parse_args(argv)
    import difflib

    for path, fn in ((README, rewrite), (TOP_README, rewrite_top)):
        old = path.read_text()
        new = fn(old)
        if a.write:
            path.write_text(new)
        name = str(path.relative_to(ROOT))
        sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), new.splitlines(True), name, "rewritten"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
