"""``lv3d demo --out DIR``: the whole story in a few minutes on two cores.

Renders a small data set (4 classes x 8 images, mild noise), learns the four classes from a few
images each with lv3d (rgb, depth and rgbd facts) and, on the same images, a small CNN and a
decision tree; prints the learned programs, an accuracy table on the held-out images and the
explanation of one test answer; writes perception overlays, the programs, a plot and
``results.json`` into DIR. Built from the experiment runner's parts (one split instead of folds).

Then, where a folder of labelled real frames is at hand (``--real``, by default ../shared/data/real/osd-learn
beside the checkout), it learns box and cylinder from 4 labelled objects each in some of its frames and shows
a frame it did not learn from: what perception found there (an overlay) and the proof for one real object.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import click
import numpy as np

from .. import compile_cache
from ..experiment.config import LOGIC_SYSTEMS, SYSTEMS, StudyConfig, from_dict
from ..experiment.folds import Item

CLASSES = ["cube", "square_pyramid", "triangular_prism", "pentagonal_prism"]


def demo_config(per_class: int, noise: str, seed: int, systems: list[str], threads: int) -> StudyConfig:
    """The demo's study config (one split, not folds), checked like a study's."""
    return from_dict({"name": "demo", "seed": seed, "folds": 2, "systems": systems,
                      "data": {"classes": list(CLASSES), "per_class": per_class, "noise": noise, "workers": 2},
                      "lv3d": {"workers": 2}, "baselines": {"epochs": 40, "batch_size": 8, "threads": threads}},
                     "demo options")


def demo_split(items: list[Item], train_per_class: int, seed: int) -> tuple[list[Item], list[Item]]:
    """The first ``train_per_class`` of each class after a seeded shuffle train; the rest test."""
    rng = np.random.default_rng(seed)
    train, test = [], []
    for cls in CLASSES:
        members = [it for it in items if it.cls == cls]
        order = rng.permutation(len(members))
        train += [members[i] for i in order[:train_per_class]]
        test += [members[i] for i in order[train_per_class:]]
    return train, test


def write_overlays(data: Path, items: list[Item], folder: Path) -> None:
    """Perception's rgbd result drawn over each test image."""
    import cv2

    from ..perception import perceive
    from ..perception.overlay import draw_overlay
    from ..rgbd import load_item

    folder.mkdir(parents=True, exist_ok=True)
    for it in items:
        frame = load_item(data / it.dir)
        try:
            img = draw_overlay(frame.color, perceive(frame, "rgbd", scene_id=it.id))
        except Exception as e:  # an overlay is an illustration: report it, keep the demo going
            click.echo(f"  overlay of {it.id} failed: {e}", err=True)
            continue
        cv2.imwrite(str(folder / f"{it.id}_{it.cls}.png"), cv2.cvtColor(img, cv2.COLOR_RGB2BGR))


def plot_accuracy(acc: dict[str, float], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.5))
    names = list(acc)
    ax.bar(names, [100 * acc[n] for n in names],
           color=["tab:blue" if n in LOGIC_SYSTEMS else "tab:gray" for n in names])
    ax.set_ylabel("test accuracy (%)")
    ax.set_ylim(0, 105)
    ax.set_title("lv3d demo: 4 classes, multi-class accuracy on held-out images")
    plt.setp(ax.get_xticklabels(), rotation=20)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@click.command()
@click.option("--out", "out", required=True, type=click.Path(path_type=Path), help="output folder")
@click.option("--per-class", default=8, show_default=True, type=click.IntRange(2, 1000),
              help="images rendered per class")
@click.option("--train", "train_per_class", default=4, show_default=True, type=click.IntRange(1, 999),
              help="training images per class")
@click.option("--noise", default="mild", show_default=True, help="noise preset of the renderer")
@click.option("--seed", default=0, show_default=True, type=click.IntRange(0, 2 ** 32 - 1))
@click.option("--systems", default="lv3d-rgb,lv3d-depth,lv3d-rgbd,cnn-rgbd,tree-rgbd", show_default=True,
              help="comma-separated systems to compare")
@click.option("--threads", default=1, show_default=True, type=click.IntRange(1, 256), help="CPU threads for the CNN")
@click.option("--real", "real", type=click.Path(path_type=Path), default=None,
              help="a folder of labelled real frames for the last step (default: ../shared/data/real/osd-learn beside "
                   "the checkout, when there)")
