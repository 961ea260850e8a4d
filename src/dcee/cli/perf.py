"""``dcee perf``: the standard workloads timed against their targets."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from dcee.errors import DceeInputError
from dcee.io import check_writable_file, write_json


@click.command(short_help="Time the standard workloads against targets.")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), help="Also write JSON here.")
@click.option("--quick", is_flag=True, help="Fewer repeats; skip the whole-search workloads.")
@click.option(
    "--compare-stonesoup",
    is_flag=True,
    help="Time Stone Soup's STE example side by side (needs the 'bench' extra).",
)
@click.option("--decisions", default=10, show_default=True, help="Decisions per side to time.")
@click.option(
    "--repeats",
    default=1,
    show_default=True,
    help="With --compare-stonesoup: runs of the alternation; the median run's ratio is reported.",
)
def perf(
    json_path: str | None, quick: bool, compare_stonesoup: bool, decisions: int, repeats: int
) -> None:
    """Time the standard workloads against their targets (see docs/performance.md). The JSON
    records the machine, the versions and the load beside the run (dcee.perf.machine): a run
    with other processes busy is marked shared."""
    from rich.console import Console
    from rich.table import Table

    from dcee.perf.machine import LoadMonitor, load_warning, machine_identity, machine_record

    if json_path:
        check_writable_file(Path(json_path), "json")  # before minutes of timing, not after
    if decisions < 1:
        raise DceeInputError("decisions", f"must be >= 1, got {decisions}")
    if repeats < 1:
        raise DceeInputError("repeats", f"must be >= 1, got {repeats}")
    console = Console(width=None if sys.stdout.isatty() else 120)
    machine = machine_record()
    if compare_stonesoup:
        from dcee.perf.stonesoup_compare import compare

        with LoadMonitor() as load:
            result = compare(decisions, repeats)
        warning = load_warning(load.record())
        console.print(f"{result['workload']}, {decisions} decisions each (medians, same process):")
        for run in result["runs"] if repeats > 1 else []:
            console.print(
                f"  run: Stone Soup {run['stonesoup_median_ms']:.2f} ms · dcee infotaxis "
                f"{run['dcee_infotaxis_median_ms']:.2f} ms · ratio {run['speedup']:.1f}x"
            )
        low, high = result["speedup_range"]
        console.print(
            f"  {'median of ' + str(repeats) + ' runs: ' if repeats > 1 else ''}"
            f"Stone Soup {result['stonesoup_median_ms']:.2f} ms · "
            f"dcee infotaxis {result['dcee_infotaxis_median_ms']:.2f} ms · "
            f"ratio {result['speedup']:.1f}x"
            f"{f' (runs {low:.1f}-{high:.1f}x)' if repeats > 1 else ''}"
            f" (target >= {result['target_speedup']:.0f}x)"
        )
        console.print(f"  on {machine_identity(machine)}")
        if warning:
            console.print(f"[yellow]{warning}")
        if json_path:
            record = {"machine": machine, "load": load.record(), "stonesoup": result}
            write_json(Path(json_path), record)
        return
    from dcee.perf import run_workloads

    with console.status("timing") as status, LoadMonitor() as load:
        timings = run_workloads(quick, progress=lambda name: status.update(f"timing {name}"))
    table = Table(title=f"dcee perf · {machine_identity(machine)}")
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
    if warning := load_warning(load.record()):
        console.print(f"[yellow]{warning}")
    if json_path:
        write_json(
            Path(json_path),
            {
                "machine": machine,
                "load": load.record(),
                "quick": quick,
                "workloads": [t.as_dict() for t in timings],
            },
        )
