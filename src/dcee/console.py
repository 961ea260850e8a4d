"""What every interface prints: a search's summary table, progress, the one-line error of a user
mistake and the exit codes. The command line, the ROS 2 entry points and replay all print through
here, so none imports another to reuse its printing.

Exit codes: 0 done, 2 a user mistake (one line on stderr, ``<program>: error: <field>: <what is
allowed>``, printed before any work starts), 130 interrupted.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from dcee.errors import DceeInputError

USER_ERROR = 2
"""Exit code of a user mistake (bad option, bad scenario value, unknown name, missing file)."""
INTERRUPTED = 130
"""Exit code of an interrupted command (Ctrl-C)."""
TERMINATED = 143
"""Exit code of a command stopped by SIGTERM (``kill PID``, a scheduler stopping a job)."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread while a command runs: every clean-up written for
    Ctrl-C runs for it too (a campaign stops its worker processes instead of orphaning them)."""


def _raise_terminated(signum: int, frame: Any) -> None:
    raise Terminated


def error_exit(program: str, message: str) -> None:
    """Print ``<program>: error: <message>`` (its first line) on stderr and exit 2."""
    first = message.splitlines()[0] if message else "error"
    click.echo(f"{program}: error: {first}", err=True)
    sys.exit(USER_ERROR)


def _redeliver_interrupts(unraisable: Any, fallback: Callable[[Any], None]) -> None:
    """An exception inside a finaliser (``__del__``, numba's and llvmlite's among them) cannot
    propagate: Python prints it with a traceback and goes on. A Ctrl-C that lands there would be
    lost and printed; this raises it again in the main thread shortly after, once the finaliser has
    returned (from a timer thread: a signal simulated here would be raised inside this hook and
    lost again; should it land in another finaliser, this hook defers it once more)."""
    if unraisable.exc_type is not None and issubclass(unraisable.exc_type, KeyboardInterrupt):
        _interrupt_main_soon()
    else:
        fallback(unraisable)


def _interrupt_main_soon(delay: float = 0.01) -> None:
    """Raise KeyboardInterrupt in the main thread ``delay`` s from now, from a timer thread.
    Should the main thread still be in here when the timer fires (``Timer.start`` waits for the
    thread to start: on a loaded machine the 10 ms can pass first; seen once in a CI run), the
    interrupt lands in this hook, where Python would print it and drop it: it is caught and
    scheduled again, later each time."""
    import _thread
    import threading

    while True:
        try:
            timer = threading.Timer(delay, _thread.interrupt_main)
            timer.daemon = True
            timer.start()
            return
        except KeyboardInterrupt:
            delay *= 2


def run_command(command: click.Command, program: str, argv: list[str] | None = None) -> None:
    """Run a click ``command`` as program ``program``: a user mistake ends in one line on stderr
    and exit 2, an interruption in exit 130 (Ctrl-C) or 143 (SIGTERM, after the same clean-up),
    success in exit 0 (never a traceback for either)."""
    previous = sys.unraisablehook
    sys.unraisablehook = lambda u: _redeliver_interrupts(u, previous)
    main_thread = threading.current_thread() is threading.main_thread()
    previous_term = signal.signal(signal.SIGTERM, _raise_terminated) if main_thread else None
    try:
        command.main(args=argv, prog_name=program, standalone_mode=False)
    except DceeInputError as exc:
        error_exit(program, str(exc))
    except click.ClickException as exc:
        error_exit(program, exc.format_message())
    except (KeyboardInterrupt, click.exceptions.Abort) as exc:
        # click turns an interruption inside a command into Abort, the interruption its cause
        if isinstance(exc, Terminated) or isinstance(exc.__cause__, Terminated):
            click.echo(f"{program}: terminated", err=True)
            sys.exit(TERMINATED)
        click.echo(f"{program}: interrupted", err=True)
        sys.exit(INTERRUPTED)
    finally:
        sys.unraisablehook = previous
        if main_thread:
            signal.signal(signal.SIGTERM, previous_term)
    sys.exit(0)


def compile_notice(quiet: bool) -> None:
    """Say so when this process will compile the numerical kernels (first use after installing
    or changing the code: up to a minute of no visible progress otherwise)."""
    if quiet:
        return
    from dcee.kernel_cache import compiled_before

    if not compiled_before():
        click.echo(
            "dcee: compiling the numerical kernels (first run only; up to a minute)", err=True
        )


def plume_notice(scenario: Any, quiet: bool) -> None:
    """Say so when the scenario's fluid-solver plume is not cached yet and is about to be
    computed (minutes of no visible progress otherwise): the 3-D plume of its release cell, or
    the planar plume in open terrain."""
    if quiet:
        return
    model = scenario.truth.model
    kind = getattr(model, "kind", None)
    if kind == "lbm3d":
        from dcee.simulation.lbm3d import cache_path

        height = float(scenario.truth_theta()[2]) - float(scenario.volume.low[2])
        path, what = cache_path(model, height), "the 3-D plume of this release cell (about 4 min)"
    elif kind == "lbm" and not scenario.world.obstacles and scenario.world.map is None:
        from dcee.simulation.lbm import cache_path

        path, what = cache_path(model), "the planar solver plume (about a minute)"
    else:
        return
    if not path.exists():
        click.echo(f"dcee: computing {what}, once: it is cached as {path}", err=True)


def _why_climb(scenario: Any) -> str:
    """Why an unset climb resolved to a climbing UAV (:func:`dcee.scenarios.unset_climb`)."""
    if scenario.estimator.likelihood == "fluctuation":
        return "a turbulent plume is expected (fluctuation likelihood)"
    return "the count of releases is unknown (estimator.max_sources > 1)"


def climb_notice(scenarios: Any, quiet: bool = False) -> None:
    """Say so when ``agent.climb`` was left unset and resolves to a climbing UAV (the
    fluctuation likelihood's default and the count-unknown one,
    :meth:`dcee.scenarios.Scenario.resolved_climb`): the agent
    then has two moves more than the paper's. ``scenarios``: one scenario or several."""
    if quiet:
        return
    many = scenarios if isinstance(scenarios, list | tuple) else [scenarios]
    auto = [s for s in many if s.agent.climb is None and s.climb > 0]
    if auto:
        click.echo(
            f"dcee: agent.climb unset: {_why_climb(auto[0])}, so the UAV may also climb and "
            f"descend {auto[0].climb:g} m; set agent.climb = 0 for a fixed altitude "
            "(docs/scenarios.md)",
            err=True,
        )


