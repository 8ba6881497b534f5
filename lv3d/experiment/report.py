"""The study's report, regenerated from the fold files (never edited by hand):
``results.csv`` (one row per condition x system x fold x task; ``tuned``: the setting a tuned baseline chose on
that fold, as JSON), ``results.json`` (means, standard
deviations, paired tests, the calibration of the multi-class answers and, for lv3d systems, how they were
reached: by a proof, an arbiter, resemblance (near) or none, each kind's count, share right and mean confidence;
which classes the answers confuse), ``results.md`` (the
tables), ``accuracy.png``, ``reliability.png`` (the answers' reliability diagram, last condition),
``confusion.png`` (the multi-class answers of each lv3d system against the true classes, last condition) and
``sweep.png`` when the study has several conditions.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

from ..learn.model import ANSWER_KINDS
from ..output import write_atomic
from .config import LOGIC_SYSTEMS, StudyConfig, class_rule, is_number
from .folds import fold_path
from .stats import ece, mean_std, paired, reliability_bins


def _load(out: Path, cond: str, system: str, folds: int) -> list[dict]:
    recs = []
    for k in range(folds):
        p = fold_path(out, cond, system, k)
        if p.is_file():
            recs.append(json.loads(p.read_text()))
    return recs


def _best_seeing(systems) -> str | None:
    """lv3d-rgbd, or the lv3d system of ``systems`` that sees most (LOGIC_SYSTEMS is ordered rgb, depth, rgbd)."""
    logic = [s for s in LOGIC_SYSTEMS if s in systems]
    return logic[-1] if logic else None


def default_pairs(systems: list[str]) -> list[list[str]]:
    """Every pair of lv3d systems, then lv3d-rgbd (or the best-seeing lv3d system) against each baseline."""
    logic = [s for s in LOGIC_SYSTEMS if s in systems]
    pairs = [[a, b] for i, a in enumerate(logic[::-1]) for b in logic[::-1][i + 1:]]
    if logic:
        pairs += [[_best_seeing(systems), s] for s in systems if s not in LOGIC_SYSTEMS]
    return pairs


def summarise(out: Path, cfg: StudyConfig, condition: str) -> tuple[dict, list[dict]]:
    """(summary of one condition, CSV rows) from its fold files."""
    classes = list(cfg.data.classes)
    rows, summary = [], {"systems": {}, "tests": []}
    cells: dict[str, dict[tuple[int, str], float]] = {}
    balanced: dict[str, dict[tuple[int, str], float]] = {}  # the same cells' balanced accuracy, where they have one
    loaded = []  # every system's fold records
    for s in cfg.systems:
        recs = _load(out, condition, s, cfg.folds)
        loaded += recs
        cells[s], balanced[s] = {}, {}
        per = {"folds_done": len(recs), "classes": {}, "errors": 0, "learn_failures": 0, "learn_failure_examples": []}
        for r in recs:
            per["errors"] = max(per["errors"], len(r.get("pipeline_errors", {})))
            for task, why in sorted(r.get("learn_failures", {}).items()):
                for cls, reason in sorted(why.items()):
                    per["learn_failures"] += 1
                    if len(per["learn_failure_examples"]) < 3:
                        per["learn_failure_examples"].append(f"fold {r['fold']} {task} {cls}: {reason}")
            # a tuned baseline's chosen setting rides on its rows, so that a rerun restoring its folds from the CSV
            # (scripts/restore_baselines.py) keeps it in the report
            tuned = json.dumps({k: r["tuned"][k] for k in ("setting", "inner_accuracy")}) if r.get("tuned") else ""
            for task, sc in r["tasks"].items():
                rows.append({"condition": condition, "system": s, "fold": r["fold"], "task": task,
                             "accuracy": sc["accuracy"], "balanced_accuracy": sc.get("balanced_accuracy", ""),
                             "n": sc["n"], "seconds": sc["seconds"], "tuned": tuned})
                if task != "multiclass":
                    cells[s][(r["fold"], task)] = sc["accuracy"]
                    if is_number(sc.get("balanced_accuracy")):
                        balanced[s][(r["fold"], task)] = sc["balanced_accuracy"]
        for c in classes + ["multiclass"]:
            m, sd = mean_std([r["tasks"][c]["accuracy"] for r in recs if c in r["tasks"]])
            per["classes"][c] = {"mean": m, "std": sd}
        # mean over classes per fold, then mean and std over folds
        m, sd = mean_std([sum(r["tasks"][c]["accuracy"] for c in classes) / len(classes) for r in recs])
        per["mean"] = {"mean": m, "std": sd}
        # the same for balanced accuracy (the mean of the rates on positives and on negatives): a class task's test
        # fold is mostly negatives, where answering "no" scores high; a fold without a positive has none
        m, sd = mean_std([_mean_balanced(r["tasks"], classes) for r in recs])
        per["balanced"] = {"mean": m, "std": sd}
        if cfg.data.split == "folders":  # each fold a folder: what was learned elsewhere holds there?
            names = [Path(f).name for f in cfg.data.folders]
            names = names if len(set(names)) == len(names) else [str(f) for f in cfg.data.folders]
            per["by_folder"] = {names[r["fold"]]: {
                "mean": sum(r["tasks"][c]["accuracy"] for c in classes) / len(classes),
                "balanced": _mean_balanced(r["tasks"], classes),
                "multiclass": r["tasks"].get("multiclass", {}).get("accuracy", math.nan)} for r in recs}
        per["seconds"] = sum(r["seconds"] for r in recs)
        per["code"] = sorted({r["code"] for r in recs if r.get("code")})
        holds = sorted({v for r in recs for v in r.get("holds_under", [])} - set(per["code"]))
        if holds:  # later code versions with the same facts and learning code (runner._holds_under)
            per["holds_under"] = holds
        calibration = answer_calibration(recs)
        if calibration:
            per["calibration"] = calibration
        reached = answer_kinds(recs)
        if reached:
            per["answered_by"] = reached
        confusion = answer_confusion(recs)
        if confusion:
            per["confusion"] = confusion
        left = next((r["left_out"] for r in recs if r.get("left_out") is not None), None)
        if left is not None:
            summary["left_out"] = {**left, "classes": dict(cfg.left_out_classes)}
            summary["class_rule"] = class_rule(cfg.data.split, cfg.folds)
            summary["examples"] = sum(len(r["test_ids"]) for r in recs)
        # settings a tuned baseline chose per fold (baselines.tune), with their inner cross-validation accuracy
        tuned = [{"fold": r["fold"], **r["tuned"]["setting"], "inner_accuracy": r["tuned"]["inner_accuracy"]}
                 for r in recs if r.get("tuned")]
        if tuned:
            per["tuned"] = tuned
        summary["systems"][s] = per
    short = short_draws(loaded, cfg.train.positives, len(classes))
    if short:
        summary["short"] = short
    for a, b in cfg.stats.pairs or default_pairs(list(cfg.systems)):
        common = sorted(set(cells[a]) & set(cells[b]))
        if common:
            t = paired([cells[a][c] for c in common], [cells[b][c] for c in common])
            summary["tests"].append({"a": a, "b": b, "cells": len(common), **t})
    summary["against_best_cnn"] = _against_best(summary, "cnn-")
    summary["against_best_pretrained"] = _against_best(summary, "effnet-")
    summary["against_best_cnn_balanced"] = _against_best_balanced(summary, balanced, "cnn-")
    summary["against_best_pretrained_balanced"] = _against_best_balanced(summary, balanced, "effnet-")
    return summary, rows


def short_draws(records: list[dict], asked: int, n_classes: int) -> dict:
    """The tasks of a condition's fold ``records`` whose training folds held fewer examples than it asks
    (``asked`` positives of the class for a class task; that many of each of the ``n_classes`` classes for the
    multi-class task), where a small data set (a folder of a few frames) caps the draw: {task: (fewest drawn,
    most drawn, asked)} over the records, the short tasks only. The draws take what there is
    (folds.class_task), so the condition's figures are those of fewer."""
    drawn: dict[str, list[int]] = {}
    for r in records:
        for task, sc in r["tasks"].items():
            n = sc.get("n_train") if task == "multiclass" else sc.get("n_pos")
            if isinstance(n, int):
                drawn.setdefault(task, []).append(n)
    short = {}
    for task, ns in drawn.items():
        want = asked * n_classes if task == "multiclass" else asked
        if min(ns) < want:
            short[task] = (min(ns), max(ns), want)
    return short


