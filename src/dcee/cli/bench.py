"""``dcee bench`` (a resumable campaign of simulated searches) and ``dcee report`` (its tables,
tests, figures and HTML)."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from dcee.cli.options import (
    LIKELIHOOD_OPTION,
    SET_OPTION,
    TRUTH_OPTION,
    RegistryChoice,
    overrides,
    suite_names,
)
from dcee.console import climb_notice, clock, compile_notice
from dcee.io import check_writable_dir
from dcee.search_memory import check_search_memory

if TYPE_CHECKING:  # imported where used: `dcee --help` stays light
    from dcee.campaign.folder import Campaign


@click.command(short_help="Run a campaign of searches (resumable).")
@click.option(
    "--suite",
    default="paper",
    show_default=True,
    type=RegistryChoice(suite_names),
    help="Named set of configurations (docs/scenarios.md).",
)
@click.option(
    "--strategies",
    default="dcee,mpc,entrotaxis,infotaxis,dcee-ms",
    show_default=True,
    help="Comma-separated planner specs NAME[:KEY=VALUE]... (`dcee strategies` lists them).",
)
@click.option("--repeats", default=10, show_default=True, help="Repeats per configuration.")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False, path_type=Path),
    help="Campaign folder (created, or resumed if it holds this campaign).",
)
@click.option("--workers", type=int, help="Local worker processes [default: all cores].")
@click.option("--scheduler", help="Address of a running Dask scheduler, e.g. tcp://host:8786.")
@click.option("--unknown", type=click.Choice(["source", "full"]), help="Override unknown set.")
@click.option("--particles", type=int, help="Override the particle count.")
@click.option(
    "--agents",
    type=int,
    help="Robots searching together with one shared belief (override agent.count) [default: 1].",
)
@TRUTH_OPTION
@LIKELIHOOD_OPTION
@SET_OPTION
@click.option(
    "--allow-code-change",
    is_flag=True,
    help="Resume a campaign that other code started (every version used is recorded).",
)
@click.option(
    "--dry-run",
    is_flag=True,
    help="Check the campaign (suite, strategies, settings, memory, an existing --out folder) "
    "and print how many searches it would run, then stop: no search, no files.",
)
def bench(
    suite: str,
    strategies: str,
    repeats: int,
    out_dir: Path,
    workers: int | None,
    scheduler: str | None,
    unknown: str | None,
    particles: int | None,
    agents: int | None,
    truth: str | None,
    likelihood: str | None,
    settings: tuple[str, ...],
    allow_code_change: bool,
    dry_run: bool,
) -> None:
    """Run a campaign of simulated searches; resumes where a previous run stopped."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from dcee.campaign import Campaign, run_campaign
    from dcee.campaign.runner import check_workers
    from dcee.scenarios import truth_choice

    check_workers(workers, scheduler)
    names = tuple(s.strip() for s in strategies.split(",") if s.strip())
    changes = overrides(likelihood, settings)
    if agents is not None:
        changes["agent.count"] = agents
    campaign = Campaign(
        out_dir,
        suite,
        names,
        repeats,
        unknown,
        particles,
        truth_choice(truth) if truth is not None else None,
        changes,
        allow_code_change,
        open_truths=not dry_run,
    )
    if scheduler is None:  # a Dask cluster's memory is its workers' own
        scenarios = list(campaign.scenarios.values())
        check_search_memory(
            max(sc.search.particles for sc in scenarios),
            max(sc.estimator.max_sources for sc in scenarios),
            processes=workers or os.cpu_count() or 1,
        )
    if dry_run:
        check_writable_dir(out_dir, "out", create=False)
        _dry_run(campaign, scheduler)
        return
    check_writable_dir(out_dir, "out")
    compile_notice(False)
    climb_notice(list(campaign.scenarios.values()))
    failures: list[str] = []
    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("failed {task.fields[failed]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    )
    interactive = sys.stderr.isatty()
    started = time.monotonic()
    with Progress(*columns, disable=not interactive) as progress:
        bar = progress.add_task(suite, total=None, failed=0)

        def on_result(res: dict[str, Any], finished: int, todo: int) -> None:
            if res["status"] == "failed":
                t = res["task"]
                failures.append(f"{t.config} {t.strategy} seed {t.seed}: {res['error']}")
            progress.update(bar, total=todo, completed=finished, failed=len(failures))
            if not interactive:
                _log_progress(suite, finished, todo, len(failures), time.monotonic() - started)

        counts = run_campaign(campaign, workers=workers, scheduler=scheduler, on_result=on_result)
    click.echo(
        f"{counts['total']} searches: {counts['skipped']} already done, {counts['done']} run, "
        f"{counts['failed']} failed · results in {out_dir}"
    )
    for line in failures[:20]:
        click.echo(f"  failed: {line}", err=True)


def _dry_run(campaign: Campaign, scheduler: str | None) -> None:
    """What ``dcee bench --dry-run`` prints: the searches the campaign holds and how many of
    them an earlier run finished (its folder checked as a resume would check it, nothing
    written; a scheduler is not contacted)."""
    from dcee.campaign.folder import is_done

    campaign.prepare(write=False)
    tasks = campaign.tasks()
    # a new folder holds no finished search (spares 2,000 lookups of a 100-configuration suite)
    done = sum(is_done(t) for t in tasks) if (campaign.out_dir / "runs").is_dir() else 0
    where = f"on {scheduler}" if scheduler else "here"
    click.echo(
        f"would run {len(tasks) - done} of {len(tasks)} searches ({len(campaign.scenarios)} "
        f"configurations × {len(campaign.strategies)} strategies × {campaign.repeats} repeats; "
        f"{done} already done) {where}, into {campaign.out_dir}"
    )


def _log_progress(suite: str, finished: int, todo: int, failed: int, elapsed: float) -> None:
    """Plain progress lines for logs (stderr not a terminal, e.g. under nohup or a batch
    system): about twenty per campaign plus the last, each with completed/total, failures and
    an ETA from the mean rate so far."""
    if finished != todo and finished % max(1, todo // 20):
        return
    eta = elapsed / finished * (todo - finished)
    click.echo(
        f"{suite}: {finished}/{todo} searches, failed {failed}, "
        f"elapsed {clock(elapsed)}, ETA {clock(eta)}",
        err=True,
    )


@click.command(short_help="Tables, paired tests, figures and HTML.")
@click.argument("results_dir", type=click.Path(file_okay=False, path_type=Path))
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    help="Report folder [default: RESULTS_DIR/report].",
)
def report(results_dir: Path, out_dir: Path | None) -> None:
    """Tables (CSV, Markdown), paired tests, figures and a self-contained HTML report of a
    campaign or of any folder of `dcee run` results."""
    from dcee.analysis.report import write_report
    from dcee.analysis.results import incomplete_runs

    paths = write_report(results_dir, out_dir or results_dir / "report")
    for p in paths:
        click.echo(str(p))
    skipped = incomplete_runs(results_dir)
    if skipped:  # a report that silently drops searches would mislead its pairs and counts
        names = ", ".join(str(p) for p in skipped[:3]) + (", ..." if len(skipped) > 3 else "")
        click.echo(
            f"dcee: note: {len(skipped)} search folder(s) left out, not complete or not "
            f"readable: {names}",
            err=True,
        )