def run_with_progress(job: Callable[[Any], Any], budget: float, quiet: bool) -> Any:
    """Call ``job(progress)`` with a progress bar over the search's ``budget`` (s) on a terminal;
    ``progress(t, record)`` is None when ``quiet`` or stderr is not a terminal."""
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


def print_summary(summary: dict[str, Any], out_dir: Path | None, where: str = "results in") -> None:
    """A search's summary (:func:`dcee.runs.search_summary`) as a table on stdout, then
    ``<where> <out_dir>`` when there is a folder."""
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{summary['scenario']} · {summary['strategy']} · seed {summary['seed']}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    rows = [
        ("final RMSE (m)", f"{summary['final_rmse']:.3f}"),
        ("source acquired", str(summary["source_acquired"])),
        *(
            [
                (
                    f"OSPA to the {summary['true_sources']} releases (m, 3 m cut-off)",
                    f"{summary['final_ospa']:.2f}",
                )
            ]
            if summary.get("true_sources", 1) > 1
            else []
        ),
        *(
            [
                (
                    "estimate (latitude, longitude; height)",
                    f"{geo['latitude']:.7f}°, {geo['longitude']:.7f}°; {geo['height_m']:.1f} m",
                ),
                (
                    "estimate (local x, y, z m)",
                    ", ".join(f"{v:.2f}" for v in summary["final_mean"]),
                ),
            ]
            if (geo := summary.get("final_mean_geo"))
            else []
        ),
        ("plume acquired", str(summary["plume_acquired"])),
        ("time to RMSE < 1 m (s)", _seconds(summary["time_to_rmse_1m"])),
        ("time to RMSE < 0.5 m (s)", _seconds(summary["time_to_rmse_0_5m"])),
        *(
            [("longest stall before acquired (s)", f"{summary['longest_stall']:.0f}")]
            if "longest_stall" in summary  # searches saved before the metric lack it
            else []
        ),
        *(
            [("longest wander in 15 m before acquired (s)", f"{summary['longest_wander']:.0f}")]
            if "longest_wander" in summary
            else []
        ),
        ("steps", str(summary["steps"])),
        *(
            [
                (
                    "search ended",
                    {"localised": "source localised (stop rule)"}.get(
                        summary["finish_reason"], str(summary["finish_reason"])
                    ),
                )
            ]
            if summary.get("finish_reason")  # a robot's search (dcee-ros-demo)
            else []
        ),
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


def clock(seconds: float) -> str:
    """``h:mm:ss`` of a duration in s."""
    m, s = divmod(round(seconds), 60)
    h, m = divmod(m, 60)
    return f"{h}:{m:02d}:{s:02d}"


def _seconds(v: float | None) -> str:
    return "never" if v is None else f"{v:.0f}"


__all__ = [
    "INTERRUPTED",
    "USER_ERROR",
    "clock",
    "compile_notice",
    "error_exit",
    "print_summary",
    "run_command",
    "run_with_progress",
]
