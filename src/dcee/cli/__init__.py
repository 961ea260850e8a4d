"""The ``dcee`` command line: one module per command group, the shared options in
:mod:`dcee.cli.options`, the printing and exit codes in :mod:`dcee.console`.

Every user mistake (bad option, bad scenario value, unknown name, missing file) ends in one line
on stderr, ``dcee: error: <field>: <what is allowed>``, and exit code 2; result files are written
atomically (temporary name, then rename), so an interrupted run leaves no half-written file.
"""

from __future__ import annotations

import click

from dcee.cli.bench import bench, report
from dcee.cli.catalogue import scenarios, schema, show, strategies
from dcee.cli.checkpoint import checkpoint
from dcee.cli.perf import perf
from dcee.cli.plume import plume
from dcee.cli.replay import replay
from dcee.cli.run import run
from dcee.console import run_command


@click.group(context_settings={"help_option_names": ["-h", "--help"]}, invoke_without_command=True)
@click.version_option(package_name="dcee")
@click.pass_context
def cli(ctx: click.Context) -> None:
    """Autonomous search for the source of an airborne release (DCEE and peers)."""
    if ctx.invoked_subcommand is None:
        click.echo(ctx.get_help())


for _command in (
    run,
    replay,
    checkpoint,
    scenarios,
    strategies,
    show,
    schema,
    perf,
    bench,
    report,
    plume,
):
    cli.add_command(_command)


def main(argv: list[str] | None = None) -> None:
    """Entry point: user errors → one line on stderr and exit 2."""
    run_command(cli, "dcee", argv)


__all__ = ["cli", "main"]
