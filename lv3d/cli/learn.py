"""``lv3d mil TASK.pl`` (classic MIL tasks) and ``lv3d learn fit|predict`` (shape concepts from a
rendered data set, docs/dataset.md)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from ..errors import InputError, read_json
from ..facts import MODALITIES


@click.command()
@click.argument("task", type=click.Path(path_type=Path))
@click.option("--time-limit", type=float, default=None, help="seconds for the search (default: the task's, else 10)")
def mil(task: Path, time_limit: float | None):
    """Learn the Metagol-style TASK file and print the program."""
    from ..learn.engine import LearnError
    from ..learn.task import learn_task

    try:
        clauses = learn_task(task, time_limit=time_limit)
    except LearnError as e:
        raise InputError(task, str(e).split(": ", 1)[-1]) from None
    click.echo("\n".join(clauses))


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
    except (json.JSONDecodeError, KeyError, TypeError) as e:
        raise InputError(manifest, f"malformed: {e}") from None
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
@click.option("--seed", type=int, default=0, show_default=True)
@click.option("--time-limit", type=float, default=None, help="seconds per class")
def fit(data: Path, modality: str, facts: str, classes: str | None, out: Path, seed: int, time_limit: float | None):
    """Learn one program per class and save them as .pl files in OUT."""
    from ..output import check_out, replacing
    from ..learn.model import Model

    check_out(out, (data,))  # before any work: a file, a folder lv3d did not write or one holding the data
    wanted = [c.strip() for c in classes.split(",")] if classes else None
    scenes, labels = _dataset_scenes(data, modality, facts)
    settings = {"time_limit": time_limit} if time_limit else None
    model = Model.fit(scenes, labels, settings=settings, seed=seed, classes=wanted)
    with replacing(out, (data,)) as tmp:  # written beside OUT, then moved into its place
        model.save(tmp)
    for c, p in model.programs.items():
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