def _short_text(short: dict) -> str:
    """The line a report gives a condition with :func:`short_draws`."""
    parts = []
    for task in sorted(short):
        lo, hi, want = short[task]
        what = "examples in all" if task == "multiclass" else "positives"
        parts.append(f"{task} {lo if lo == hi else f'{lo}-{hi}'} {what} of the {want} asked")
    return ("Fewer training examples than this condition asks (the training folds hold fewer; a draw takes what "
            "there is, so these figures are those of fewer): " + "; ".join(parts) + ".")


def _multiclass_draws(r: dict) -> list[list]:
    """A fold record's multi-class predictions, one list of [id, label, confidence] per draw (a record of one
    draw holds that list alone); none where it holds no multi-class predictions or no test classes."""
    truth, preds = r.get("test_classes"), r.get("predictions", {}).get("multiclass")
    if not truth or not preds:
        return []
    return preds if isinstance(preds[0][0], list) else [preds]


def answer_calibration(recs: list[dict]) -> dict | None:
    """How well the confidences of a system's multi-class answers match how often they are right, over every
    fold and draw: {"ece", "answers", "bins": [(lower edge, answers, mean confidence, share right), ...]}; None
    where the fold files hold no multi-class predictions with the test classes beside them."""
    conf, right = [], []
    for r in recs:
        for draw in _multiclass_draws(r):
            for (_, label, c), y in zip(draw, r["test_classes"]):
                conf.append(min(1.0, max(0.0, float(c))))
                right.append(label == y)
    if not conf:
        return None
    return {"ece": ece(conf, right), "answers": len(conf), "bins": reliability_bins(conf, right)}


