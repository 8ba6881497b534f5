"""Run a study: for every condition, system and fold, train each class task (and the multi-class
task) on the training folds and test on the held-out fold; one JSON per (condition, system, fold)
under ``<out>/folds/``, skipped on a rerun when it was made from the same settings (and, for lv3d
systems, the same version of lv3d's code: see code_version.py).

Every system sees the same images, folds and training samples: the samples are drawn from seeds
that depend on (study seed, fold, class) only, never on the system. The cells (condition, system, fold)
are independent jobs, run one after another here or on an executor (executor.py: local processes or a
Dask cluster) with the same results; this process alone writes into ``--out``, which it holds locked.

A class the learner finds no program for (its search runs out of time, nothing covers the positives,
perception found no object in any positive) is recorded in the fold file under ``learn_failures`` with
the reason, and counted in the report; a learn call that fails for a reason of the input stops the study.
"""

from __future__ import annotations

import functools
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml
from tqdm import tqdm

from ..errors import InputError
from ..output import claim, clean_stale, locked, write_atomic
from . import data as data_mod
from .code_version import learner_version, learning_version
from .config import LOGIC_SYSTEMS, TUNE_KEYS, Study, StudyConfig, class_rule, digest, load_study
from .executor import LocalExecutor
from .folds import Item, class_task, fold_path, grouped_folds, multiclass_task, split, stratified_folds
from .report import write_report
from .systems import make_system, modality_of, negative_label


def task_seed(seed: int, fold: int, task: int, draw: int = 0) -> int:
    """A seed for one draw of one (fold, task) cell, independent of the system."""
    return int(np.random.SeedSequence([seed, fold, task] + ([draw] if draw else [])).generate_state(1)[0])


TUNE_TASK = 1_000_000  # the task number of tuning's seeds: above every class task (0, 1, ...) and the multi-class one


def tune_seed(seed: int, fold: int) -> int:
    """The seed of tuning a baseline on one fold's training examples, independent of the system."""
    return task_seed(seed, fold, TUNE_TASK)


def result_key(cfg: StudyConfig, system: str, fold: int, seen: str | None = None) -> str:
    """What a fold result depends on: a finished result with another key is recomputed. ``seen``: the digest of
    what perception gave the system, for an lv3d system the facts it learns from (data.facts_digest), for a
    baseline on real frames where its crops lie (real_data.crops_digest). It stands for the perception and
    grounding code that made them: a result is kept across a change to that code which leaves them as they
    were."""
    d = cfg.to_dict() if isinstance(cfg, StudyConfig) else cfg
    relevant = {k: d[k] for k in ("seed", "folds", "data", "train")}
    if relevant["train"].get("draws") == 1:  # one draw: the key leaves draws out, as results made without it have
        relevant["train"] = {k: v for k, v in relevant["train"].items() if k != "draws"}
    relevant["system"] = system
    relevant["fold"] = fold
    if system in LOGIC_SYSTEMS:
        # workers: speed only; the perception seed and the depth settings change the facts, whose digest the key
        # holds (at their defaults they are left out, as keys have always left them)
        relevant["settings"] = {k: v for k, v in d["lv3d"].items()
                                if k != "workers" and not (k == "perception_seed" and v == 0)
                                and not (k == "depth" and not v)}
        if seen is None:
            raise ValueError(f"the key of an {system} result needs the digest of its facts")
        relevant["code"] = learning_version()  # a change to the learning code or to a fact recomputes
        relevant["facts"] = seen
    else:
        # tuning changes the CNNs only; off, the key is the one results made before the setting existed have
        tuned = system.startswith("cnn-") and d["baselines"].get("tune")
        relevant["settings"] = {k: v for k, v in d["baselines"].items() if tuned or k not in TUNE_KEYS}
    if system not in LOGIC_SYSTEMS:
        from .config import EFFNET_KEYS

        # effnet-* read their own keys and their input only; the other baselines' keys stay as before effnet-*
        b = relevant["settings"]
        if system.startswith("effnet-"):
            relevant["settings"] = {k: b.get(k) for k in ("image_size", "threads", *EFFNET_KEYS)}
        else:
            relevant["settings"] = {k: v for k, v in b.items() if k not in EFFNET_KEYS}
    relevant["data"] = {"classes": d["data"]["classes"], "per_class": d["data"]["per_class"],
                        "noise": d["data"]["noise"], "noise_overrides": d["data"]["noise_overrides"] or {},
                        "seed": d["seed"]}
    if d["data"].get("folders"):  # labelled real frames: the folders' content, not a rendering recipe
        relevant["data"] = {"real": _real_key(tuple(d["data"]["folders"]), tuple(d["data"]["classes"])),
                            "seed": d["seed"]}
        if d["data"].get("split", "frames") != "frames":  # the default leaves the key as results made before it
            relevant["data"]["split"] = d["data"]["split"]
        if system not in LOGIC_SYSTEMS:  # the baselines' crops lie around the objects rgbd perception found
            if seen is None:
                raise ValueError(f"the key of a {system} result on real frames needs the digest of its crops")
            relevant["crops"] = seen
    return digest(relevant)


