"""The ``dcee`` command line.

Every user mistake (bad option, bad scenario value, unknown name, missing file) ends in one line
on stderr, ``dcee: error: <field>: <what is allowed>``, and exit code 2; result files are written
atomically (temporary name, then rename), so an interrupted run leaves no half-written file.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from dcee.errors import DceeInputError
from dcee.io import check_writable_dir, check_writable_file
from dcee.io import write_atomic as _write_atomic
from dcee.io import write_json as _write_json


class RegistryChoice(click.ParamType):
    """A choice among the names a registry holds, read when needed (not at import, so that
    ``dcee --help`` does not import the registries' heavy modules)."""

    name = "choice"

    def __init__(self, names: Callable[[], list[str]]) -> None:
        self.names = names

    def get_metavar(self, param: click.Parameter, ctx: click.Context | None = None) -> str:
        return "[" + "|".join(self.names()) + "]"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> str:
        allowed = self.names()
        if value not in allowed:
            self.fail(f"{value!r} is not one of {', '.join(allowed)}", param, ctx)
        return value


def _suite_names() -> list[str]:
    from dcee.campaign.suites import SUITES

    return list(SUITES)


def _likelihood_names() -> list[str]:
    from dcee.scenarios.config import LIKELIHOODS

    return list(LIKELIHOODS)


# Shared by ``run`` and ``bench``: what the sensor sees.
TRUTH_OPTION = click.option(
    "--truth",
    help="What the sensor sees: isotropic | filament | puffs | PATH of a recording "
    "[default: the scenario's truth.model].",
)
LIKELIHOOD_OPTION = click.option(
    "--likelihood",
    type=RegistryChoice(_likelihood_names),
    help="Reading model of the filter and planners: paper (eq. 3) | fluctuation (intermittent "
    "log-normal for turbulent plumes, with the paper's calm model beside it, the two selected "
    "online by the readings' evidence) [default: the scenario's estimator.likelihood].",
)
SET_OPTION = click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="PATH=VALUE",
    help="Override any scenario setting, e.g. --set sensor.average=0 --set estimator.log_sd=0.8 "
    "(repeatable; VALUE is TOML).",
)


def _overrides(likelihood: str | None, settings: tuple[str, ...]) -> dict[str, Any]:
    """The dotted scenario overrides of --likelihood and --set (checked before any work)."""
    from dcee.scenarios.config import parse_setting

    out: dict[str, Any] = dict(parse_setting(s) for s in settings)
    if likelihood:
        out["estimator.likelihood"] = likelihood
    return out


@click.group(context_settings={"help_option_names": ["-h", "--help"]}, invoke_without_command=True)
@click.version_option(package_name="dcee")
@click.pass_context
def cli(ctx: click.Context) -> None:
    """Autonomous search for the source of an airborne release (DCEE and peers)."""
    if ctx.invoked_subcommand is None:
        click.echo(ctx.get_help())


