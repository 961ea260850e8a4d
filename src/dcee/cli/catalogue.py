"""What there is to choose from: ``dcee scenarios``, ``strategies``, ``show`` and ``schema``."""

from __future__ import annotations

import json

import click


@click.command(short_help="List the built-in scenarios.")
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
    click.echo(
        f"{'random-site:K':14s} A random site: 3-6 buildings, a release among them, the wind "
        "from anywhere; for tuning the gas round buildings (--truth lbm), never reported."
    )
    from dcee.scenarios.geo_area import SITES

    for path in sorted(SITES.glob("*.geojson")):
        click.echo(
            f"{'area:' + path.stem:14s} A site on a map in geographic coordinates "
            f"({path.name}; docs/guide/on-a-map.md); any GeoJSON site: --area FILE."
        )


@click.command(short_help="List the planners and their options.")
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


@click.command(short_help="Print a scenario's resolved configuration.")
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
    from dcee.scenarios import load_scenario, to_toml

    scenario = load_scenario(scenario_name)
    if fmt == "toml":
        click.echo(to_toml(scenario), nl=False)
    else:
        click.echo(json.dumps(scenario.model_dump(mode="json"), indent=2))


@click.command(short_help="Print the JSON Schema of scenario files.")
def schema() -> None:
    """Print the JSON Schema of scenario files (from the validating models), for editors and
    other tools."""
    from dcee.scenarios import Scenario

    click.echo(json.dumps(Scenario.model_json_schema(), indent=2))