@functools.lru_cache(maxsize=16)
def _real_key(folders: tuple, classes: tuple) -> str:
    from .real_data import real_data

    return real_data(folders, classes).key


def score_binary(preds: list[tuple[str, float]], test: list[Item], cls: str) -> dict:
    """Accuracy of one class task on the test fold: a prediction is positive iff its label is ``cls``."""
    tp = fp = tn = fn = 0
    for (label, _), it in zip(preds, test):
        pos_pred, pos_true = label == cls, it.cls == cls
        tp += pos_pred and pos_true
        fp += pos_pred and not pos_true
        tn += (not pos_pred) and (not pos_true)
        fn += (not pos_pred) and pos_true
    n = tp + fp + tn + fn
    tpr = tp / (tp + fn) if tp + fn else float("nan")
    tnr = tn / (tn + fp) if tn + fp else float("nan")
    return {"accuracy": (tp + tn) / n if n else float("nan"), "balanced_accuracy": (tpr + tnr) / 2,
            "tp": tp, "fp": fp, "tn": tn, "fn": fn, "n": n}


def run_fold(system, cfg: StudyConfig, train: list[Item], test: list[Item], fold: int,
             programs: Path | None) -> dict:
    """Train and test every task of one fold for one bound system; returns the fold's record.

    With ``train.draws`` > 1 each task is trained on that many independently seeded samples: its accuracies
    are their means, its counts their sums, ``per_draw`` lists each draw's accuracy, its predictions and
    programs are per draw (``draw<d>``); draw 0 is the sample one draw takes. ``learn_failures`` maps a
    task (``task`` or ``task/draw<d>``) to {class: why no program was learned}. For a system that says how it
    reached each answer (an lv3d model's ``answer``), ``answered_by`` lists, per draw, how each multi-class
    answer was reached, in the order of ``test_ids`` (lv3d.learn.model.ANSWER_KINDS)."""
    t = cfg.train
    draws = t.draws
    classes = list(cfg.data.classes)
    test_ids = [it.id for it in test]
    record: dict = {"tasks": {}, "predictions": {}, "learn_failures": {}}

    def save(fitted, task: str, d: int) -> None:
        failures = dict(getattr(fitted, "failures", None) or {})
        if failures:
            record["learn_failures"][task if draws == 1 else f"{task}/draw{d}"] = failures
        if programs is not None:
            fitted.save(programs / task if draws == 1 else programs / task / f"draw{d}")

    def keep(task: str, scores: list[dict], preds: list[list]) -> None:
        as_json = [[[i, str(l), float(c)] for i, (l, c) in zip(test_ids, p)] for p in preds]
        record["predictions"][task] = as_json[0] if draws == 1 else as_json
        if draws == 1:
            record["tasks"][task] = scores[0]
            return
        out = dict(scores[0])
        out.update({k: float(np.mean([s[k] for s in scores])) for k in ("accuracy", "balanced_accuracy") if k in out})
        out.update({k: sum(s[k] for s in scores) for k in ("tp", "fp", "tn", "fn") if k in out})
        out.update(seconds=round(sum(s["seconds"] for s in scores), 3), per_draw=[s["accuracy"] for s in scores])
        record["tasks"][task] = out

    for j, cls in enumerate(classes):
        scores, preds = [], []
        for d in range(draws):
            seed = task_seed(cfg.seed, fold, j, d)
            examples, positive = class_task(train, cls, t.positives, t.negatives_per_positive, seed)
            labels = [cls if p else negative_label(cls) for p in positive]
            t0 = time.perf_counter()
            fitted = system.fit([it.id for it in examples], labels, seed, positive=cls)
            preds.append(fitted.predict(test_ids))
            score = score_binary(preds[-1], test, cls)
            score.update(n_pos=sum(positive), n_neg=len(positive) - sum(positive),
                         seconds=round(time.perf_counter() - t0, 3))
            scores.append(score)
            save(fitted, cls, d)
        keep(cls, scores, preds)
    if t.multiclass:
        scores, preds = [], []
        for d in range(draws):
            seed = task_seed(cfg.seed, fold, len(classes), d)
            examples = multiclass_task(train, t.positives, seed)
            t0 = time.perf_counter()
            fitted = system.fit([it.id for it in examples], [it.cls for it in examples], seed)
            if hasattr(fitted, "answer"):  # an lv3d model says how it reached each answer
                answers = fitted.answer(test_ids)
                preds.append([(label, conf) for label, conf, _ in answers])
                record.setdefault("answered_by", []).append([how for *_, how in answers])
            else:
                preds.append(fitted.predict(test_ids))
            correct = [label == it.cls for (label, _), it in zip(preds[-1], test)]
            scores.append({"accuracy": float(np.mean(correct)), "n": len(correct), "n_train": len(examples),
                           "seconds": round(time.perf_counter() - t0, 3)})
            save(fitted, "multiclass", d)
        keep("multiclass", scores, preds)
    if not record["learn_failures"]:
        del record["learn_failures"]
    return record


