"""``lv3d mil TASK.pl`` (classic MIL tasks) and ``lv3d learn fit|predict|explain`` (shape concepts from a
rendered data set, docs/dataset.md, or from the labelled objects of a folder of real frames,
docs/real_frames.md)."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import click

from .. import compile_cache
from ..errors import InputError
from ..facts import MODALITIES
from .depth_set import depth_overrides, depth_set_option, model_depth, save_with_model, shown


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


def _named(data: tuple[Path, ...]) -> str:
    return ", ".join(str(d) for d in data)


def _examples(data: tuple[Path, ...], modality: str, facts: str | None, cache: Path | None = None,
              warn: set[str] | None = None, depth: dict | None = None):
    """The examples of a data set or of folders of labelled real frames (lv3d.examples.read_examples, with the
    depth settings ``depth``), each warning of reading them one line (an example's only where ``warn`` holds its
    id, where given)."""
    from ..examples import read_examples

    ex = read_examples(list(data), modality, facts=facts or "pipeline", cache=cache, depth=depth)
    for w in ex.warnings:
        if warn is None or w.example is None or w.example in warn:
            click.echo(f"lv3d: warning: {w}", err=True)
    return ex


_data = click.option("--data", type=click.Path(path_type=Path), required=True, multiple=True,
                     help="a rendered data set (manifest.json) or a folder of labelled real frames (objects.csv); "
                          "repeatable for several such folders, whose examples are read together")
_modality = click.option("--modality", type=click.Choice(MODALITIES), default="rgbd", show_default=True)
_facts = click.option("--facts", type=click.Choice(["truth", "pipeline"]), default=None,
                      help="facts from perception + grounding (pipeline, the default) or, on a rendered data set "
                           "only, from its ground truth (truth)")
_cache = click.option("--cache", type=click.Path(path_type=Path), default=None,
                      help="folder caching the facts of real frames (default $XDG_CACHE_HOME/lv3d or ~/.cache/lv3d)")


@learn.command()
@_data
@_modality
@_facts
@_cache
@depth_set_option
@click.option("--classes", default=None, help="comma-separated classes to learn (default: every class in the data "
                                               "but other, objects.csv's catch-all shape)")
@click.option("--out", type=click.Path(path_type=Path), required=True, help="directory for the programs")
@click.option("--seed", type=click.IntRange(0, 2 ** 32 - 1), default=0, show_default=True)
@click.option("--time-limit", type=click.FloatRange(0, 86400, min_open=True), default=None, help="seconds per class")
def fit(data: tuple[Path, ...], modality: str, facts: str | None, cache: Path | None, depth_set: tuple[str, ...],
        classes: str | None, out: Path, seed: int, time_limit: float | None):
    """Learn one program per class and save them as .pl files in OUT (with the depth settings the facts were
    made with, depth_settings.json). Examples where perception found no object are left out (counted)."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    from ..experiment.config import OTHER_SHAPE
    from ..learn.model import Model
    from ..output import check_out, replacing

    check_out(out, data)  # before any work: a file, a folder lv3d did not write or one holding the data
    depth = depth_overrides(depth_set)
    wanted = [c.strip() for c in classes.split(",") if c.strip()] if classes is not None else None
    if wanted is not None and not wanted:
        raise InputError("--classes", "no class given")
    ex = _examples(data, modality, facts, cache, depth=depth)
    for c in wanted or ():
        if c not in ex.labels:
            raise InputError("--classes", f"no example of {_named(data)} is a {c!r}; its classes: {', '.join(sorted(set(ex.labels)))}")
    left_out = ex.without_object
    learnable = ex.learnable()
    scenes, labels = learnable.scenes, learnable.labels
    if left_out:
        click.echo(f"% {left_out} example(s) left out: perception found no object there", err=True)
    if not scenes:
        raise click.ClickException(f"{_named(data)}: perception found no object in any example; nothing to learn from")
    present = set(labels)
    lost = [c for c in (wanted or []) if c not in present]
    if lost:
        raise click.ClickException(f"perception found no object in any example of {', '.join(lost)}")
    if wanted is None and OTHER_SHAPE in present and len(present) > 1:
        wanted = sorted(present - {OTHER_SHAPE})  # its examples stay, as negatives of every class
    settings = {"time_limit": time_limit} if time_limit is not None else None
    model = Model.fit(scenes, labels, settings=settings, seed=seed, classes=wanted)
    if not model.programs and model.failures:  # nothing learned: no empty model is saved
        why = "; ".join(f"{c}: {w}" for c, w in model.failures.items())
        raise click.ClickException(f"no program learned for any class ({why})")
    with replacing(out, data) as tmp:  # written beside OUT, then moved into its place
        model.save(tmp)
        if facts != "truth":
            save_with_model(tmp, depth)
    click.echo(f"% learned from {len(scenes)} examples ({', '.join(f'{c} {labels.count(c)}' for c in sorted(present))})")
    for c, p in model.programs.items():
        if p.target != c:
            click.echo(f"% {c}: learned as {p.target}, since {c} names a body predicate")
        click.echo(f"% {c}: covers {p.score['tp']}/{p.score['n_pos']} positives, "
                   f"{p.score['fp']}/{p.score['n_neg']} negatives\n{p}\n")
    for (c, r), p in model.arbiters.items():
        click.echo(f"% {c} rather than {r} (where both programs prove an object): covers {p.score['tp']}/"
                   f"{p.score['n_pos']} of the {c} examples, {p.score['fp']}/{p.score['n_neg']} of the {r} ones\n{p}\n")
    for c, why in model.failures.items():
        click.echo(f"no program for {c}: {why}", err=True)


