"""``dcee-ros-demo``: the search node and a simulated robot talking over ROS 2 topics.

    dcee-ros-demo --scenario lab:upwind --strategy infotaxis --seed 0 --particles 3000 \\
        --json s.json --record bag

runs both nodes (one process, their own ROS context, simulated time on ``/clock``), prints the
usual summary when the budget is spent, optionally writes it as JSON and records every topic
the search exchanges to an MCAP bag that ``dcee replay`` reprocesses. Keep it on this machine
with ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` (the demo sets it unless already set).
"""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path
from typing import Any

import click

from dcee.console import print_summary, run_command
from dcee.errors import DceeInputError

RECORDED = {
    "concentration": "std_msgs/msg/Float32",
    "odom": "nav_msgs/msg/Odometry",
    "goal_pose": "geometry_msgs/msg/PoseStamped",
    "dcee/estimate": "geometry_msgs/msg/PointStamped",
    "dcee/estimate_covariance": "geometry_msgs/msg/PoseWithCovarianceStamped",
}
"""Topics ``--record`` writes, with their types."""


def run_demo(
    scenario_name: str,
    strategy: str,
    seed: int,
    particles: int | None = None,
    record: Path | None = None,
    budget: float | None = None,
    speedup: float = 10.0,
    timeout: float = 600.0,
    domain_id: int | None = None,
    truth: str | None = None,
    likelihood: str | None = None,
) -> dict[str, Any]:
    """Run the search node against the simulated robot until the budget is spent; returns the
    summary (:func:`dcee.runs.metrics.summarise` plus the message counts, the driven
    path and ``records``, the node's per-reading records)."""
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    import rclpy
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from dcee.planning import get as get_planner
    from dcee.robot.bag import BagWriter
    from dcee.ros.node import SearchNode
    from dcee.ros.sim_node import SimRobotNode
    from dcee.runs import search_summary
    from dcee.scenarios import load_scenario, truth_choice

    get_planner(strategy)  # fail fast on a bad name
    scenario = load_scenario(scenario_name).with_overrides(
        **{
            "search.particles": particles,
            "search.budget": budget,
            "truth.model": truth_choice(truth) if truth is not None else None,
            "estimator.likelihood": likelihood,
        }
    )
    if not speedup > 0:
        raise DceeInputError("speedup", f"must be > 0, got {speedup}")
    writer = BagWriter(record) if record is not None else None  # refuses an existing folder
    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=domain_id)
    nodes: list[Any] = []
    executor: Any = None
    try:
        sim = SimRobotNode(scenario, seed, speedup=speedup, context=context)
        search = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("use_sim_time", value=True),
                Parameter("scenario", value=scenario_name),
                Parameter("strategy", value=strategy),
                Parameter("seed", value=seed),
            ],
            true_location=scenario.truth_theta()[:3],
            scenario=scenario,
        )
        nodes = [sim, search]
        counts = dict.fromkeys(RECORDED, 0)
        if writer is not None:
            recorder = rclpy.create_node("dcee_recorder", context=context)
            recorder.set_parameters([Parameter("use_sim_time", value=True)])
            nodes.append(recorder)
            _record_topics(recorder, writer, counts)
        # callbacks one at a time: 3x the throughput of the multi-threaded executor here
        # (Python callbacks share the GIL anyway)
        executor = SingleThreadedExecutor(context=context)
        for node in nodes:
            executor.add_node(node)
        started = time.monotonic()

        # spin() in a thread (3-4x the throughput of spinning in this one, measured) until the
        # search is over or the wall-clock timeout
        def spin() -> None:
            try:
                executor.spin()
            except ExternalShutdownException:  # the context went down: the normal end
                pass

        spinner = threading.Thread(target=spin, daemon=True)
        spinner.start()
        search.done.wait(timeout)
        sim.stop()  # no publication after this: the context can go
        context.try_shutdown()  # ends spin() between callbacks
        spinner.join(timeout=10.0)
        if not search.done.is_set():
            raise DceeInputError("timeout", f"the search did not finish in {timeout:g} s")
        wall = time.monotonic() - started
    finally:
        if executor is not None:
            executor.shutdown(timeout_sec=5.0)
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown(context=context)
        if writer is not None:
            writer.close()
    cycle = search.cycle
    summary = search_summary(
        cycle.records, scenario, strategy, seed, sim.robot.path_length, search.searcher
    )
    summary.update(
        transport="ros2",
        finish_reason=search.finish_reason,
        wall_seconds=wall,
        goals_received=sim.goals,
        dropped_readings=cycle.dropped_readings,
        recorded_messages=counts if writer is not None else {},
        bag=str(record) if record is not None else None,
    )
    summary["records"] = cycle.records
    return summary