def run_cell(job: tuple, inputs: dict) -> tuple[dict, dict[str, str]]:
    """One (condition, system, fold) cell, wherever it runs: (its record, its programs as {relative path:
    text}). ``job``: (condition config, system, fold, training items, test items)."""
    ccfg, sname, k, train, test = job
    system = make_system(sname, ccfg, inputs)
    t0 = time.perf_counter()
    # a baseline that tunes (baselines.tune) chooses its settings here, from this fold's training examples only
    tuned = system.tune(train, tune_seed(ccfg.seed, k)) if hasattr(system, "tune") else None
    files: dict[str, str] = {}
    if sname in LOGIC_SYSTEMS:
        with tempfile.TemporaryDirectory(prefix="lv3d-programs-") as tmp:
            record = run_fold(system, ccfg, train, test, k, Path(tmp))
            files = {str(p.relative_to(tmp)): p.read_text() for p in sorted(Path(tmp).rglob("*")) if p.is_file()}
    else:
        record = run_fold(system, ccfg, train, test, k, None)
    if tuned is not None:
        record["tuned"] = tuned
    record["seconds"] = round(time.perf_counter() - t0, 3)
    return record, files


class _RealInputs:
    """What each system sees of the labelled objects of real frames (real_data), computed on first use."""

    def __init__(self, cfg: StudyConfig, out: Path, rd, executor=None, progress: bool = True):
        self.cfg, self.out, self.rd, self.executor, self.progress = cfg, out, rd, executor, progress
        self._frames: dict[str, dict] = {}
        self._facts: dict[str, dict] = {}
        self._pixels = None
        self.errors: dict[str, dict[str, str]] = {}

    def frames(self, modality: str) -> dict:
        from .code_version import facts_version
        from .real_data import ensure_frame_facts

        if modality not in self._frames:
            lv, cfg = self.cfg.lv3d, self.cfg
            root = Path(cfg.data.cache).expanduser() / "facts" if cfg.data.cache else Path(self.out) / "facts"
            self._frames[modality] = ensure_frame_facts(self.rd, root, facts_version(), modality, lv.refine,
                                                        lv.workers, executor=self.executor,
                                                        seed=lv.perception_seed, depth=lv.depth)
        return self._frames[modality]

    def for_system(self, name: str) -> dict:
        from .real_data import ensure_real_pixels, example_facts_of

        if name in LOGIC_SYSTEMS:
            m = modality_of(name)
            if m not in self._facts:
                facts, self.errors[m] = example_facts_of(self.rd, self.frames(m))
                if self.progress:  # each example perception found no object for: one line naming file and line
                    for why in self.errors[m].values():
                        tqdm.write(f"lv3d: warning: {why} (lv3d-{m} answers \"unknown\")", file=sys.stderr)
                if not self.cfg.lv3d.confidences:
                    facts = {i: data_mod.without_confidences(f) for i, f in facts.items()}
                self._facts[m] = facts
            return self._facts[m]
        if self._pixels is None:
            self._pixels = ensure_real_pixels(self.rd, data_mod.cache_root(self.cfg, self.out),
                                              self.cfg.baselines.image_size, self.frames("rgbd"))
        return self._pixels

    def seen(self, name: str) -> str:
        """The digest of what perception gives system ``name``: its facts (lv3d) or where its crops lie."""
        from .real_data import crops_digest

        return data_mod.facts_digest(self.for_system(name)) if name in LOGIC_SYSTEMS else \
            crops_digest(self.frames("rgbd"))