def answer_kinds(recs: list[dict]) -> dict | None:
    """How a system's multi-class answers were reached (the fold files' ``answered_by``, lv3d systems), over
    every fold and draw: {kind: (answers, right, their mean confidence)}; None where the fold files do not say."""
    out: dict[str, list] = {}
    for r in recs:
        for draw, how in zip(_multiclass_draws(r), r.get("answered_by") or []):
            for (_, label, conf), y, kind in zip(draw, r["test_classes"], how):
                n = out.setdefault(kind, [0, 0, 0.0])
                n[0] += 1
                n[1] += label == y
                n[2] += float(conf)
    return {k: (n, right, total / n) for k, (n, right, total) in out.items()} or None


def answer_confusion(recs: list[dict]) -> dict | None:
    """A system's multi-class answers against the true classes, over every fold and draw: {"answers": {true
    class: answers}, "pairs": [[true class, answer, answers], ...]} (``pairs`` holds each pair of a class and an
    answer that names another, ``unknown`` among them, most frequent first, ties by name); None where the fold
    files hold no multi-class predictions with the test classes beside them."""
    answers: dict[str, int] = {}
    wrong: dict[tuple[str, str], int] = {}
    for r in recs:
        for draw in _multiclass_draws(r):
            for (_, label, _), y in zip(draw, r["test_classes"]):
                answers[y] = answers.get(y, 0) + 1
                if label != y:
                    wrong[(y, str(label))] = wrong.get((y, str(label)), 0) + 1
    if not answers:
        return None
    pairs = sorted(wrong.items(), key=lambda kv: (-kv[1], kv[0]))
    return {"answers": dict(sorted(answers.items())), "pairs": [[y, a, n] for (y, a), n in pairs]}