def load_model(model_dir: Path):
    """(the model saved in ``model_dir``, the modalities its programs were learned from, sorted); an InputError
    naming the folder where it holds no program."""
    from ..learn.model import Model

    model = Model.load(model_dir)
    if not model.programs:
        raise InputError(model_dir, "the model holds no program")
    return model, sorted({p.modality for p in model.programs.values() if p.modality})


def _model_and_scenes(data: tuple[Path, ...], modality: str, facts: str | None, cache: Path | None, model_dir: Path,
                      depth_set: tuple[str, ...] = (), warn: set[str] | None = None):
    """The model of ``model_dir`` and the scenes of ``data`` (:func:`_examples`, its ``warn``, with the depth
    settings of ``depth_set``). Depth settings other than those the model's facts were made with are one note
    line, not an error: frames of another sensor are read with that sensor's settings."""
    model, learned = load_model(model_dir)
    if learned and learned != [modality]:
        raise InputError("--modality", f"the model in {model_dir} was learned from {', '.join(learned)} facts; "
                                       f"predict with --modality {learned[0]}")
    depth = depth_overrides(depth_set)
    fitted = model_depth(model_dir)
    if fitted is not None and facts != "truth" and fitted != depth:
        click.echo(f"lv3d: note: the model in {model_dir} learned from facts made with the depth settings "
                   f"{shown(fitted)}; these examples' are made with {shown(depth)}", err=True)
    ex = _examples(data, modality, facts, cache, warn, depth)
    scenes, labels = ex.scenes, ex.labels
    return model, scenes, labels


@learn.command()
@_data
@_modality
@_facts
@_cache
@depth_set_option
@click.option("--model", "model_dir", type=click.Path(path_type=Path), required=True)
@click.option("--explain/--no-explain", default=False, help="print each answer's proof")
def predict(data: tuple[Path, ...], modality: str, facts: str | None, cache: Path | None, depth_set: tuple[str, ...],
            model_dir: Path, explain: bool):
    """Classify every example of a data set or folder with saved programs; print accuracy, over the examples of
    the classes the model holds a program for, each class's, and their mean (balanced accuracy). An example where perception found no object
    is answered "unknown" (and counts as wrong); examples of other classes are answered but left out of the
    accuracy (the model cannot name them), and counted."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    model, scenes, labels = _model_and_scenes(data, modality, facts, cache, model_dir, depth_set)
    held = set(model.programs)
    right: Counter = Counter()
    seen: Counter = Counter()
    for s, y in zip(scenes, labels):
        if s.target is None:
            label, conf = "unknown", 0.0
            click.echo(f"{s.scene}\t{y}\t{label}\t{conf:.3f}")
        elif explain:
            e = model.explain(s)
            label, conf = e.label, e.confidence
            click.echo(f"{s.scene} ({y}): {e}")
        else:
            label, conf = model.predict(s)
            click.echo(f"{s.scene}\t{y}\t{label}\t{conf:.3f}")
        seen[y] += 1
        right[y] += label == y
    others = {y: n for y, n in sorted(seen.items()) if y not in held}
    n = sum(seen[y] for y in held)
    if others:
        click.echo("left out of the accuracy, of classes the model holds no program for: " +
                   ", ".join(f"{y} {k}" for y, k in others.items()) + f" (its classes: {', '.join(sorted(held))})")
    click.echo("per class: " + ", ".join(f"{y} {right[y]}/{seen[y]}" for y in sorted(held) if seen[y]))
    correct = sum(right[y] for y in held)
    tested = [y for y in held if seen[y]]
    balanced = sum(right[y] / seen[y] for y in tested) / len(tested) if tested else 0.0
    click.echo(f"accuracy {correct}/{n} = {correct / n:.3f}, balanced {balanced:.3f} (the mean of each class's share "
               f"right)" if n else
               "accuracy: none of the examples is of a class the model holds a program for")


@learn.command()
@_data
@_modality
@_facts
@_cache
@depth_set_option
@click.option("--model", "model_dir", type=click.Path(path_type=Path), required=True)
@click.option("--example", "examples", multiple=True, metavar="ID",
              help="explain this example only (an id predict prints, or FRAME_xOBJECT with the frame's file "
                   "name; repeatable; default: every example)")
def explain(data: tuple[Path, ...], modality: str, facts: str | None, cache: Path | None, depth_set: tuple[str, ...],
            model_dir: Path, examples: tuple[str, ...]):
    """Print why each example gets its label: the program that proves it and the facts (with confidences)
    the proof used."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    examples = tuple(_example_atom(e) for e in examples)
    # the examples asked for: only their own "no object" warnings (each is answered so below as well)
    model, scenes, labels = _model_and_scenes(data, modality, facts, cache, model_dir, depth_set,
                                              set(examples) or None)
    by_id = {s.scene: (s, y) for s, y in zip(scenes, labels)}
    unknown = [e for e in examples if e not in by_id]
    if unknown:
        raise InputError("--example", f"no example {unknown[0]!r} in {_named(data)}; e.g. {', '.join(list(by_id)[:5])}")
    for i in examples or list(by_id):
        s, y = by_id[i]
        if s.target is None:
            click.echo(f"{i} ({y}): unknown: perception found no object under its labelled pixel")
            continue
        click.echo(f"{i} ({y}): {model.explain(s)}")


def _example_atom(example: str) -> str:
    """The id of an example named by its frame's file name and its object (``My Frame-001_x2``): the frame part as
    the atom lv3d names the frame by (frame_folder.scene_atom); an id predict prints is kept as it is."""
    from ..frame_folder import scene_atom
    from ..object_facts import example_id

    frame, sep, obj = example.rpartition("_x")
    return example_id(scene_atom(frame), obj) if sep and frame and obj.isdigit() else example