@cli.command()
@click.option(
    "--scenario",
    "scenario_name",
    required=True,
    help="Built-in name (see `dcee scenarios`) or path to a TOML file.",
)
@click.option(
    "--strategy",
    default="dcee",
    show_default=True,
    help="Planner NAME[:KEY=VALUE]..., e.g. dcee-cl:reach=6 (`dcee strategies` lists them).",
)
@click.option("--seed", default=0, show_default=True, type=int, help="Run seed.")
@click.option("--particles", type=int, help="Override search.particles.")
@click.option("--hypotheses", type=int, help="Override search.hypotheses (per candidate move).")
@click.option("--budget", type=float, help="Override search.budget (seconds of flight).")
@click.option("--unknown", type=click.Choice(["source", "full"]), help="Override unknown set.")
@click.option(
    "--agents",
    type=int,
    help="Robots searching together with one shared belief (override agent.count) [default: 1].",
)
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    help="Output folder [default: results/<scenario>_<strategy>_seed<seed>[_<settings>]]; "
    "refused if it holds a different search.",
)
@click.option(
    "--json",
    "json_file",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Also write the summary JSON here.",
)
@TRUTH_OPTION
@LIKELIHOOD_OPTION
@SET_OPTION
@click.option("--animate", is_flag=True, help="Also write animation.gif.")
@click.option("--no-figure", is_flag=True, help="Skip figure.png.")
@click.option("--quiet", "-q", is_flag=True, help="No progress display.")
def run(
    scenario_name: str,
    strategy: str,
    seed: int,
    particles: int | None,
    hypotheses: int | None,
    budget: float | None,
    unknown: str | None,
    agents: int | None,
    out_dir: Path | None,
    json_file: Path | None,
    truth: str | None,
    likelihood: str | None,
    settings: tuple[str, ...],
    animate: bool,
    no_figure: bool,
    quiet: bool,
) -> None:
    """Run one simulated search and write its record, summary, configuration and figure."""
    import numpy as np

    from dcee.allocator import tune_allocator
    from dcee.planning import get as get_planner
    from dcee.scenarios import load_scenario
    from dcee.scenarios.config import truth_choice
    from dcee.simulation import make_truth, run_episode
    from dcee.simulation.episode import snapshot_times

    if seed < 0:
        raise DceeInputError("seed", f"must be >= 0, got {seed}")
    get_planner(strategy)  # fail fast on an unknown name or a bad option
    if truth is not None:
        truth = truth_choice(truth)
    base = load_scenario(scenario_name)
    changes = {
        "search.particles": particles,
        "search.hypotheses": hypotheses,
        "search.budget": budget,
        "unknown": unknown,
        "truth.model": truth,
        "agent.count": agents,
        **_overrides(likelihood, settings),
    }
    scenario = base.with_overrides(**changes)
    if scenario.agent.count > 1:
        from dcee.planning import check_team_planner

        check_team_planner(get_planner(strategy))
    out_dir = out_dir or Path("results") / _default_run_folder(
        scenario, base, changes, strategy, seed
    )
    check_writable_dir(out_dir, "out")
    _check_same_run(out_dir, scenario, strategy, seed)
    if json_file is not None:
        check_writable_file(json_file, "json")
    truth_model = make_truth(scenario, seed)  # a bad recording fails here, before the search
    tune_allocator()  # this process is the command line's own (see dcee.allocator)
    _compile_notice(quiet)
    dense = np.linspace(0.0, scenario.search.budget, 41) if animate else ()
    result = _run_with_progress(
        lambda progress: run_episode(
            scenario,
            strategy,
            seed,
            truth=truth_model,
            progress=progress,
            snapshot_at=sorted({*snapshot_times(scenario.search.budget), *dense}),
        ),
        scenario.search.budget,
        quiet,
    )
    # stale artefacts of an earlier identical run that this one does not write
    for name, wanted in (("figure.png", not no_figure), ("animation.gif", animate)):
        if not wanted:
            (out_dir / name).unlink(missing_ok=True)
    if not no_figure:
        from dcee.analysis.figures import search_figure

        _write_atomic(
            out_dir / "figure.png", lambda p: search_figure(result, scenario, truth_model, p)
        )
    if animate:
        from dcee.analysis.figures import search_animation

        _write_atomic(
            out_dir / "animation.gif",
            lambda p: search_animation(result, scenario, truth_model, p),
        )
    result.save(out_dir)  # summary.json last: marks a complete result
    if json_file is not None:
        _write_json(json_file, result.summary)
    _print_summary(result.summary, out_dir)


NAMED_CHANGES = (
    "search.particles",
    "search.hypotheses",
    "search.budget",
    "unknown",
    "truth.model",
    "agent.count",
)
"""Overrides that the default run folder names in words; any other change adds a hash."""


def _default_run_folder(
    scenario: Any, base: Any, changes: dict[str, Any], strategy: str, seed: int
) -> str:
    """``paper-1_dcee_seed0``, plus what differs from the built-in: ``_n10000`` particles,
    ``_j20`` hypotheses, ``_b300`` budget, ``_full`` unknowns, ``_filament`` truth, ``_a3``
    robots, and a short
    hash of the resolved scenario when anything else changed (``--likelihood``, ``--set``), so
    two different runs never share a default folder."""
    import hashlib

    parts = [scenario.name.replace(":", "-"), strategy.replace(":", "+"), f"seed{seed}"]
    s, b = scenario.search, base.search
    if s.particles != b.particles:
        parts.append(f"n{s.particles}")
    if s.hypotheses != b.hypotheses:
        parts.append(f"j{s.hypotheses}")
    if s.budget != b.budget:
        parts.append(f"b{s.budget:g}")
    if scenario.unknown != base.unknown:
        parts.append(scenario.unknown)
    if scenario.truth.model != base.truth.model:
        parts.append(scenario.truth.model_name)
    if scenario.agent.count != base.agent.count:
        parts.append(f"a{scenario.agent.count}")
    named_only = base.with_overrides(**{k: v for k, v in changes.items() if k in NAMED_CHANGES})
    if scenario != named_only:
        digest = hashlib.sha256(
            json.dumps(scenario.model_dump(mode="json"), sort_keys=True).encode()
        ).hexdigest()[:8]
        parts.append(digest)
    return "_".join(parts)


