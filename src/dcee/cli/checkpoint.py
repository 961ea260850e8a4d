"""``dcee checkpoint``: check a search checkpoint (a robot's ``checkpoint`` file) and say what it
holds, before a node resumes from it."""

from __future__ import annotations

import json
from pathlib import Path

import click

from dcee.cli.options import LIKELIHOOD_OPTION, SET_OPTION, overrides


@click.command(short_help="Check a search checkpoint and print what it holds.")
@click.argument("path", type=click.Path(path_type=Path))
@click.option(
    "--scenario",
    "scenario_name",
    help="Built-in name or TOML file: refuse a checkpoint saved under another scenario (the "
    "node's parameters, e.g. --particles, are part of it).",
)
@click.option("--particles", type=int, help="Override search.particles (as the node's parameter).")
@LIKELIHOOD_OPTION
@SET_OPTION
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
def checkpoint(
    path: Path,
    scenario_name: str | None,
    particles: int | None,
    likelihood: str | None,
    settings: tuple[str, ...],
    as_json: bool,
) -> None:
    """Read the checkpoint PATH (written by `Searcher.save`, the ROS 2 node's `checkpoint`
    parameter) as a node would: a file that is truncated, edited, of another dcee version or,
    with --scenario, of another scenario is refused in one line, exit code 2. An intact one:
    its scenario, code version, readings, time, position and estimate."""
    from dcee.runs import scenario_key
    from dcee.scenarios import load_scenario
    from dcee.searcher import Searcher

    key = None
    if scenario_name is not None:
        scenario = load_scenario(scenario_name).with_overrides(
            **{"search.particles": particles, **overrides(likelihood, settings)}
        )
        key = scenario_key(scenario)
    searcher = Searcher.load(path, key)
    est = searcher.estimate()
    code = searcher.checkpoint_code or {}
    summary = {
        "checkpoint": str(path),
        "scenario": (searcher.scenario_key or {}).get("name"),
        "scenario_identity": (searcher.scenario_key or {}).get("identity"),
        "code_version": code.get("commit") or code.get("version") or code,
        "readings": int(getattr(searcher.filter, "n_readings", 0)),
        "time_s": float(searcher.time),
        "position_m": None if searcher.position is None else searcher.position.tolist(),
        "planner": type(searcher.planner).__name__ if searcher.planner is not None else None,
        "estimate_m": est.mean.tolist(),
        "spread_m": est.spread,
    }
    if as_json:
        click.echo(json.dumps(summary, indent=2))
        return
    for k, v in summary.items():
        if isinstance(v, list):
            v = "(" + ", ".join(f"{x:.3f}" for x in v) + ")"
        elif isinstance(v, float):
            v = f"{v:.3f}"
        click.echo(f"{k:18s} {v}")