class _Inputs:
    """What each system sees, computed on first use (facts per modality, pixels once)."""

    def __init__(self, cfg: StudyConfig, out: Path, data: Path, items: list[Item], executor=None):
        self.cfg, self.out, self.data, self.items, self.executor = cfg, out, data, items, executor
        self._facts: dict[str, dict] = {}
        self._pixels = None
        self.errors: dict[str, dict[str, str]] = {}

    def for_system(self, name: str) -> dict:
        if name in LOGIC_SYSTEMS:
            m = modality_of(name)
            if m not in self._facts:
                lv = self.cfg.lv3d
                self._facts[m], self.errors[m] = data_mod.ensure_facts(
                    self.cfg, self.out, self.data, self.items, m, lv.refine, lv.confidences, lv.workers,
                    executor=self.executor)
            return self._facts[m]
        if self._pixels is None:
            self._pixels = data_mod.ensure_pixels(self.data, self.items, self.cfg.baselines.image_size)
        return self._pixels

    def seen(self, name: str) -> str | None:
        """The digest of the facts lv3d system ``name`` learns from; None for a baseline (it sees the images)."""
        return data_mod.facts_digest(self.for_system(name)) if name in LOGIC_SYSTEMS else None


def _write_json(path: Path, obj) -> None:
    write_atomic(path, json.dumps(obj, indent=1))  # a fold file is complete or absent, never half-written


def _write_programs(folder: Path, files: dict[str, str]) -> None:
    """The programs of one cell, replacing what an earlier run of the cell left there."""
    if folder.exists():
        shutil.rmtree(folder)
    for rel, text in files.items():
        write_atomic(folder / rel, text)


def run_study(config: Path, out: Path, overrides: list[str] = (), progress: bool = True, executor=None) -> dict:
    """Run (or resume) the study of ``config`` into ``out``; writes the fold files and the report.
    ``executor``: where the cells run (default: one after another in this process).
    Returns ``{"ran": n, "skipped": n, "report": summary, "learn_failures": n}``."""
    config, out = Path(config), Path(out)
    study = load_study(config, list(overrides))
    claim(out, (config,), own=_is_study)  # a new, empty or lv3d-written folder; filled in place, so it resumes
    with locked(out):
        return _run(study, out, progress, executor or LocalExecutor(1))