def _record_topics(node: Any, writer: Any, counts: dict[str, int]) -> None:
    from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy

    qos = QoSProfile(
        depth=100,
        reliability=QoSReliabilityPolicy.RELIABLE,
        durability=QoSDurabilityPolicy.VOLATILE,
    )
    for topic, msgtype in RECORDED.items():
        writer.add_topic(topic, msgtype)
        module, _, cls = msgtype.replace("/msg/", ".msg.").rpartition(".")
        msg_class = getattr(__import__(module, fromlist=[cls]), cls)

        def on_message(data: bytes, topic: str = topic) -> None:
            writer.write(topic, node.get_clock().now().nanoseconds, data)
            counts[topic] += 1

        node.create_subscription(msg_class, topic, on_message, qos, raw=True)


@click.command()
@click.option("--scenario", "scenario_name", required=True, help="Built-in name or TOML file.")
@click.option("--strategy", default="infotaxis", show_default=True, help="Planner NAME.")
@click.option("--seed", default=0, show_default=True, type=int)
@click.option("--particles", type=int, help="Override search.particles.")
@click.option(
    "--json", "json_file", type=click.Path(dir_okay=False, path_type=Path), help="Summary JSON."
)
@click.option(
    "--record",
    type=click.Path(path_type=Path),
    help="Write the exchanged topics to this new MCAP bag folder (for dcee replay).",
)
@click.option(
    "--speedup",
    default=10.0,
    show_default=True,
    type=float,
    help="Simulated seconds per wall second.",
)
@click.option("--budget", type=float, help="Override search.budget (simulated s).")
@click.option(
    "--truth",
    help="What the simulated robot's sensor sees: isotropic | filament | PATH of a recording.",
)
@click.option(
    "--likelihood",
    type=click.Choice(["paper", "fluctuation"]),
    help="The estimator's reading model (override estimator.likelihood).",
)
@click.option("--timeout", default=600.0, show_default=True, type=float, help="Wall s at most.")
def cli(
    scenario_name: str,
    strategy: str,
    seed: int,
    particles: int | None,
    json_file: Path | None,
    record: Path | None,
    speedup: float,
    budget: float | None,
    truth: str | None,
    likelihood: str | None,
    timeout: float,
) -> None:
    """Search over ROS 2 topics: the dcee node against a simulated unicycle robot."""
    from dcee.io import check_writable_file, write_json

    if seed < 0:
        raise DceeInputError("seed", f"must be >= 0, got {seed}")
    if json_file is not None:
        check_writable_file(json_file, "json")
    if record is not None and record.exists():
        raise DceeInputError("record", f"{record} exists; choose a new bag folder")
    from dcee.allocator import tune_allocator

    tune_allocator()  # this process is the demo's own (see dcee.allocator)
    summary = run_demo(
        scenario_name,
        strategy,
        seed,
        particles,
        record,
        budget,
        speedup,
        timeout,
        truth=truth,
        likelihood=likelihood,
    )
    summary.pop("records")
    if json_file is not None:
        write_json(json_file, summary)
    print_summary(summary, record, where="topics recorded in")


def main(argv: list[str] | None = None) -> None:
    """Entry point: user errors → one line on stderr and exit 2."""
    run_command(cli, "dcee-ros-demo", argv)


__all__ = ["RECORDED", "main", "run_demo"]
