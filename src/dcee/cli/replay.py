"""``dcee replay``: the estimator re-run over a recorded ROS 2 bag."""

from __future__ import annotations

from pathlib import Path

import click

from dcee.cli.options import LIKELIHOOD_OPTION, SET_OPTION, overrides
from dcee.console import compile_notice, print_summary
from dcee.errors import DceeInputError
from dcee.io import check_writable_dir, folder_kept_only_on_success, write_atomic


@click.command(short_help="Re-run the estimator over a recorded ROS 2 bag.")
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

    from dcee.robot.bag import read_events
    from dcee.robot.replay import replay_bag
    from dcee.scenarios import load_scenario
    from dcee.simulation import make_truth

    if seed < 0:
        raise DceeInputError("seed", f"must be >= 0, got {seed}")
    if not (math.isfinite(calibration) and calibration > 0):
        raise DceeInputError("calibration", f"must be a finite number > 0, got {calibration}")
    scenario = load_scenario(scenario_name).with_overrides(
        **{"search.particles": particles, **overrides(likelihood, settings)}
    )
    with folder_kept_only_on_success(out_dir):  # a failed replay leaves no folder
        check_writable_dir(out_dir, "out")
        topics = {"concentration": concentration_topic, "pose": pose_topic, "goal": goal_topic}
        read_events(bag, topics)  # a missing or unreadable bag fails here, before any work
        compile_notice(False)
        result = replay_bag(bag, scenario, seed, topics, calibration)
        (out_dir / "figure.png").unlink(missing_ok=True)
        if not no_figure:
            from dcee.analysis.figures import search_figure

            truth_model = make_truth(scenario, seed)
            write_atomic(
                out_dir / "figure.png", lambda p: search_figure(result, scenario, truth_model, p)
            )
        result.save(out_dir)
    print_summary(result.summary, out_dir)
