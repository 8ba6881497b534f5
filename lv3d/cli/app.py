"""The ``lv3d`` command: a group whose subcommands (the other modules of this package) are imported
lazily, so that ``lv3d dataset`` does not pay for importing JAX or torch."""

from __future__ import annotations

import importlib

import click

from ..errors import InputError

# command name -> "module:attribute" of a click command or group
COMMANDS = {
    "dataset": "lv3d.cli.dataset:dataset",
    "extract": "lv3d.cli.extract:extract",
    "label": "lv3d.cli.label:label",
    "mil": "lv3d.cli.learn:mil",
    "learn": "lv3d.cli.learn:learn",
    "experiment": "lv3d.cli.experiment:experiment",
    "demo": "lv3d.cli.demo:demo",
    "calibrate": "lv3d.cli.calibrate:calibrate",
}


class LazyGroup(click.Group):
    def list_commands(self, ctx):
        return sorted(COMMANDS)

    def get_command(self, ctx, name):
        if name not in COMMANDS:
            return None
        module, attr = COMMANDS[name].split(":")
        try:
            return getattr(importlib.import_module(module), attr)
        except (ImportError, AttributeError) as e:
            raise click.ClickException(f"command {name!r} is not available: {e}") from None


@click.group(cls=LazyGroup)
def cli():
    """lv3d: learn 3D shape concepts from a few RGB-D images, with an explanation for every answer."""


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def main(argv=None) -> int:
    """Entry point: bad input (a bad option, value, file or setting) becomes one line on stderr and exit code
    2; a run that cannot finish for another reason one line and exit code 1. Worker processes started from
    here die with this process (lv3d.workers)."""
    from ..workers import install

    install()
    try:
        rv = cli.main(args=argv, prog_name="lv3d", standalone_mode=False)
    except InputError as e:
        click.echo(f"lv3d: error: {_one_line(e)}", err=True)
        return 2
    except click.exceptions.Abort:
        click.echo("lv3d: aborted", err=True)
        return 130
    except click.UsageError as e:
        if type(e).__name__ == "NoArgsIsHelpError":  # a group without its subcommand: its help
            click.echo(e.ctx.get_help() if e.ctx is not None else str(e))
            return 0
        where = e.ctx.command_path if e.ctx is not None else "lv3d"
        click.echo(f"lv3d: error: {where}: {_one_line(e.format_message())} (see {where} --help)", err=True)
        return 2
    except click.ClickException as e:
        click.echo(f"lv3d: error: {_one_line(e.format_message())}", err=True)
        return e.exit_code
    except click.exceptions.Exit as e:
        return e.exit_code
    return rv if isinstance(rv, int) and not isinstance(rv, bool) else 0  # a command's exit status