def _check_same_run(out_dir: Path, scenario: Any, strategy: str, seed: int) -> None:
    """Refuse an output folder that holds anything but an earlier run of this very search (same
    resolved scenario, strategy and seed), so results never mix."""
    entries = [p for p in out_dir.iterdir() if not p.name.startswith(".")]
    if not entries:
        return
    try:
        from dcee.campaign.runner import scenario_identity

        config = json.loads((out_dir / "config.json").read_text())
        same = (
            isinstance(config.get("scenario"), dict)
            and scenario_identity(config["scenario"])
            == scenario_identity(scenario.model_dump(mode="json"))
            and config.get("strategy") == strategy
            and config.get("seed") == seed
        )
    except (OSError, ValueError):
        same = False
    if not same:
        raise DceeInputError(
            "out",
            f"{str(out_dir)!r} holds other files or a different search; choose another --out "
            "(or remove it)",
        )


def _compile_notice(quiet: bool) -> None:
    """Say so when this run will compile the numerical kernels (first use after installing or
    changing the code: up to a minute of no visible progress otherwise)."""
    if quiet:
        return
    import dcee.models

    cache = Path(dcee.models.__file__).parent / "__pycache__"
    if not any(cache.glob("*.nbi")):
        click.echo(
            "dcee: compiling the numerical kernels (first run only; up to a minute)", err=True
        )


def _run_with_progress(job: Callable[[Any], Any], budget: float, quiet: bool) -> Any:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    if quiet or not sys.stderr.isatty():
        return job(None)
    with Progress(
        TextColumn("[bold]searching"),
        BarColumn(),
        TextColumn("{task.fields[status]}"),
        TimeElapsedColumn(),
        transient=True,
    ) as bar:
        task = bar.add_task("search", total=budget, status="preparing (kernels, first step)")

        def progress(t: float, rec: dict[str, Any]) -> None:
            bar.update(task, completed=t, status=f"t={t:.0f}s RMSE {rec['rmse']:.2f} m")

        return job(progress)


def _print_summary(
    summary: dict[str, Any], out_dir: Path | None, where: str = "results in"
) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{summary['scenario']} · {summary['strategy']} · seed {summary['seed']}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    rows = [
        ("final RMSE (m)", f"{summary['final_rmse']:.3f}"),
        ("source acquired", str(summary["source_acquired"])),
        ("plume acquired", str(summary["plume_acquired"])),
        ("time to RMSE < 1 m (s)", _fmt(summary["time_to_rmse_1m"])),
        ("time to RMSE < 0.5 m (s)", _fmt(summary["time_to_rmse_0_5m"])),
        *(
            [("longest stall before acquired (s)", f"{summary['longest_stall']:.0f}")]
            if "longest_stall" in summary  # searches saved before the metric lack it
            else []
        ),
        ("steps", str(summary["steps"])),
        ("path length (m)", f"{summary['path_length']:.1f}"),
        ("mean decision time (ms)", f"{1e3 * summary['decision_seconds_mean']:.2f}"),
        ("total compute (s)", f"{summary['compute_seconds_total']:.2f}"),
        *(
            [("reading model, P", f"{summary['model']}, {summary['model_probability']:.3f}")]
            if "model" in summary  # the fluctuation likelihood with its calm model
            else []
        ),
    ]
    for k, v in rows:
        table.add_row(k, v)
    console = Console()
    console.print(table)
    if out_dir is not None:
        console.print(f"{where} {out_dir}")


def _fmt(v: float | None) -> str:
    return "never" if v is None else f"{v:.0f}"