def _best_rival(summary: dict, prefix: str, measure: str) -> tuple[str, str] | None:
    """(the best-seeing lv3d system, the system named ``prefix``* (``cnn-``: the CNNs trained from scratch;
    ``effnet-``: the pretrained networks) with the highest mean of ``measure``, "mean" (binary accuracy) or
    "balanced"), or None when the study has no such pair."""
    lv3d = _best_seeing(summary["systems"])
    rivals = [s for s, per in summary["systems"].items()
              if s.startswith(prefix) and not math.isnan(per[measure]["mean"])]
    if lv3d is None or not rivals:
        return None
    return lv3d, max(rivals, key=lambda s: summary["systems"][s][measure]["mean"])


def _against_best(summary: dict, prefix: str) -> dict | None:
    """The paired test of the best-seeing lv3d system against the system named ``prefix``* with the highest mean
    binary accuracy (:func:`_best_rival`), or None when the study has no such test."""
    pair = _best_rival(summary, prefix, "mean")
    test = None if pair is None else next((t for t in summary["tests"] if (t["a"], t["b"]) == pair), None)
    if test is None:
        return None
    rival = summary["systems"][pair[1]]["mean"]["mean"]
    return {**test, "rival_mean": rival}


def _against_best_balanced(summary: dict, balanced: dict[str, dict], prefix: str) -> dict | None:
    """:func:`_against_best` in balanced accuracy: the best-seeing lv3d system against the system named
    ``prefix``* with the highest mean balanced accuracy, paired over the (fold, class) cells where both have one.
    A class task's test fold is mostly negatives, so a system that answers "no" to nearly everything scores a
    high binary accuracy and a balanced accuracy near 50 %; this comparison is not fooled by it."""
    pair = _best_rival(summary, prefix, "balanced")
    if pair is None:
        return None
    lv3d, best = pair
    common = sorted(set(balanced.get(lv3d, {})) & set(balanced.get(best, {})))
    if not common:
        return None
    return {"a": lv3d, "b": best, "cells": len(common), "rival_mean": summary["systems"][best]["balanced"]["mean"],
            **paired([balanced[lv3d][c] for c in common], [balanced[best][c] for c in common])}


def _mean_balanced(tasks: dict, classes: list[str]) -> float:
    """The mean balanced accuracy of one fold's class tasks that have one (NaN for none)."""
    vals = [tasks[c].get("balanced_accuracy") for c in classes if c in tasks]
    vals = [v for v in vals if is_number(v)]
    return sum(vals) / len(vals) if vals else float("nan")


TOP_CONFUSIONS = 4  # pairs of a true class and a wrong answer named per system in results.md


def _pct(x: dict) -> str:
    return "–" if math.isnan(x["mean"]) else f"{100 * x['mean']:.1f} ± {100 * x['std']:.1f}"


