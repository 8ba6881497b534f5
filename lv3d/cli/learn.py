"""``lv3d mil TASK.pl`` (classic MIL tasks) and ``lv3d learn fit|predict`` (shape concepts from a
rendered data set, docs/dataset.md)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from ..errors import InputError, read_json
from ..facts import MODALITIES


def _setting(text: str) -> tuple[str, object]:
    """NAME=VALUE of --set: the value read as JSON (numbers, true/false, lists), else as a name."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip():
        raise InputError("--set", f"expected NAME=VALUE, got {text!r}")
    try:
        value = json.loads(raw)
    except json.JSONDecodeError:
        value = raw.strip()
    return name.strip(), value


@click.command()
@click.argument("task", type=click.Path(path_type=Path))
@click.option("--goal", default=None, help="learn this goal only (a goal clause's name, e.g. a; default: the goals "
                                           "the file's directives run, else every learning goal clause)")
@click.option("--noisy", is_flag=True, help="the noise-tolerant search: programs from samples of the examples, "
                                            "scored on all of them (wrong labels, facts with confidences)")
@click.option("--set", "sets", multiple=True, metavar="NAME=VALUE",
              help="a learner setting, e.g. --set max_clauses=4 (repeatable; docs/learner.md lists them)")
@click.option("--time-limit", type=click.FloatRange(0, 86400, min_open=True), default=None,
              help="seconds for each goal's search (default: the task's, else 10)")
@click.option("--memory-limit", type=click.IntRange(64, 1 << 20), default=None,
              help="MB for the learner's process (default 2048)")
@click.option("--timing", is_flag=True, help="print each goal's learning time on stderr")
def mil(task: Path, goal: str | None, noisy: bool, sets: tuple[str, ...], time_limit: float | None,
        memory_limit: int | None, timing: bool):
    """Learn the task file TASK (Metagol's example files unchanged, or lv3d's form) and print each goal's
    program as Metagol prints it. Exit status 1 when a goal has no program within its bounds, 2 when a
    goal or the file cannot be learned (one line on stderr)."""
    from ..learn.engine import LearnError
    from ..learn.settings import check_settings
    from ..learn.task import MEMORY_MB, run_task

    settings = check_settings(dict(_setting(t) for t in sets), "--set")
    try:
        run = run_task(task, time_limit=time_limit, settings=settings, goal=goal,
                       mode="noisy" if noisy else "exact", memory_mb=memory_limit or MEMORY_MB)
    except LearnError as e:
        raise InputError(task, str(e).split(": ", 1)[-1]) from None
    for w in run.warnings:
        click.echo(f"lv3d: warning: {task}: {w}", err=True)
    several = len(run.goals) > 1
    code = 0
    for g in run.goals:
        if several:
            click.echo(f"% {g.name}")
        if g.error is not None:
            click.echo(f"lv3d: error: {task}: {f'{g.name}: ' if several else ''}{g.error}", err=True)
            code = 2
        elif g.clauses is None:
            click.echo("% unable to learn a solution")
            code = max(code, 1)
        else:
            click.echo("\n".join(g.clauses))
        if timing:
            click.echo(f"% {g.name}: {g.cpu_s:.3f} s cpu, {g.wall_s:.3f} s wall", err=True)
    if code:
        raise click.exceptions.Exit(code)


@click.group()
def learn():
    """Learn shape concepts from a data set and classify with them."""


def _dataset_scenes(data: Path, modality: str, facts: str):
    """(scenes, labels) of a data set directory: facts from the ground truth or through the pipeline."""
    from ..truth_facts import truth_facts

    manifest = data / "manifest.json"
    if not manifest.is_file():
        raise InputError(data, "not a data set (no manifest.json)")
    try:
        items = json.loads(manifest.read_text())["items"]
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError) as e:
        raise InputError(manifest, f"malformed: {e}") from None
    if not isinstance(items, list):
        raise InputError(manifest, "items: must be a list of {id, class, dir}")
    for i, it in enumerate(items):
        if not (isinstance(it, dict) and all(isinstance(it.get(k), str) and it.get(k) for k in ("id", "class", "dir"))):
            raise InputError(manifest, f"items[{i}]: must be {{id, class, dir}} (texts), got {it!r}")
    scenes, labels = [], []
    for it in items:
        item_dir = data / it["dir"]
        if facts == "truth":
            meta_path = item_dir / "meta.json"
            meta = read_json(meta_path, "meta.json")
            scenes.append(truth_facts(meta, it["id"], modality))
        else:
            from ..pipeline import scene_facts
            from ..rgbd import load_item

            scenes.append(scene_facts(load_item(item_dir), it["id"], modality))
        labels.append(it["class"])
    if not scenes:
        raise InputError(data, "the data set lists no items")
    return scenes, labels