@cli.command()
@click.argument("bag", type=click.Path(path_type=Path))
@click.option(
    "--scenario",
    "scenario_name",
    required=True,
    help="Built-in name or TOML file: the estimator's models and prior, the hold and averaging; "
    "its [truth] is the reference for the RMSE.",
)
@click.option("--particles", type=int, help="Override search.particles.")
@click.option("--seed", default=0, show_default=True, type=int, help="Filter seed.")
@click.option(
    "--out",
    "out_dir",
    required=True,
    type=click.Path(file_okay=False, path_type=Path),
    help="Output folder (steps.parquet, summary.json, config.json, posterior.npz, figure.png).",
)
@click.option(
    "--calibration",
    default=1.0,
    show_default=True,
    type=float,
    help="g/m³ per sensor unit of the recorded concentration (a PID in ppm: g/m³ per ppm).",
)
@click.option("--concentration-topic", default="concentration", show_default=True)
@click.option("--pose-topic", default="odom", show_default=True, help="nav_msgs/Odometry.")
@click.option("--goal-topic", default="goal_pose", show_default=True)
@LIKELIHOOD_OPTION
@SET_OPTION
@click.option("--no-figure", is_flag=True, help="Skip figure.png.")
def replay(
    bag: Path,
    scenario_name: str,
    particles: int | None,
    seed: int,
    out_dir: Path,
    calibration: float,
    concentration_topic: str,
    pose_topic: str,
    goal_topic: str,
    likelihood: str | None,
    settings: tuple[str, ...],
    no_figure: bool,
) -> None:
    """Re-run the estimator over a recorded ROS 2 bag (readings, poses and goals as recorded,
    no planner in the loop) and write the usual search outputs."""
    import math

    from dcee.ros.bag import read_events
    from dcee.ros.replay import replay_bag
    from dcee.scenarios import load_scenario
    from dcee.simulation import make_truth

    if seed < 0:
        raise DceeInputError("seed", f"must be >= 0, got {seed}")
    if not (math.isfinite(calibration) and calibration > 0):
        raise DceeInputError("calibration", f"must be a finite number > 0, got {calibration}")
    scenario = load_scenario(scenario_name).with_overrides(
        **{"search.particles": particles, **_overrides(likelihood, settings)}
    )
    check_writable_dir(out_dir, "out")
    topics = {"concentration": concentration_topic, "pose": pose_topic, "goal": goal_topic}
    read_events(bag, topics)  # a missing or unreadable bag fails here, before any work
    _compile_notice(False)
    result = replay_bag(bag, scenario, seed, topics, calibration)
    (out_dir / "figure.png").unlink(missing_ok=True)
    if not no_figure:
        from dcee.analysis.figures import search_figure

        truth_model = make_truth(scenario, seed)
        _write_atomic(
            out_dir / "figure.png", lambda p: search_figure(result, scenario, truth_model, p)
        )
    result.save(out_dir)
    _print_summary(result.summary, out_dir)


@cli.command()
def scenarios() -> None:
    """List the built-in scenarios."""
    from dcee.scenarios import builtin_scenarios

    for name, data in builtin_scenarios().items():
        click.echo(f"{name:14s} {data['description']}")
    click.echo(
        f"{'random:K':14s} Random configuration K (any integer >= 1): source anywhere in the "
        "50 m x 50 m area, wind from any direction, speed, release rate, height and dispersion "
        "drawn from K alone; K < 1000 tuning range, K >= 1000 reporting range (docs/scenarios.md)."
    )
    click.echo(f"{'random-start:K':14s} The same as random:K with a start drawn over the area.")


@cli.command()
def strategies() -> None:
    """List the registered planners with their options and defaults (use as NAME:KEY=VALUE)."""
    from dcee.planning import get, names

    for name in names():
        planner = get(name)
        doc = planner.summary or next(iter((type(planner).__doc__ or "").strip().splitlines()), "")
        opts = " ".join(f"{k}={v}" for k, v in planner.options().items())
        click.echo(f"{name:12s} {doc}")
        if opts:
            click.echo(f"{'':12s} options: {opts}")


@cli.command()
@click.argument("scenario_name")
@click.option(
    "--format",
    "fmt",
    type=click.Choice(["toml", "json"]),
    default="toml",
    show_default=True,
    help="toml: a scenario file `--scenario` accepts; json: the same settings as JSON.",
)
def show(scenario_name: str, fmt: str) -> None:
    """Print the resolved configuration of a scenario (built-in or TOML path), e.g.
    `dcee show paper:5 > my.toml`, edit, then `dcee run --scenario my.toml`."""
    from dcee.scenarios import load_scenario
    from dcee.scenarios.config import to_toml

    scenario = load_scenario(scenario_name)
    if fmt == "toml":
        click.echo(to_toml(scenario), nl=False)
    else:
        click.echo(json.dumps(scenario.model_dump(mode="json"), indent=2))


@cli.command()
def schema() -> None:
    """Print the JSON Schema of scenario files (from the validating models), for editors and
    other tools."""
    from dcee.scenarios import Scenario

    click.echo(json.dumps(Scenario.model_json_schema(), indent=2))