def markdown(name: str, summaries: dict[str, dict], classes: list[str], closing: list[str] = ()) -> str:
    """The report: a section per condition, then the lines ``closing`` (a section on all conditions), then the code
    version the lv3d results were made with."""
    lines = [f"# {name}", "", "Predictive accuracy (%) on the held-out fold, mean ± std over folds. "
             "Class columns: binary class tasks; *mean*: over the class tasks; *balanced*: the class tasks' "
             "balanced accuracy (the mean of the shares right among positives and among negatives; a class task's "
             "test fold is mostly negatives, where answering \"no\" scores high), mean over them; "
             "*multi*: one model for all classes.",
             "Regenerated by `lv3d experiment run` from the fold files; do not edit.", ""]
    for cond, summ in summaries.items():
        if len(summaries) > 1 or cond != "base":
            lines += [f"## {cond}", ""]
        lines.append("| system | " + " | ".join(classes) + " | mean | balanced | multi | folds | pipeline errors |")
        lines.append("|---" * (len(classes) + 6) + "|")
        for s, per in summ["systems"].items():
            cols = [_pct(per["classes"][c]) for c in classes]
            lines.append(f"| {s} | " + " | ".join(cols) + f" | {_pct(per['mean'])} | {_pct(per['balanced'])} | "
                         f"{_pct(per['classes']['multiclass'])} | {per['folds_done']} | {per['errors']} |")
        by_folder = {s: per["by_folder"] for s, per in summ["systems"].items() if per.get("by_folder")}
        if by_folder:
            lines += ["", "Each folder a test fold, learned from the others' objects (data.split folders): mean class "
                      "task, balanced, multi-class (%):", "",
                      "| system | " + " | ".join(next(iter(by_folder.values()))) + " |",
                      "|---" * (1 + len(next(iter(by_folder.values())))) + "|"]
            for s, folders in by_folder.items():
                lines.append(f"| {s} | " + " | ".join(
                    " / ".join("–" if math.isnan(v) else f"{100 * v:.1f}" for v in f.values())
                    for f in folders.values()) + " |")
        if summ.get("short"):
            lines += ["", _short_text(summ["short"])]
        if summ["tests"]:
            lines += ["", "Paired tests over (fold, class) cells of binary accuracy (a − b; ties dropped):", "",
                      "| a | b | cells | mean diff (pts) | 95% interval (bootstrap) | a wins | b wins | ties | sign p "
                      "| Wilcoxon p |",
                      "|---|---|---|---|---|---|---|---|---|---|"]
            for t in summ["tests"]:
                sg = t["sign"]
                lo, hi = t["ci95"]
                lines.append(f"| {t['a']} | {t['b']} | {t['cells']} | {100 * t['mean_diff']:+.1f} | "
                             f"{100 * lo:+.1f} to {100 * hi:+.1f} | {sg['wins']} | "
                             f"{sg['losses']} | {sg['ties']} | {sg['p']:.4g} | {t['wilcoxon']['p']:.4g} |")
        failing = {s: per for s, per in summ["systems"].items() if per.get("learn_failures")}
        if failing:
            lines += ["", "Classes the learner found no program for (their tasks answer \"unknown\", the negative "
                      "answer; counted in the accuracies above):", ""]
            for s, per in failing.items():
                lines.append(f"- {s}: {per['learn_failures']} (" + "; ".join(per["learn_failure_examples"]) +
                             ("; ..." if per["learn_failures"] > len(per["learn_failure_examples"]) else "") + ")")
        tuned = [(s, t) for s, per in summ["systems"].items() for t in per.get("tuned", [])]
        if tuned:
            lines += ["", "CNN settings chosen per fold by inner cross-validation on that fold's training examples "
                      "(baselines.tune; inner accuracy: multi-class, mean over the inner folds):", "",
                      "| system | fold | width | epochs | augment | input px | inner accuracy |",
                      "|---|---|---|---|---|---|---|"]
            for s, t in tuned:
                lines.append(f"| {s} | {t['fold']} | {t['width']} | {t['epochs']} | {'on' if t['augment'] else 'off'} "
                             f"| {t['image_size']} | {100 * t['inner_accuracy']:.1f} |")
        calibrated = {s: per["calibration"] for s, per in summ["systems"].items() if per.get("calibration")}
        if calibrated:
            lines += ["", "Calibration of the multi-class answers (the answer's confidence against how often it is "
                      "right, 10 equal-width bins; reliability.png):", "",
                      "| system | answers | ECE | mean confidence | share right |", "|---|---|---|---|---|"]
            for s, c in calibrated.items():
                n = sum(b[1] for b in c["bins"])
                mc = sum(b[1] * b[2] for b in c["bins"]) / n
                mr = sum(b[1] * b[3] for b in c["bins"]) / n
                lines.append(f"| {s} | {c['answers']} | {c['ece']:.3f} | {mc:.3f} | {mr:.3f} |")
        reached = {s: per["answered_by"] for s, per in summ["systems"].items() if per.get("answered_by")}
        if reached:
            lines += ["", "How the lv3d systems reached their multi-class answers (answers, the share right, and their "
                      "mean confidence): "
                      "*proof*, a class's program proves the object and ranks first; *arbiter*, two classes' "
                      "programs prove it and an arbiter between them chose; *near*, no program proves it and the "
                      "training object it resembles most names the class; *unknown*, no answer (no object, or no "
                      "program):", "",
                      "| system | " + " | ".join(ANSWER_KINDS) + " |", "|---|" + "---|" * len(ANSWER_KINDS)]
            for s, kinds in reached.items():
                cols = [f"{kinds[k][0]} ({100 * kinds[k][1] / kinds[k][0]:.0f} %, {kinds[k][2]:.2f})"
                        if kinds.get(k, (0,))[0] else "0" for k in ANSWER_KINDS]
                lines.append(f"| {s} | " + " | ".join(cols) + " |")
        confused = {s: per["confusion"] for s, per in summ["systems"].items() if per.get("confusion")}
        if confused:
            lines += ["", f"Which classes the multi-class answers confuse (true class → answer: how many of that "
                      f"class's answers, over folds and draws; *unknown*: no answer), the {TOP_CONFUSIONS} most "
                      f"frequent per system (confusion.png: every pair, lv3d systems):", "",
                      "| system | wrong | most frequent |", "|---|---|---|"]
            for s, c in confused.items():
                total, wrong = sum(c["answers"].values()), sum(n for *_, n in c["pairs"])
                top = "; ".join(f"{y} → {a} {n} of {c['answers'][y]}" for y, a, n in c["pairs"][:TOP_CONFUSIONS])
                lines.append(f"| {s} | {wrong} of {total} | {top or '–'} |")
        left = summ.get("left_out")
        if left is not None:
            few = left.get("classes", {})
            other = ", ".join(f"{k} {v}" for k, v in sorted(left["other_classes"].items()) if k not in few) or "none"
            too_few = "".join(f", objects of {k}, a class not {summ['class_rule']}: {v}" for k, v in sorted(few.items()))
            lines += ["", f"Examples: {summ['examples']} labelled objects of the study's classes; left out: "
                      f"{len(left['unusable_rows'])} unusable rows of objects.csv, objects of other classes: {other}"
                      f"{too_few}. "
                      "*pipeline errors*: examples whose labelled pixel lies on no object that system's perception "
                      "found (answered \"unknown\")."]
            lines += [f"- {row}" for row in left["unusable_rows"][:10]]
        for key, what in (("against_best_cnn", "the best CNN"), ("against_best_pretrained", "the best pretrained network")):
            best = summ.get(key)
            if best:
                lo, hi = best["ci95"]
                lines += ["", f"{best['a']} against {what} here ({best['b']}, {100 * best['rival_mean']:.1f}): "
                          f"{100 * best['mean_diff']:+.1f} points, 95% interval {100 * lo:+.1f} to {100 * hi:+.1f}."]
            bal = summ.get(f"{key}_balanced")
            if bal:
                lo, hi = bal["ci95"]
                lines += ["", f"In balanced accuracy, {bal['a']} against {what} by it ({bal['b']}, "
                          f"{100 * bal['rival_mean']:.1f}): {100 * bal['mean_diff']:+.1f} points, 95% interval "
                          f"{100 * lo:+.1f} to {100 * hi:+.1f} ({bal['cells']} cells)."]
        lines.append("")
    lines += closing
    pers = [per for summ in summaries.values() for per in summ["systems"].values()]
    versions = sorted({v for per in pers for v in per.get("code", [])})
    holds = sorted({v for per in pers for v in per.get("holds_under", [])} - set(versions))
    if versions:
        lines.append("lv3d results made with lv3d code version " + ", ".join(f"`{v}`" for v in versions) +
                     " (a digest of its source: lv3d/experiment/code_version.py)" +
                     ("; they hold for version " + ", ".join(f"`{v}`" for v in holds) + " too, whose facts "
                      "and learning code are the same" if holds else "") + ".")
        lines.append("")
    return "\n".join(lines)