@click.option("--no-real", is_flag=True, help="skip the real-frame step")
def demo(out: Path, per_class: int, train_per_class: int, noise: str, seed: int, systems: str, threads: int,
         real: Path | None, no_real: bool):
    """Learn four shape classes from a few RGB-D images and explain an answer."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    from ..errors import InputError
    from ..experiment import data as data_mod
    from ..experiment.systems import make_system

    names = [s.strip() for s in systems.split(",") if s.strip()]
    for s in names:
        if s not in SYSTEMS:
            raise InputError("--systems", f"unknown system {s!r}; known: {', '.join(SYSTEMS)}")
    if not 1 <= train_per_class < per_class:
        raise InputError("--train", f"need 1 <= train < per-class ({per_class}), got {train_per_class}")
    t_start = time.perf_counter()
    cfg = demo_config(per_class, noise, seed, names, threads)
    from ..output import claim, lock_folder

    target = claim(out)  # a new, empty or lv3d-written folder, filled in place (a rerun reuses its data and facts)
    lock = lock_folder(target, f"--out {out}")  # one run at a time in this folder, until this one ends
    click.echo(f"1. rendering {per_class} images of each of {', '.join(CLASSES)} ({noise} noise)")
    data = data_mod.ensure_dataset(cfg, out)
    items = data_mod.read_items(data)
    train, test = demo_split(items, train_per_class, seed)
    click.echo(f"   {len(train)} training images, {len(test)} test images")

    acc, fitted = {}, {}
    for name in names:
        t0 = time.perf_counter()
        if name in LOGIC_SYSTEMS:
            m = name.split("-")[1]
            click.echo(f"2. {name}: perception + grounding -> facts, then learning")
            inputs, errors = data_mod.ensure_facts(cfg, out, data, items, m, refine=True, workers=2)
            if errors:
                click.echo(f"   {len(errors)} image(s) gave no object: {', '.join(sorted(errors))}")
        else:
            click.echo(f"3. {name}: training on the same {len(train)} images")
            inputs = data_mod.ensure_pixels(data, items, cfg.baselines.image_size)
        system = make_system(name, cfg, inputs)
        fit = system.fit([it.id for it in train], [it.cls for it in train], seed)
        preds = fit.predict([it.id for it in test])
        acc[name] = float(np.mean([label == it.cls for (label, _), it in zip(preds, test)]))
        fitted[name] = (fit, preds)
        if name in LOGIC_SYSTEMS:
            fit.save(out / "programs" / name)
        click.echo(f"   {name}: {100 * acc[name]:.0f} % on {len(test)} test images ({time.perf_counter() - t0:.0f} s)")

    for name in names:
        if name in LOGIC_SYSTEMS:
            click.echo(f"\nLearned programs ({name}, {out / 'programs' / name}):")
            for pl in sorted((out / "programs" / name).rglob("*.pl")):
                click.echo(f"% --- {pl.relative_to(out)}")
                click.echo(pl.read_text().rstrip())

    click.echo("\nAccuracy on the held-out images (multi-class):")
    click.echo("| system | accuracy | correct |\n|---|---|---|")
    for name in names:
        click.echo(f"| {name} | {100 * acc[name]:.0f} % | {round(acc[name] * len(test))}/{len(test)} |")

    best = next((n for n in ("lv3d-rgbd", "lv3d-depth", "lv3d-rgb") if n in fitted), None)
    if best:
        fit, preds = fitted[best]
        # the first test scene in which perception found an object (else there is nothing to explain)
        j = next((j for j, it in enumerate(test) if fit.facts[it.id].target is not None), 0)
        it, (label, conf) = test[j], preds[j]
        click.echo(f"\nWhy {best} says {it.id} (truly a {it.cls}) is a {label} (confidence {conf:.2f}):")
        click.echo(str(fit.explain(it.id)))

    click.echo("\n4. overlays of what perception found (rgbd)")
    write_overlays(data, test, out / "overlays")
    plot_accuracy(acc, out / "accuracy.png")
    real_result = None
    folder = None if no_real else (real if real is not None else _default_real())
    if folder is not None:
        click.echo(f"\n5. a real frame ({folder})")
        real_result = real_step(folder, out, seed)
    (out / "results.json").write_text(json.dumps(
        {"classes": CLASSES, "train": [it.id for it in train], "test": [it.id for it in test], "accuracy": acc,
         "predictions": {n: [[it.id, str(l), float(c)] for it, (l, c) in zip(test, p)] for n, (_, p) in fitted.items()},
         "real": real_result, "seconds": round(time.perf_counter() - t_start, 1)}, indent=1))
    click.echo(f"\nWrote {out / 'results.json'}, {out / 'accuracy.png'}, {out / 'overlays'}/, {out / 'programs'}/ "
               f"in {time.perf_counter() - t_start:.0f} s")
    lock.release()


REAL_CLASSES = ("box", "cylinder")
REAL_TRAIN = 4  # labelled objects of each class to learn from


def _default_real() -> Path | None:
    """../shared/data/real/osd-learn beside the checkout holding lv3d, when it is there."""
    folder = Path(__file__).resolve().parents[3] / "shared" / "data" / "real" / "osd-learn"
    return folder if (folder / "objects.csv").is_file() else None


def real_step(folder: Path, out: Path, seed: int) -> dict:
    """Learn box and cylinder (lv3d-rgbd) from REAL_TRAIN labelled objects each of ``folder``'s frames, then show
    one frame none of them came from: perception's overlay and the proof for one of its labelled objects."""
    from dataclasses import replace

    import cv2

    from ..experiment.code_version import facts_version
    from ..experiment.folds import grouped_folds, multiclass_task
    from ..experiment.real_data import ensure_frame_facts, example_facts_of, real_data
    from ..experiment.systems import FittedLogic
    from ..learn import Model
    from ..perception import perceive
    from ..perception.overlay import draw_overlay

    rd = real_data([str(folder)], REAL_CLASSES)
    if len({it.cls for it in rd.items}) < 2:
        click.echo(f"   {folder} holds no labelled {' and no '.join(REAL_CLASSES)}: step skipped")
        return {"skipped": "no examples of both classes"}
    train_fold, test_fold = grouped_folds(rd.items, 2, seed)
    train = multiclass_task(train_fold, REAL_TRAIN, seed)
    # the test frame, of the other fold's frames: the first whose objects are neither partly hidden nor stacked
    # (objects.csv's partial and stacked) with both classes, else with a cylinder; else the first with both
    # classes, else any
    frames = sorted({it.group_key for it in test_fold})
    classes = {f: {it.cls for it in test_fold if it.group_key == f} for f in frames}
    plain = [f for f in frames if not any(o.partial or o.stacked for o in rd.labels[f])]
    test_frame = next(iter([f for f in plain if classes[f] >= set(REAL_CLASSES)]
                           or [f for f in plain if REAL_CLASSES[1] in classes[f]]
                           or [f for f in frames if classes[f] >= set(REAL_CLASSES)] or frames))
    test = [it for it in test_fold if it.group_key == test_frame]
    keep = {it.group_key for it in train} | {test_frame}
    small = replace(rd, items=train + test, frames={a: v for a, v in rd.frames.items() if a in keep},
                    labels={a: v for a, v in rd.labels.items() if a in keep})
    ff = ensure_frame_facts(small, out / "real_facts", facts_version(), "rgbd", True)
    facts, errors = example_facts_of(small, ff)
    usable = [it for it in train if facts[it.id].target is not None]
    click.echo(f"   learning {', '.join(REAL_CLASSES)} (lv3d-rgbd) from {len(usable)} labelled objects of "
               f"{len({it.group_key for it in train})} frames")
    model = Model.fit([facts[it.id] for it in usable], [it.cls for it in usable], seed=seed)
    fit = FittedLogic(model, facts)
    fit.save(out / "programs" / "real")
    for pl in sorted((out / "programs" / "real").rglob("*.pl")):
        click.echo(pl.read_text().rstrip())
    fold_folder, name = rd.frames[test_frame]
    frame = fold_folder.load(name)
    scene = perceive(frame, "rgbd", scene_id=test_frame)
    (out / "overlays").mkdir(parents=True, exist_ok=True)
    overlay = out / "overlays" / f"real_{test_frame}.png"
    cv2.imwrite(str(overlay), cv2.cvtColor(draw_overlay(frame.color, scene), cv2.COLOR_RGB2BGR))
    click.echo(f"   frame {name}: perception found {len(scene.objects)} objects, "
               f"{sum(len(o.faces) for o in scene.objects)} faces ({overlay})")
    answers = {}
    for it, (label, conf) in zip(test, fit.predict([it.id for it in test])):
        answers[it.id] = [it.cls, label, conf]
        click.echo(f"   {it.id}: labelled {it.cls}, lv3d-rgbd says {label} ({conf:.2f})"
                   + (f" [{errors[it.id]}]" if it.id in errors else ""))
    shown = next((it for it in test if facts[it.id].target is not None), None)
    if shown is not None:
        click.echo(f"\nWhy lv3d-rgbd says the real object {shown.id} (labelled {shown.cls}) is "
                   f"{answers[shown.id][1]}:")
        click.echo(str(fit.explain(shown.id)))
    return {"folder": str(folder), "train": [it.id for it in train], "frame": name, "answers": answers,
            "overlay": str(overlay)}