_data = click.option("--data", type=click.Path(path_type=Path), required=True, help="data set directory")
_modality = click.option("--modality", type=click.Choice(MODALITIES), default="rgbd", show_default=True)
_facts = click.option("--facts", type=click.Choice(["truth", "pipeline"]), default="truth", show_default=True,
                      help="facts from the ground truth or from perception + grounding")


@learn.command()
@_data
@_modality
@_facts
@click.option("--classes", default=None, help="comma-separated classes to learn (default: all in the data)")
@click.option("--out", type=click.Path(path_type=Path), required=True, help="directory for the programs")
@click.option("--seed", type=click.IntRange(0, 2 ** 32 - 1), default=0, show_default=True)
@click.option("--time-limit", type=click.FloatRange(0, 86400, min_open=True), default=None, help="seconds per class")
def fit(data: Path, modality: str, facts: str, classes: str | None, out: Path, seed: int, time_limit: float | None):
    """Learn one program per class and save them as .pl files in OUT."""
    from ..output import check_out, replacing
    from ..learn.model import Model

    check_out(out, (data,))  # before any work: a file, a folder lv3d did not write or one holding the data
    wanted = [c.strip() for c in classes.split(",") if c.strip()] if classes is not None else None
    if wanted is not None and not wanted:
        raise InputError("--classes", "no class given")
    scenes, labels = _dataset_scenes(data, modality, facts)
    for c in wanted or ():
        if c not in labels:
            raise InputError("--classes", f"no item of {data} is a {c!r}; its classes: {', '.join(sorted(set(labels)))}")
    settings = {"time_limit": time_limit} if time_limit is not None else None
    model = Model.fit(scenes, labels, settings=settings, seed=seed, classes=wanted)
    if not model.programs and model.failures:  # nothing learned: no empty model is saved
        why = "; ".join(f"{c}: {w}" for c, w in model.failures.items())
        raise click.ClickException(f"no program learned for any class ({why})")
    with replacing(out, (data,)) as tmp:  # written beside OUT, then moved into its place
        model.save(tmp)
    for c, p in model.programs.items():
        if p.target != c:
            click.echo(f"% {c}: learned as {p.target}, since {c} names a body predicate")
        click.echo(f"% {c}: covers {p.score['tp']}/{p.score['n_pos']} positives, "
                   f"{p.score['fp']}/{p.score['n_neg']} negatives\n{p}\n")
    for c, why in model.failures.items():
        click.echo(f"no program for {c}: {why}", err=True)


@learn.command()
@_data
@_modality
@_facts
@click.option("--model", "model_dir", type=click.Path(path_type=Path), required=True)
@click.option("--explain/--no-explain", default=False, help="print each answer's proof")
def predict(data: Path, modality: str, facts: str, model_dir: Path, explain: bool):
    """Classify every item of a data set with saved programs; print accuracy."""
    from ..learn.model import Model

    model = Model.load(model_dir)
    learned = sorted({p.modality for p in model.programs.values() if p.modality})
    if not model.programs:
        raise InputError(model_dir, "the model holds no program")
    if learned and learned != [modality]:
        raise InputError("--modality", f"the model in {model_dir} was learned from {', '.join(learned)} facts; "
                                       f"predict with --modality {learned[0]}")
    scenes, labels = _dataset_scenes(data, modality, facts)
    correct = 0
    for s, y in zip(scenes, labels):
        if explain:
            e = model.explain(s)
            label, conf = e.label, e.confidence
            click.echo(f"{s.scene} ({y}): {e}")
        else:
            label, conf = model.predict(s)
            click.echo(f"{s.scene}\t{y}\t{label}\t{conf:.3f}")
        correct += label == y
    click.echo(f"accuracy {correct}/{len(scenes)} = {correct / len(scenes):.3f}")