def plot(out: Path, summaries: dict[str, dict], classes: list[str]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first = next(iter(summaries.values()))
    systems = list(first["systems"])
    fig, ax = plt.subplots(figsize=(max(6, 1.2 * len(classes) * len(systems) / 3), 4))
    width = 0.8 / max(1, len(systems))
    groups = classes + ["mean", "multiclass"]
    for i, s in enumerate(systems):
        per = first["systems"][s]
        vals = [per["classes"][c] if c != "mean" else per["mean"] for c in groups]
        ax.bar([g + i * width for g in range(len(groups))], [100 * v["mean"] for v in vals], width,
               yerr=[100 * v["std"] for v in vals], label=s, capsize=2)
    ax.set_xticks([g + 0.4 - width / 2 for g in range(len(groups))], groups, rotation=20)
    ax.set_ylabel("accuracy (%)")
    ax.set_ylim(0, 105)
    ax.set_title(next(iter(summaries)))
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "accuracy.png", dpi=110)
    plt.close(fig)
    last = summaries[list(summaries)[-1]]
    calibrated = {s: per["calibration"] for s, per in last["systems"].items() if per.get("calibration")}
    if calibrated:
        fig, ax = plt.subplots(figsize=(5, 5))
        ax.plot([0, 1], [0, 1], color="grey", lw=1, ls="--", label="perfect")
        for s, c in calibrated.items():
            ax.plot([b[2] for b in c["bins"]], [b[3] for b in c["bins"]], marker="o", label=f"{s} (ECE {c['ece']:.2f})")
        ax.set_xlabel("confidence of the answer")
        ax.set_ylabel("share of answers right")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_title(f"multi-class answers, {list(summaries)[-1]}")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out / "reliability.png", dpi=110)
        plt.close(fig)
    confused = {s: per["confusion"] for s, per in last["systems"].items()
                if s in LOGIC_SYSTEMS and per.get("confusion")}
    if confused:
        _plot_confusion(out / "confusion.png", confused, classes, list(summaries)[-1])
    if len(summaries) > 1:
        fig, ax = plt.subplots(figsize=(7, 4))
        conds = list(summaries)
        for s in systems:
            ys = [summaries[c]["systems"][s]["mean"] for c in conds]
            ax.errorbar(range(len(conds)), [100 * y["mean"] for y in ys], [100 * y["std"] for y in ys],
                        label=s, marker="o", capsize=2)
        ax.set_xticks(range(len(conds)), conds, rotation=20)
        ax.set_ylabel("mean class-task accuracy (%)")
        ax.set_ylim(0, 105)
        ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        fig.savefig(out / "sweep.png", dpi=110)
        plt.close(fig)


