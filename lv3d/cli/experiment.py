"""``lv3d experiment run CONFIG --out DIR [--set key=value ...]``: run or resume one study."""

from __future__ import annotations

from pathlib import Path

import click


@click.group()
def experiment():
    """Run the studies of experiments/*.yaml (seeded, resumable)."""


@experiment.command()
@click.argument("config", type=click.Path(path_type=Path))
@click.option("--out", "out", required=True, type=click.Path(path_type=Path), help="work directory of the run")
@click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
              help="override a config key, e.g. --set train.positives=8 --set systems=[lv3d-rgbd,cnn-rgbd]")
@click.option("--quiet", is_flag=True, help="no progress bars")
def run(config: Path, out: Path, overrides: tuple[str, ...], quiet: bool):
    """Run the study CONFIG into OUT; finished (fold, system) results are kept and skipped."""
    from ..experiment.runner import run_study

    res = run_study(config, out, list(overrides), progress=not quiet)
    click.echo(f"{res['ran']} fold results computed, {res['skipped']} reused; report: {out / 'results.md'}")
    click.echo((out / "results.md").read_text())
