"""``dcee plume``: compute (once, then cached) the fluid solver's plume and check its
statistics against published plume measurements."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from dcee.cli.options import SET_OPTION
from dcee.errors import DceeInputError
from dcee.io import check_writable_file, write_json

DISTANCES = (5.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0)
"""m downwind where the statistics are printed (those inside the domain)."""


def _spec(settings: tuple[str, ...], model: str = "lbm") -> Any:
    """The ``model`` truth's parameters from ``--set truth.model.KEY=VALUE`` (or
    ``KEY=VALUE``)."""
    from pydantic import ValidationError

    from dcee.scenarios import parse_setting
    from dcee.scenarios.schema.truth_models import TRUTH_KINDS

    spec_class = TRUTH_KINDS[model].spec
    assert spec_class is not None
    values = {}
    for text in settings:
        path, value = parse_setting(text)
        key = path.removeprefix("truth.model.")
        if key not in spec_class.model_fields or key == "kind":
            allowed = ", ".join(k for k in spec_class.model_fields if k != "kind")
            raise DceeInputError(path, f"not a setting of the {model} truth (allowed: {allowed})")
        values[key] = value
    try:
        return spec_class(**values)
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
@click.option(
    "--model",
    type=click.Choice(["lbm", "lbm3d"]),
    default="lbm",
    show_default=True,
    help="The planar plume behind a turbulence grid, or the 3-D surface-layer plume.",
)
@click.option(
    "--height",
    type=click.FloatRange(0.0, 100.0),
    default=1.0,
    show_default=True,
    help="lbm3d: m above the ground of the release (its lattice cell's centre is used).",
)
@click.option(
    "--scenario",
    "scenario_name",
    help="Instead: compute the plume a scenario's solver truth flies (a site's, round its "
    "buildings: area:fontvieille takes minutes on first use), cache it and print where.",
)
@click.option("-q", "--quiet", is_flag=True, help="No progress bar.")
def plume(
    settings: tuple[str, ...],
    json_file: Path | None,
    model: str,
    height: float,
    scenario_name: str | None,
    quiet: bool,
) -> None:
    """Compute the plume of `truth.model = "lbm"` (lbmpy's lattice Boltzmann, docs/plumes.md)
    or, with --model lbm3d, of the 3-D surface-layer plume, for the parameters given with
    --set truth.model.KEY=VALUE, keep it in the cache ($DCEE_CACHE or ~/.cache/dcee; a second
    call reads it back) and print its statistics downwind against published figures: the
    spread against Briggs' open-country curves for stability classes A (very unstable) to D
    (neutral), the scalar flux (kept by a conserved scalar), the centreline fluctuation
    intensity and intermittency factor; for lbm3d also the vertical spread and the centroid's
    height, and the wind against the log law and the neutral surface layer's turbulence."""
    from rich.console import Console

    if scenario_name is not None:
        given = click.get_current_context().get_parameter_source
        for name, flag in (("model", "--model"), ("height", "--height"), ("json_file", "--json")):
            if given(name) == click.core.ParameterSource.COMMANDLINE:
                raise DceeInputError(flag, "not with --scenario (the scenario's truth says it)")
        _scenario_plume(scenario_name, settings, quiet)
        return
    spec = _spec(settings, model)
    if json_file is not None:
        check_writable_file(json_file, "--json")
    if model == "lbm3d":
        from dcee.simulation import lbm3d

        path = _computed(
            lbm3d.cache_path(spec, height),
            lambda progress: lbm3d.cached_recording(spec, height, progress),
            quiet,
        )
        _report_3d(path, spec, json_file)
        return
    from rich.table import Table

    from dcee.recordings.statistics import briggs_sigma_y, section_statistics
    from dcee.simulation.lbm import cache_path, cached_recording, load_canonical

    path = _computed(
        cache_path(spec), lambda progress: cached_recording(spec, progress=progress), quiet
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


def _scenario_plume(name: str, settings: tuple[str, ...], quiet: bool) -> None:
    """``dcee plume --scenario NAME``: build the scenario's truth once (its solver plume
    computed and cached as a search would) and say where the recording is."""
    from dcee.cli.options import overrides
    from dcee.scenarios import load_scenario
    from dcee.simulation import make_truth

    scenario = load_scenario(name).with_overrides(**overrides(None, settings))
    kind = scenario.truth.model_name
    if kind not in ("lbm", "lbm3d"):
        raise DceeInputError(
            "scenario", f"{scenario.name}'s truth is {kind!r}, not a solver's plume (lbm, lbm3d)"
        )
    before = set(_cached_files())
    if not quiet:
        click.echo(f"dcee: computing {scenario.name}'s {kind} plume once (cached)", err=True)
    make_truth(scenario, 0)
    new = sorted(set(_cached_files()) - before)
    where = ", ".join(str(p) for p in new) if new else "already in the cache"
    click.echo(f"{scenario.name}: {kind} plume ready ({where})")


def _cached_files() -> list[Path]:
    """The recordings in the plume cache now."""
    from dcee.simulation.lbm import cache_folder

    folder = cache_folder()
    return list(folder.glob("*.nc")) if folder.is_dir() else []


def _computed(path: Path, compute: Any, quiet: bool) -> Path:
    """``compute(progress)`` → the cached recording, with a progress bar unless it is cached
    already or ``quiet``."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    if path.is_file() or quiet:
        return compute(None)
    with Progress(
        TextColumn("[bold]solving"),
        BarColumn(),
        TextColumn("{task.percentage:>3.0f} % of the canonical time"),
        TimeRemainingColumn(),
        console=Console(stderr=True),
    ) as bar:
        task = bar.add_task("solve", total=1.0)
        return compute(lambda done, total: bar.update(task, completed=done / total))


def _report_3d(path: Path, spec: Any, json_file: Path | None) -> None:
    """Print (and write) the 3-D plume's statistics against the published figures."""
    import numpy as np
    from rich.console import Console
    from rich.table import Table

    from dcee.recordings.statistics import (
        briggs_sigma_y,
        briggs_sigma_z,
        section_statistics_3d,
    )
    from dcee.simulation.lbm3d import load_canonical, recording_attrs
    from dcee.simulation.lbm3d_solver import SURFACE_LAYER_SIGMAS, friction_velocity, log_law

    truth, release = load_canonical(path)
    assert truth.z is not None
    rows = section_statistics_3d(
        truth.values, truth.x, truth.y, truth.z, [d for d in DISTANCES if d < truth.x[-1]]
    )
    attrs = recording_attrs(path)
    table = Table(
        title=f"lbm3d plume {path.name}, release at {release:g} m",
        caption="σ_y, σ_z: spreads of the time-mean section about its centroid (z̄ its height); "
        "Briggs open country D (neutral) to A (very unstable), fitted beyond 100 m; σc/C̄, γ: "
        "fluctuation intensity and intermittency (share > C̄/10) at the centroid",
    )
    for name in ("x m", "σ_y m", "Briggs D-A", "σ_z m", "Briggs D-A ", "z̄ m", "σc/C̄", "γ"):
        table.add_column(name, justify="right")
    for r in rows:
        table.add_row(
            f"{r.x:.0f}",
            f"{r.sigma_y:.2f}",
            f"{briggs_sigma_y(r.x, 'D'):.1f}-{briggs_sigma_y(r.x, 'A'):.1f}",
            f"{r.sigma_z:.2f}",
            f"{briggs_sigma_z(r.x, 'D'):.1f}-{briggs_sigma_z(r.x, 'A'):.1f}",
            f"{r.centroid_z:.2f}",
            f"{r.intensity:.2f}",
            f"{r.intermittency:.2f}",
        )
    console = Console()
    console.print(table)
    u_star = friction_velocity(spec)
    heights = np.asarray(attrs["mean_wind_heights"], dtype=np.float64)
    profile = np.asarray(attrs["mean_wind_profile"], dtype=np.float64)
    wind = Table(title="mean wind 2 m upwind of the release (m/s; 1 m/s at 4 m)")
    for name in ("z m", "ū", "log law"):
        wind.add_column(name, justify="right")
    for z in (0.75, 1.75, 2.75, 4.0, 6.0, 8.0):
        k = int(np.argmin(np.abs(heights - z)))
        wind.add_row(
            f"{heights[k]:.2f}", f"{profile[k]:.2f}", f"{float(log_law(spec, heights[k])):.2f}"
        )
    console.print(wind)
    click.echo("ū against the inflow's log law; the turbulence at the release height against the")
    click.echo("neutral surface layer's (Panofsky & Dutton 1984, in brackets)")
    measured = [attrs[f"turbulence_intensity_{c}"] / u_star for c in "uvw"]
    click.echo(
        "turbulence at the release: σu/u*, σv/u*, σw/u* = "
        + ", ".join(f"{m:.2f} ({p:g})" for m, p in zip(measured, SURFACE_LAYER_SIGMAS, strict=True))
        + f"; Lagrangian time ≈ {attrs['lagrangian_time_estimate']:.1f} s"
    )
    click.echo(f"cached recording: {path}")
    if json_file is not None:
        write_json(
            json_file,
            {
                "recording": str(path),
                "release_height": release,
                "parameters": json.loads(spec.model_dump_json()),
                "sections": [r.__dict__ for r in rows],
                "turbulence_over_u_star": dict(zip("uvw", measured, strict=True)),
                "wind_profile": {"z": heights.tolist(), "u": profile.tolist()},
            },
        )