def confusion_matrix(confusion: dict, classes: list[str]) -> tuple[list[str], list[list[float]]]:
    """The answers of :func:`answer_confusion` as a matrix: the answer columns (``classes``, then ``unknown``
    and any other answer met) and one row per class of ``classes``, each the share of that class's answers
    (a row of zeros for a class with none)."""
    cols = list(classes) + ["unknown"]
    cols += sorted({a for _, a, _ in confusion["pairs"]} - set(cols))
    rows = []
    for y in classes:
        n = confusion["answers"].get(y, 0)
        row = [0.0] * len(cols)
        if n:
            for yy, a, k in confusion["pairs"]:
                if yy == y:
                    row[cols.index(a)] = k / n
            row[cols.index(y)] = 1.0 - sum(row)  # the right answers: every class is a column
        rows.append(row)
    return cols, rows


def _plot_confusion(path: Path, confused: dict[str, dict], classes: list[str], title: str) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(confused), figsize=(0.55 * len(classes) * len(confused) + 2.5,
                                                         0.5 * len(classes) + 2.2), squeeze=False)
    for ax, (s, c) in zip(axes[0], confused.items()):
        cols, rows = confusion_matrix(c, classes)
        ax.imshow(rows, vmin=0, vmax=1, cmap="Blues")
        for i, row in enumerate(rows):
            for j, v in enumerate(row):
                if v >= 0.005:
                    ax.text(j, i, f"{100 * v:.0f}", ha="center", va="center", fontsize=6,
                            color="white" if v > 0.5 else "black")
        ax.set_xticks(range(len(cols)), cols, rotation=60, ha="right", fontsize=7)
        ax.set_yticks(range(len(classes)), classes if ax is axes[0][0] else [""] * len(classes), fontsize=7)
        ax.set_xlabel("answer")
        ax.set_title(s, fontsize=9)
    axes[0][0].set_ylabel("true class")
    fig.suptitle(f"multi-class answers (% of the true class's), {title}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def against_first(rows: list[dict], conditions: list[str], systems: list[str]) -> list[dict]:
    """Each later condition against the first, per system: the paired tests over the (fold, class) cells of binary
    accuracy both hold (a: the condition, b: the first), and the difference of their multi-class accuracy (mean
    over folds, each fold's over its draws, as the tables give it; None where either lacks it). ``rows`` are the
    report's CSV rows. A system whose every cell is the same in both is left out: a baseline the conditions'
    switches do not reach, whose fold results are reused."""
    acc: dict = {}
    for r in rows:
        acc.setdefault((r["condition"], r["system"]), {})[(r["fold"], r["task"])] = r["accuracy"]
    out = []
    first = conditions[0]
    for s in systems:
        base = acc.get((first, s), {})
        for cond in conditions[1:]:
            mine = acc.get((cond, s), {})
            shared = sorted(set(base) & set(mine))
            common = [k for k in shared if k[1] != "multiclass"]
            if not common or all(mine[k] == base[k] for k in shared):
                continue
            multi = [(mine[k], base[k]) for k in shared if k[1] == "multiclass"]
            out.append({"system": s, "condition": cond, "first": first, "cells": len(common),
                        **paired([mine[k] for k in common], [base[k] for k in common]),
                        "multiclass_diff": mean_std([a for a, _ in multi])[0] - mean_std([b for _, b in multi])[0]
                        if multi else None})
    return out


def against_first_markdown(tests: list[dict]) -> list[str]:
    """The report's section of :func:`against_first` (no lines when there is no test)."""
    if not tests:
        return []
    first = tests[0]["first"]
    lines = [f"## Each condition against {first}", "",
             f"Paired tests over (fold, class) cells of binary accuracy, the condition against {first} (condition − "
             f"{first}; ties dropped), and the difference of multi-class accuracy:", "",
             "| system | condition | cells | mean diff (pts) | 95% interval (bootstrap) | condition wins | "
             f"{first} wins | ties | sign p | Wilcoxon p | multi diff (pts) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for t in tests:
        sg, (lo, hi) = t["sign"], t["ci95"]
        multi = "–" if t["multiclass_diff"] is None else f"{100 * t['multiclass_diff']:+.1f}"
        lines.append(f"| {t['system']} | {t['condition']} | {t['cells']} | {100 * t['mean_diff']:+.1f} | "
                     f"{100 * lo:+.1f} to {100 * hi:+.1f} | {sg['wins']} | {sg['losses']} | {sg['ties']} | "
                     f"{sg['p']:.4g} | {t['wilcoxon']['p']:.4g} | {multi} |")
    return lines + [""]


def write_report(out: Path, cfg: StudyConfig, conds: dict[str, StudyConfig], compare: bool = False) -> dict:
    """Write results.{csv,json,md} and the plots into ``out``; returns the summaries per condition. ``compare``
    (a study of named conditions, such as ablations): each condition is also tested against the first
    (:func:`against_first`, in results.json's ``against_first`` and a section of results.md)."""
    out = Path(out)
    summaries, rows = {}, []
    for cname, c in conds.items():
        summ, r = summarise(out, c, cname)
        summaries[cname] = summ
        rows += r
    tests = against_first(rows, list(conds), list(cfg.systems)) if compare and len(conds) > 1 else []
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, ["condition", "system", "fold", "task", "accuracy", "balanced_accuracy", "n", "seconds",
                             "tuned"])
    w.writeheader()
    w.writerows(rows)
    write_atomic(out / "results.csv", buf.getvalue())
    extra = {"against_first": tests} if tests else {}
    write_atomic(out / "results.json", json.dumps({"name": cfg.name, "conditions": summaries, **extra}, indent=1))
    classes = list(cfg.data.classes)
    write_atomic(out / "results.md", markdown(cfg.name, summaries, classes, against_first_markdown(tests)))
    plot(out, summaries, classes)
    return summaries
