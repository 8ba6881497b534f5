"""``lv3d experiment run CONFIG --out DIR [--set key=value ...]``: run or resume one study;
``lv3d experiment report CONFIG --out DIR [--set ...]``: rewrite its report from the fold files there."""

from __future__ import annotations

from pathlib import Path

import click

from .. import compile_cache


@click.group()
def experiment():
    """Run the studies of experiments/*.yaml (seeded, resumable)."""


@experiment.command()
@click.argument("config", type=click.Path(path_type=Path))
@click.option("--out", "out", required=True, type=click.Path(path_type=Path), help="work directory of the run")
@click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
              help="override a config key, e.g. --set train.positives=8 --set systems=[lv3d-rgbd,cnn-rgbd]")
@click.option("--quiet", is_flag=True, help="no progress bars")
@click.option("--executor", type=click.Choice(["local", "dask"]), default="local", show_default=True,
              help="where the study's cells and facts run: processes of this machine, or a Dask cluster")
@click.option("--address", default=None, metavar="tcp://HOST:PORT",
              help="the Dask scheduler (with --executor dask; without it, a local cluster of --workers processes)")
@click.option("--workers", type=click.IntRange(1, 256), default=1, show_default=True,
              help="cells run at once (local processes, or the workers of a local Dask cluster)")
def run(config: Path, out: Path, overrides: tuple[str, ...], quiet: bool, executor: str, address: str | None,
        workers: int):
    """Run the study CONFIG into OUT; finished (fold, system) results are kept and skipped. The results are
    the same, bit for bit, whatever --executor and --workers."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    from ..experiment.config import load_study
    from ..experiment.executor import make_executor
    from ..experiment.runner import run_study
    from ..output import check_out

    load_study(config, list(overrides))  # every setting checked before any work
    check_out(out, (config,))
    ex = make_executor(executor, workers, address)
    try:
        res = run_study(config, out, list(overrides), progress=not quiet, executor=ex)
    finally:
        ex.close()
    click.echo(f"{res['ran']} fold results computed, {res['skipped']} reused; report: {out / 'results.md'}")
    if res["learn_failures"]:
        click.echo(f"lv3d: warning: in {res['learn_failures']} learn calls the learner found no program for a class; "
                   f"{out / 'results.md'} says which and why", err=True)
    click.echo((out / "results.md").read_text())


@experiment.command()
@click.argument("config", type=click.Path(path_type=Path))
@click.option("--out", "out", required=True, type=click.Path(path_type=Path), help="work directory of the study")
@click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE", help="override a config key, as for run")
def report(config: Path, out: Path, overrides: tuple[str, ...]):
    """Rewrite OUT's report (results.md, results.csv, results.json, plots) from the fold files OUT holds, for
    CONFIG with the overrides given; computes nothing. For a study whose systems ran in parts, e.g. a costly
    baseline at one size only: run each part, then report the whole."""
    from ..experiment.runner import report_study

    report_study(config, out, list(overrides))
    click.echo((out / "results.md").read_text())
