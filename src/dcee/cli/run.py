"""``dcee run``: one simulated search, its record, summary, configuration and figure."""

from __future__ import annotations

from pathlib import Path

import click

from dcee.cli.options import LIKELIHOOD_OPTION, SET_OPTION, TRUTH_OPTION, overrides
from dcee.console import (
    climb_notice,
    compile_notice,
    plume_notice,
    print_summary,
    run_with_progress,
)
from dcee.errors import DceeInputError
from dcee.io import (
    check_writable_dir,
    check_writable_file,
    folder_kept_only_on_success,
    write_atomic,
    write_json,
)
from dcee.search_memory import check_search_memory


@click.command(short_help="One simulated search: record, summary and figure.")
@click.option(
    "--scenario",
    "scenario_name",
    help="Built-in name (see `dcee scenarios`), path to a TOML file, or a GADEN simulation "
    "folder [default, and required otherwise: the folder --truth names, as its room's scenario].",
)
@click.option(
    "--strategy",
    default="dcee",
    show_default=True,
    help="Planner NAME[:KEY=VALUE]..., e.g. dcee-cl:reach=6 (`dcee strategies` lists them).",
)
@click.option(
    "--area",
    "area_file",
    type=click.Path(dir_okay=False, path_type=Path),
    help="A site in geographic coordinates: a GeoJSON file with the search area, buildings, "
    "no-go zones, the start and the release (docs/guide/on-a-map.md); with --scenario, that "
    "scenario's settings on this site. Writes estimate.geojson and estimate.kml too.",
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
@click.option(
    "--dry-run",
    is_flag=True,
    help="Check the command (scenario, settings, strategy, memory) and print what it would "
    "run and where, then stop: no search, no files.",
)
def run(
    scenario_name: str | None,
    strategy: str,
    area_file: Path | None,
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
    dry_run: bool,
) -> None:
    """Run one simulated search and write its record, summary, configuration and figure."""
    import numpy as np

    from dcee.allocator import tune_allocator
    from dcee.planning import get as get_planner
    from dcee.runs import run_episode, snapshot_times
    from dcee.runs.folder import check_same_run, default_run_folder, edited_name, edits
    from dcee.scenarios import load_scenario, truth_choice
    from dcee.simulation import make_truth

    if seed < 0:
        raise DceeInputError("seed", f"must be >= 0, got {seed}")
    get_planner(strategy)  # fail fast on an unknown name or a bad option
    if truth is not None:
        truth = truth_choice(truth)
    if scenario_name is None and area_file is not None:
        scenario_name, area_file = str(area_file), None  # the site's own scenario
    if scenario_name is None:
        if not (isinstance(truth, dict) and truth.get("kind") == "gaden"):
            raise DceeInputError(
                "scenario",
                "required (a built-in, a TOML file or a GADEN folder), unless "
                "--truth names a GADEN simulation folder",
            )
        scenario_name = truth["folder"]
    base = load_scenario(scenario_name)
    if area_file is not None:
        from dcee.scenarios.geo_area import with_area
        from dcee.scenarios.schema import validate_scenario

        base = validate_scenario(with_area(base, area_file))
    changes = {
        "search.particles": particles,
        "search.hypotheses": hypotheses,
        "search.budget": budget,
        "unknown": unknown,
        "truth.model": truth,
        "agent.count": agents,
        **overrides(likelihood, settings),
    }
    scenario = base.with_overrides(**changes)
    if scenario.agent.count > 1:
        from dcee.planning import check_team_planner

        check_team_planner(get_planner(strategy))
    out_dir = out_dir or Path("results") / default_run_folder(
        scenario, base, changes, strategy, seed
    )
    # an edited scenario's results carry a derived name (paper:1+3fa2c1d0) and the edits
    scenario = scenario.with_overrides(name=edited_name(scenario, base, changes))
    run_edits = edits(changes)
    check_search_memory(scenario.search.particles, scenario.estimator.max_sources)
    if dry_run:  # the truth's data (a recording, a solver's plume) are read by the search
        check_writable_dir(out_dir, "out", create=False)
        if json_file is not None:
            check_writable_file(json_file, "json")
        click.echo(
            f"would run {scenario.name} ({scenario.truth.model_name} truth, "
            f"{scenario.search.particles} particles, {scenario.search.budget:g} s) with "
            f"{strategy}, seed {seed}, into {out_dir}"
        )
        return
    with folder_kept_only_on_success(out_dir):  # a failed run leaves no folder
        check_writable_dir(out_dir, "out")
        check_same_run(out_dir, scenario, strategy, seed)
        if json_file is not None:
            check_writable_file(json_file, "json")
        plume_notice(scenario, quiet)
        truth_model = make_truth(scenario, seed)  # a bad recording fails here, before the search
        tune_allocator()  # this process is the command line's own (see dcee.allocator)
        compile_notice(quiet)
        climb_notice(scenario, quiet)
        dense = np.linspace(0.0, scenario.search.budget, 41) if animate else ()
        result = run_with_progress(
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

            write_atomic(
                out_dir / "figure.png", lambda p: search_figure(result, scenario, truth_model, p)
            )
        if animate:
            from dcee.analysis.figures import search_animation

            write_atomic(
                out_dir / "animation.gif",
                lambda p: search_animation(result, scenario, truth_model, p),
            )
        if run_edits:
            result.summary["edits"] = run_edits
            result.config = {**(result.config or {}), "edits": run_edits}
        result.save(out_dir)  # summary.json last: marks a complete result
        if json_file is not None:
            write_json(json_file, result.summary)
    print_summary(result.summary, out_dir)
