"""``dcee plume``: compute (once, then cached) the fluid solver's plume and check its
statistics against published plume measurements."""

from __future__ import annotations

import json
from pathlib import Path

import click

from dcee.cli.options import SET_OPTION
from dcee.errors import DceeInputError
from dcee.io import check_writable_file, write_json

DISTANCES = (5.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0)
"""m downwind where the statistics are printed (those inside the domain)."""


def _spec(settings: tuple[str, ...]) -> object:
    """The lbm truth's parameters from ``--set truth.model.KEY=VALUE`` (or ``KEY=VALUE``)."""
    from pydantic import ValidationError

    from dcee.scenarios import parse_setting
    from dcee.scenarios.schema.truth import LbmSpec

    values = {}
    for text in settings:
        path, value = parse_setting(text)
        key = path.removeprefix("truth.model.")
        if key not in LbmSpec.model_fields or key == "kind":
            allowed = ", ".join(k for k in LbmSpec.model_fields if k != "kind")
            raise DceeInputError(path, f"not a setting of the lbm truth (allowed: {allowed})")
        values[key] = value
    try:
        return LbmSpec(**values)
    except ValidationError as exc:
        err = exc.errors()[0]
        field = "truth.model." + ".".join(str(p) for p in err["loc"])
        raise DceeInputError(field, err["msg"]) from None


@click.command(short_help="Compute (once) and check the fluid solver's plume.")
@SET_OPTION
@click.option(
    "--json",
    "json_file",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Also write the statistics and the cache path as JSON here.",
)
@click.option("-q", "--quiet", is_flag=True, help="No progress bar.")
def plume(settings: tuple[str, ...], json_file: Path | None, quiet: bool) -> None:
    """Compute the plume of `truth.model = "lbm"` (lbmpy's lattice Boltzmann, docs/scenarios.md)
    for the parameters given with --set truth.model.KEY=VALUE, keep it in the cache
    ($DCEE_CACHE or ~/.cache/dcee; a second call reads it back) and print its statistics
    downwind against published figures: the crosswind spread against Briggs' open-country
    curves for stability classes A (very unstable) to D (neutral), the scalar flux (kept by a
    conserved scalar), the centreline fluctuation intensity and intermittency factor."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
    from rich.table import Table

    from dcee.recordings.statistics import briggs_sigma_y, section_statistics
    from dcee.simulation.lbm import cache_path, cached_recording, load_canonical

    spec = _spec(settings)
    if json_file is not None:
        check_writable_file(json_file, "--json")
    console = Console(stderr=True)
    path = cache_path(spec)
    if path.is_file() or quiet:
        path = cached_recording(spec)
    else:
        with Progress(
            TextColumn("[bold]solving"),
            BarColumn(),
            TextColumn("{task.percentage:>3.0f} % of the canonical time"),
            TimeRemainingColumn(),
            console=console,
        ) as bar:
            task = bar.add_task("solve", total=1.0)
            path = cached_recording(
                spec, progress=lambda done, total: bar.update(task, completed=done / total)
            )
    truth = load_canonical(path)
    rows = section_statistics(
        truth.values, truth.x, truth.y, [d for d in DISTANCES if d < truth.x[-1]]
    )
    table = Table(
        title=f"lbm plume {path.name}",
        caption="σ_y: crosswind spread of the mean; flux: ∫C̄ dy · U (1 at 10 m); "
        "σc/C̄: centreline fluctuation intensity; γ: intermittency (share > C̄/10)",
    )
    for name in ("x m", "σ_y m", "Briggs D-A", "flux", "σc/C̄", "γ"):
        table.add_column(name, justify="right")
    for r in rows:
        d, a = briggs_sigma_y(r.x, "D"), briggs_sigma_y(r.x, "A")
        table.add_row(
            f"{r.x:.0f}",
            f"{r.sigma_y:.2f}",
            f"{d:.1f}-{a:.1f}",
            f"{r.flux:.2f}",
            f"{r.intensity:.2f}",
            f"{r.intermittency:.2f}",
        )
    Console().print(table)
    click.echo(f"cached recording: {path}")
    if json_file is not None:
        write_json(
            json_file,
            {
                "recording": str(path),
                "parameters": json.loads(spec.model_dump_json()),
                "sections": [r.__dict__ for r in rows],
            },
        )