@cli.command()
@click.option("--json", "json_path", type=click.Path(dir_okay=False), help="Also write JSON here.")
@click.option("--quick", is_flag=True, help="Fewer repeats; skip the whole-search workloads.")
@click.option(
    "--compare-stonesoup",
    is_flag=True,
    help="Time Stone Soup's STE example side by side (needs the 'bench' extra).",
)
@click.option("--decisions", default=10, show_default=True, help="Decisions per side to time.")
def perf(json_path: str | None, quick: bool, compare_stonesoup: bool, decisions: int) -> None:
    """Time the standard workloads against their targets (see docs/performance.md)."""
    import platform

    from rich.console import Console
    from rich.table import Table

    if json_path:
        check_writable_file(Path(json_path), "json")  # before minutes of timing, not after
    console = Console(width=None if sys.stdout.isatty() else 120)
    machine = {
        "cpus": os.cpu_count(),
        "machine": platform.machine(),
        "processor": platform.processor(),
        "python": platform.python_version(),
        "numba_threads": _numba_threads(),
    }
    if compare_stonesoup:
        from dcee.perf.stonesoup_compare import compare

        if decisions < 1:
            raise DceeInputError("decisions", f"must be >= 1, got {decisions}")
        result = compare(decisions)
        console.print(
            f"{result['workload']}, {decisions} decisions each (medians, same process):\n"
            f"  Stone Soup {result['stonesoup_median_ms']:.2f} ms · "
            f"dcee infotaxis {result['dcee_infotaxis_median_ms']:.2f} ms · "
            f"ratio {result['speedup']:.1f}x (target >= {result['target_speedup']:.0f}x)"
        )
        if json_path:
            _write_json(Path(json_path), {"machine": machine, "stonesoup": result})
        return
    from dcee.perf import run_workloads

    with console.status("timing") as status:
        timings = run_workloads(quick, progress=lambda name: status.update(f"timing {name}"))
    table = Table(title=f"dcee perf · {machine['cpus']} CPUs · {machine['machine']}")
    for col in ("workload", "median", "min", "max", "target", "pass"):
        if col == "workload":
            table.add_column(col, no_wrap=True, min_width=30)
        else:
            table.add_column(col, justify="right", no_wrap=True)
    for t in timings:
        d = t.as_dict()
        mark = {True: "[green]pass", False: "[red]FAIL", None: "—"}[t.passed]
        table.add_row(
            t.name,
            f"{d['median']:.3g} {t.unit}",
            f"{d['min']:.3g}",
            f"{d['max']:.3g}",
            t.target_text,
            mark,
        )
    console.print(table)
    for t in timings:
        if t.note:
            console.print(f"  {t.name}: {t.note}")
    if json_path:
        _write_json(
            Path(json_path),
            {"machine": machine, "workloads": [t.as_dict() for t in timings]},
        )


def _numba_threads() -> int:
    import numba

    return int(numba.get_num_threads())


@cli.command()
@click.option(
    "--suite",
    default="paper",
    show_default=True,
    type=RegistryChoice(_suite_names),
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
    from dcee.scenarios.config import truth_choice

    names = tuple(s.strip() for s in strategies.split(",") if s.strip())
    overrides = _overrides(likelihood, settings)
    if agents is not None:
        overrides["agent.count"] = agents
    campaign = Campaign(
        out_dir,
        suite,
        names,
        repeats,
        unknown,
        particles,
        truth_choice(truth) if truth is not None else None,
        overrides,
        allow_code_change,
    )
    check_writable_dir(out_dir, "out")
    _compile_notice(False)
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


def _log_progress(suite: str, finished: int, todo: int, failed: int, elapsed: float) -> None:
    """Plain progress lines for logs (stderr not a terminal, e.g. under nohup or a batch
    system): about twenty per campaign plus the last, each with completed/total, failures and
    an ETA from the mean rate so far."""
    if finished != todo and finished % max(1, todo // 20):
        return
    eta = elapsed / finished * (todo - finished)
    click.echo(
        f"{suite}: {finished}/{todo} searches, failed {failed}, "
        f"elapsed {_clock(elapsed)}, ETA {_clock(eta)}",
        err=True,
    )


def _clock(seconds: float) -> str:
    m, s = divmod(round(seconds), 60)
    h, m = divmod(m, 60)
    return f"{h}:{m:02d}:{s:02d}"


@cli.command()
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

    paths = write_report(results_dir, out_dir or results_dir / "report")
    for p in paths:
        click.echo(str(p))


def main(argv: list[str] | None = None) -> None:
    """Entry point: user errors → one line on stderr and exit 2."""
    try:
        cli.main(args=argv, prog_name="dcee", standalone_mode=False)
    except DceeInputError as exc:
        click.echo(f"dcee: error: {exc}", err=True)
        sys.exit(2)
    except click.exceptions.Abort:
        click.echo("dcee: interrupted", err=True)
        sys.exit(130)
    except click.ClickException as exc:
        click.echo(f"dcee: error: {exc.format_message()}", err=True)
        sys.exit(2)
    except KeyboardInterrupt:
        click.echo("dcee: interrupted", err=True)
        sys.exit(130)
    sys.exit(0)


if __name__ == "__main__":  # pragma: no cover
    main()
