"""``lv3d dataset``: make a synthetic data set, or draw a contact sheet of one."""

from __future__ import annotations

from pathlib import Path

import click


@click.group()
def dataset():
    """Synthetic RGB-D data sets of solids on a table (docs/dataset.md)."""


@dataset.command()
@click.option("--classes", required=True, help="comma-separated classes, e.g. cube,square_pyramid")
@click.option("--per-class", type=int, required=True, help="images per class")
@click.option("--noise", default="clean", show_default=True,
              help="noise preset: clean, mild, realsense, hard, realistic, kinect (docs/dataset.md)")
@click.option("--seed", type=int, default=0, show_default=True)
@click.option("--out", type=click.Path(path_type=Path), required=True, help="data set folder to create")
@click.option("--workers", type=int, default=None, help="processes (default: all cores)")
@click.option("--width", type=int, default=640, show_default=True)
@click.option("--height", type=int, default=480, show_default=True)
def make(classes, per_class, noise, seed, out, workers, width, height):
    """Render PER_CLASS images of each class into OUT (resumes: an identical finished set is kept)."""
    from ..render.dataset import make_dataset

    path = make_dataset(out, classes, per_class, noise, seed, workers=workers, width=width, height=height)
    click.echo(str(path))


@dataset.command()
@click.argument("folder", type=click.Path(path_type=Path))
@click.option("--out", type=click.Path(path_type=Path), default=None, help="PNG to write (default FOLDER/sheet.png)")
@click.option("--max-items", type=int, default=48, show_default=True)
def show(folder, out, max_items):
    """Write a contact sheet (colour + depth thumbnails, labelled) of the data set in FOLDER."""
    from ..render.contact import dataset_sheet

    click.echo(str(dataset_sheet(folder, out or Path(folder) / "sheet.png", max_items=max_items)))