def report_study(config: Path, out: Path, overrides: list[str] = ()) -> dict:
    """Rewrite the report of the study folder ``out`` (made by :func:`run_study`) from the fold files it holds,
    for ``config`` with ``overrides``: for a study whose systems were run in parts (a costly baseline at fewer
    sizes, the lv3d systems rerun after a code change). Computes nothing; a (condition, system) without fold
    files is reported as such. Returns the report's summary."""
    study = load_study(Path(config), list(overrides))
    out = Path(out)
    if not _is_study(out):
        raise InputError(out, "not the work folder of a study (lv3d experiment run writes config.yaml and folds/)")
    with locked(out):
        _write_config(out, study)
        return write_report(out, study.base, study.conditions, compare=study.named_conditions)


def _write_config(out: Path, study: Study) -> None:
    """The study's merged config as the report describes it: ``out/config.yaml``."""
    write_atomic(out / "config.yaml", yaml.safe_dump(study.merged, sort_keys=False))


def _run(study: Study, out: Path, progress: bool, executor) -> dict:
    conds = study.conditions
    _write_config(out, study)
    for p in (out / "folds").glob("*/*") if (out / "folds").is_dir() else ():
        clean_stale(p)  # fold files a killed run was writing
    jobs = [(c, s, k) for c in conds for s in conds[c].systems for k in range(conds[c].folds)]
    ran = skipped = failed = 0
    done = _finished_keys(out)
    bar = tqdm(total=len(jobs), desc=study.name, disable=not progress)
    remote = executor if getattr(executor, "name", "local") != "local" else None
    warned: set = set()  # each warning about the examples once, not once per condition
    for cname, ccfg in conds.items():
        items = inputs = None
        seen: dict[str, str | None] = {}  # what perception gave each system (its facts, its crops): part of its key
        if ccfg.data.folders or any(s in LOGIC_SYSTEMS for s in ccfg.systems):
            items, inputs = study_inputs(ccfg, out, remote, progress, warned)
            seen = {s: inputs.seen(s) for s in ccfg.systems}
        pending = []
        for s in ccfg.systems:
            for k in range(ccfg.folds):
                path, key = fold_path(out, cname, s, k), result_key(ccfg, s, k, seen.get(s))
                record = _finished(path, key)
                if record is not None:
                    if s in LOGIC_SYSTEMS:
                        _holds_under(path, record, learner_version())
                    continue
                if key in done:  # same system, data and settings in another condition (a baseline in an ablation)
                    record = json.loads(done[key].read_text())
                    _write_json(path, {**record, "condition": cname, "reused_from": str(done[key].relative_to(out))})
                    continue
                pending.append((s, k))
        skipped += ccfg.folds * len(ccfg.systems) - len(pending)
        bar.update(ccfg.folds * len(ccfg.systems) - len(pending))
        if not pending:
            continue
        if inputs is None:
            items, inputs = study_inputs(ccfg, out, remote, progress, warned)
        if ccfg.data.split == "folders":
            from .real_data import folder_folds

            folds = folder_folds(items, inputs.rd)
        else:
            folds = (grouped_folds if ccfg.data.folders else stratified_folds)(items, ccfg.folds, ccfg.seed)
        by_system: dict[str, list[int]] = {}
        for sname, k in pending:
            by_system.setdefault(sname, []).append(k)
        for sname, ks in by_system.items():
            shared = inputs.for_system(sname)
            cells = [(ccfg, sname, k, *split(folds, k)) for k in ks]
            bar.set_postfix_str(f"{cname} {sname}")
            for i, (record, files) in executor.map(run_cell, cells, shared):
                k, test = ks[i], cells[i][4]
                if sname in LOGIC_SYSTEMS:
                    _write_programs(out / "programs" / cname / sname / f"fold{k}", files)
                record.update(key=result_key(ccfg, sname, k, seen.get(sname)), condition=cname, system=sname,
                              fold=k, test_ids=[it.id for it in test], test_classes=[it.cls for it in test],
                              pipeline_errors=inputs.errors.get(modality_of(sname), {}) if sname in LOGIC_SYSTEMS
                              else {}, code=learner_version() if sname in LOGIC_SYSTEMS else None)
                if ccfg.data.folders:  # rows of objects.csv and classes the study could not use: counted
                    record["left_out"] = inputs.rd.left_out
                _write_json(fold_path(out, cname, sname, k), record)
                done.setdefault(record["key"], fold_path(out, cname, sname, k))
                failed += sum(len(v) for v in record.get("learn_failures", {}).values())
                ran += 1
                bar.update(1)
    bar.close()
    summary = write_report(out, study.base, conds, compare=study.named_conditions)
    return {"ran": ran, "skipped": skipped, "report": summary, "learn_failures": failed}


