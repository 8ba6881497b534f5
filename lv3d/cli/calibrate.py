"""``lv3d calibrate``: make the confidence calibration maps lv3d ships (lv3d.calibrate; docs/grounding.md)."""

from __future__ import annotations

import shlex
from pathlib import Path

import click

from .. import compile_cache


def _say(text: str) -> None:
    click.echo(text)


def command_line(ctx: click.Context) -> str:
    """The command being run, written out from its parsed parameters (arguments in order, then every option
    with a value, defaults too, so that the line stays exact when a default changes): what a pickle's
    ``made_by`` and the fit's provenance record."""
    words = ctx.command_path.split()
    for p in ctx.command.params:
        value = ctx.params.get(p.name)
        if isinstance(p, click.Argument):
            words += [str(v) for v in (value if p.nargs != 1 else [value])]
        elif p.is_flag:
            words += [p.opts[0]] if value else []
        elif p.multiple:
            for v in value or ():
                words += [p.opts[0], str(v)]
        elif value is not None:
            words += [p.opts[0], str(value)]
    return " ".join(shlex.quote(w) for w in words)


def _modalities(text: str) -> tuple[str, ...]:
    return tuple(dict.fromkeys(m.strip() for m in text.split(",") if m.strip()))


@click.group()
def calibrate():
    """Fit the calibration maps of fact confidences (lv3d/data/calibration.json) on candidate facts of rendered
    dev scenes (rows) and of labelled real frames (real); check them (check). The whole recipe:
    lv3d.calibrate.fit's docstring, docs/grounding.md."""


@calibrate.command()
@click.option("--seed", type=click.IntRange(1, 2 ** 31 - 1), default=30000, show_default=True,
              help="dev seed of the first scene (never the study's 0); scene i of class c: seed + 1000 c + i")
@click.option("--per-class", type=click.IntRange(1, 100000), default=20, show_default=True)
@click.option("--preset", default="realsense", show_default=True, help="noise preset (docs/dataset.md)")
@click.option("--modalities", default="rgbd,depth,rgb", show_default=True, help="among rgbd, depth, rgb")
@click.option("--out", type=click.Path(path_type=Path), required=True,
              help="the pickle of rows: made, or resumed where a run of this command left it")
@click.option("--fresh", is_flag=True, help="start --out over instead of resuming it")
@click.pass_context
def rows(ctx, seed, per_class, preset, modalities, out, fresh):
    """Candidate facts of perceived rendered dev scenes with their truth and measurements (lv3d.calibrate.rows)."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    from ..calibrate.rows import make

    make(out, seed, per_class, preset, _modalities(modalities), fresh, command_line(ctx), log=_say)


@calibrate.command()
@click.argument("folders", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--modalities", default="depth,rgbd", show_default=True, help="among depth, rgbd")
@click.option("--limit", type=click.IntRange(1, None), default=None, metavar="N",
              help="only the first N frames of each folder")
@click.option("--seed", "seeds", default="0", show_default=True, metavar="S[,S...]",
              help="perception's seeds: every frame is perceived once per seed (0,1,2: rows of three draws of its "
                   "sample consensus, so that the maps do not fit one draw)")
@click.option("--out", type=click.Path(path_type=Path), required=True, help="the pickle of real rows to write")
@click.pass_context
def real(ctx, folders, modalities, limit, seeds, out):
    """Labelled perpendicular candidates of FOLDERS of real frames (the real layout, docs/real_frames.md)
    (lv3d.calibrate.real)."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    from ..calibrate.real import make, seed_list

    make(list(folders), out, _modalities(modalities), limit, command_line(ctx), log=_say, seeds=seed_list(seeds))


@calibrate.command()
@click.argument("data", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--real", "real_", multiple=True, type=click.Path(path_type=Path), metavar="PKL",
              help="a pickle of lv3d calibrate real (repeat for several)")
@click.option("--check", multiple=True, type=click.Path(path_type=Path), metavar="PKL",
              help="a pickle of lv3d calibrate rows to report ECE on (repeat for several)")
@click.option("--holdout", is_flag=True,
              help="first check on real frames left out of the fit: each --real pickle in turn, then the real "
                   "frames in frame-grouped folds")
@click.option("--real-share", type=float, default=0.5, show_default=True,
              help="share of a key's fit weight its real rows carry")
@click.option("--out", type=click.Path(path_type=Path), default=None,
              help="the calibration file to write (default: the shipped lv3d/data/calibration.json)")
@click.option("--dry-run", is_flag=True, help="fit and report, write nothing")
@click.option("--modalities", default="rgbd,depth", show_default=True, help="among rgbd, depth")
@click.pass_context
def fit(ctx, data, real_, check, holdout, real_share, out, dry_run, modalities):
    """Fit the maps on DATA (pickles of lv3d calibrate rows) and the --real pickles, print the checks and write
    the calibration file with its provenance (lv3d.calibrate.fit)."""
    from ..calibrate.fit import run

    run(list(data), list(real_), list(check), holdout, real_share, out, dry_run, _modalities(modalities),
        command_line(ctx))


@calibrate.command()
@click.argument("rows", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--modality", type=click.Choice(["rgbd", "depth"]), default="rgbd", show_default=True)
@click.option("--draws", type=click.IntRange(1, None), default=300, show_default=True,
              help="scene-bootstrap draws for each interval")
def check(rows, modality, draws):
    """Per-type ECE of the shipped maps on ROWS (pickles of lv3d calibrate rows), each set alone and pooled
    (lv3d.calibrate.check)."""
    from ..calibrate.check import run

    run(list(rows), modality, draws)
