"""``lv3d dataset``: make a synthetic data set, or draw a contact sheet of one."""

from __future__ import annotations

from pathlib import Path

import click

from ..limits import MAX_DATASET_IMAGES


@click.group()
def dataset():
    """Synthetic RGB-D data sets of solids on a table (docs/dataset.md)."""


@dataset.command()
@click.option("--classes", required=True, help="comma-separated classes, e.g. cube,square_pyramid")
@click.option("--per-class", type=click.IntRange(1, MAX_DATASET_IMAGES), required=True,
              help=f"images per class (a data set holds at most {MAX_DATASET_IMAGES} images)")
@click.option("--noise", default="clean", show_default=True,
              help="noise preset: clean, mild, realsense, hard, realistic, kinect (docs/dataset.md)")
@click.option("--seed", type=click.IntRange(0, 2 ** 63 - 1), default=0, show_default=True)
@click.option("--out", type=click.Path(path_type=Path), required=True, help="data set folder to create")
@click.option("--workers", type=click.IntRange(1, 256), default=None, help="processes (default: all cores)")
@click.option("--width", type=click.IntRange(8, 16384), default=640, show_default=True,
              help="pixels; width x height at most 2048x2048 (lv3d.limits)")
@click.option("--height", type=click.IntRange(8, 16384), default=480, show_default=True)
@click.option("--executor", type=click.Choice(["local", "dask"]), default="local", show_default=True,
              help="where the images are rendered: this machine's processes, or a Dask cluster")
@click.option("--address", default=None, metavar="tcp://HOST:PORT",
              help="the Dask scheduler (with --executor dask; without it, a local cluster of --workers processes); "
                   "its workers must see OUT's folder at the same path")
def make(classes, per_class, noise, seed, out, workers, width, height, executor, address):
    """Render PER_CLASS images of each class into OUT (resumes: an identical finished set is kept). The files
    are the same, byte for byte, whatever --workers and --executor."""
    from ..errors import InputError
    from ..limits import check_pixels
    from ..output import clean_stale, lock_beside
    from ..render.dataset import make_dataset
    from ..render.noise import noise_config
    from ..render.solids import CLASSES

    check_pixels(width, height, "--width/--height", "a data set image")
    names = [c.strip() for c in classes.split(",") if c.strip()]
    for c in names:
        if c not in CLASSES:
            raise InputError("--classes", f"unknown class {c!r}; known: {', '.join(CLASSES)}")
    if not names:
        raise InputError("--classes", f"no classes given; known: {', '.join(CLASSES)}")
    if per_class * len(names) > MAX_DATASET_IMAGES:
        raise InputError("--per-class", f"{per_class} images of {len(names)} classes exceed the {MAX_DATASET_IMAGES} "
                                        "images a data set may hold (lv3d.limits)")
    noise_config(noise)  # an unknown preset: one line, before any work
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}", "exists and is not a folder")
    lock = lock_beside(out, f"--out {out}")  # a second make into this folder stops here
    try:
        clean_stale(out.parent, out.name)  # what a killed make left beside it
        if executor == "dask" or address:
            from ..experiment.executor import make_executor

            ex = make_executor(executor, workers or 1, address)
            try:
                path = make_dataset(out, names, per_class, noise, seed, width=width, height=height, executor=ex)
            finally:
                ex.close()
        else:
            path = make_dataset(out, names, per_class, noise, seed, workers=workers, width=width, height=height)
    finally:
        lock.release()
    click.echo(str(path))


@dataset.command()
@click.argument("folder", type=click.Path(path_type=Path))
@click.option("--out", type=click.Path(path_type=Path), default=None, help="PNG to write (default FOLDER/sheet.png)")
@click.option("--max-items", type=click.IntRange(1, 1000), default=48, show_default=True)
def show(folder, out, max_items):
    """Write a contact sheet (colour + depth thumbnails, labelled) of the data set in FOLDER."""
    from ..render.contact import dataset_sheet

    _check_manifest(Path(folder))
    if out is not None and Path(out).is_dir():
        from ..errors import InputError

        raise InputError(f"--out {out}", "is a folder; give the PNG file to write")
    click.echo(str(dataset_sheet(folder, out or Path(folder) / "sheet.png", max_items=max_items)))


def _check_manifest(folder: Path) -> None:
    """FOLDER is a data set whose manifest lists its items ({id, class, dir} each), or a one-line error."""
    from ..errors import InputError, read_json

    if not folder.is_dir():
        raise InputError(folder, "not a data set (no such folder)")
    manifest = folder / "manifest.json"
    if not manifest.is_file():
        raise InputError(folder, "not a data set (no manifest.json)")
    m = read_json(manifest, "manifest.json")
    items = m.get("items") if isinstance(m, dict) else None
    if not isinstance(items, list) or not items:
        raise InputError(manifest, "items: must be a non-empty list of {id, class, dir}")
    for i, it in enumerate(items):
        if not (isinstance(it, dict) and all(isinstance(it.get(k), str) and it.get(k) for k in ("id", "class", "dir"))):
            raise InputError(manifest, f"items[{i}]: must be {{id, class, dir}} (texts), got {it!r}")
        d = Path(it["dir"])
        if d.is_absolute() or ".." in d.parts:
            raise InputError(manifest, f"items[{i}].dir: must be a folder inside the data set, got {it['dir']!r}")