def study_inputs(ccfg: StudyConfig, out: Path, executor=None, progress: bool = True, warned: set | None = None):
    """(the examples, what each system sees of them) of one condition whose work folder is ``out``: the labelled
    objects of its real frames or the images of its rendered data set, and an object whose ``for_system(name)``
    gives a system's inputs (an lv3d system's facts per example id, as the study learns from them; computed on
    first use and cached). ``warned``: the warnings already printed (the conditions of one study share them),
    each printed once."""
    if ccfg.data.folders:
        rd = _real_examples(ccfg, progress, set() if warned is None else warned)
        return rd.items, _RealInputs(ccfg, out, rd, executor, progress)
    data = data_mod.ensure_dataset(ccfg, out)
    items = data_mod.read_items(data)
    return items, _Inputs(ccfg, out, data, items, executor)


def _real_examples(ccfg: StudyConfig, progress: bool, warned: set):
    """The labelled objects of the condition's folders; each unusable row of objects.csv, and each class of
    data.classes left out (config.class_rule), one line on stderr unless in ``warned``."""
    from .real_data import real_data

    rd = real_data(ccfg.data.folders, ccfg.data.classes)
    rule = class_rule(ccfg.data.split, ccfg.folds)
    lines = [f"data.classes: {c!r} is not {rule}: its {n} object{'' if n == 1 else 's'}"
             for c, n in ccfg.left_out_classes] + [str(p) for p in rd.problems]
    for line in lines:
        if progress and line not in warned:
            print(f"lv3d: warning: {line} (left out)", file=sys.stderr)
        warned.add(line)
    return rd


def _is_study(folder: Path) -> bool:
    """A study's work folder (its config.yaml and folds/) is lv3d's own, marker or not."""
    return (folder / "config.yaml").is_file() and (folder / "folds").is_dir()


def _finished_keys(out: Path) -> dict[str, Path]:
    """key -> fold file, over every finished fold file of the run folder."""
    keys = {}
    for p in sorted((Path(out) / "folds").glob("*/*/fold*.json")):
        try:
            keys.setdefault(json.loads(p.read_text())["key"], p)
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return keys


def _holds_under(path: Path, record: dict, code: str) -> None:
    """Record in the lv3d fold file ``path`` (holding ``record``), kept because its key matched, that its results
    hold under lv3d code version ``code`` too (the same facts, the same learning code) where that is not the
    version that computed them: the report names both (``holds_under``)."""
    if record.get("code") in (None, code) or code in record.get("holds_under", []):
        return
    _write_json(path, {**record, "holds_under": [*record.get("holds_under", []), code]})


def _finished(path: Path, key: str) -> dict | None:
    """The fold file's record where it is finished with ``key``, else None."""
    if not path.is_file():
        return None
    try:
        record = json.loads(path.read_text())
        return record if record.get("key") == key else None
    except (OSError, ValueError, AttributeError):
        return None
