"""``dcee-ros-demo``: the search node and a simulated robot talking over ROS 2 topics.

    dcee-ros-demo --scenario lab:upwind --strategy infotaxis --seed 0 --particles 3000 \\
        --json s.json --record bag

runs both nodes (one process, their own ROS context, simulated time on ``/clock``) the way a
robot's software would: the search node is a managed node that a mission client configures
and activates through its lifecycle services, sends the scenario's obstacles as an occupancy
grid on ``map``, and starts through ``dcee/start``; the simulated robot publishes odometry,
readings and (with ``[anemometer]``) the wind. It prints the usual summary when the search
ends (source localised or budget spent), optionally writes it as JSON and records every topic
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
    overrides: dict[str, Any] | None = None,
    checkpoint: Path | None = None,
    observer: Any = None,
) -> dict[str, Any]:
    """Run the search node against the simulated robot until the budget is spent; returns the
    summary (:func:`dcee.runs.metrics.summarise` plus the message counts, the driven
    path and ``records``, the node's per-reading records). ``checkpoint``: the node's
    ``checkpoint`` parameter (written after every reading, resumed from when it exists);
    ``observer(search_node, sim_node, context)``: called once both nodes exist, before the
    search starts (the soak benchmark samples and injects faults from it)."""
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
            **(overrides or {}),
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
        # the robot's clock starts when the search does (the mission's dcee/start)
        sim = SimRobotNode(scenario, seed, speedup=speedup, context=context, paused=True)
        # the node learns the obstacles from the map topic, not from its scenario
        search = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("use_sim_time", value=True),
                Parameter("scenario", value=scenario_name),
                Parameter("strategy", value=strategy),
                Parameter("seed", value=seed),
                Parameter("autostart", value=False),
                Parameter("checkpoint", value=str(checkpoint) if checkpoint else ""),
            ],
            true_location=scenario.truth_theta()[:3],
            scenario=scenario.with_overrides(world={}),
        )
        mission = Mission(context, search.get_name(), scenario)
        nodes = [sim, search, mission.node]
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
            except Exception:
                # the context went down between two waits: building the next wait set then
                # fails (RCLError "the given context is not valid"), the same normal end (seen
                # under load in CI); anything raised while the context is up is a real error
                if context.ok():
                    raise

        spinner = threading.Thread(target=spin, daemon=True)
        if observer is not None:
            observer(search, sim, context)
        spinner.start()
        mission.start(timeout=min(timeout, 60.0))  # configure, activate, map, dcee/start
        sim.paused = False
        search.done.wait(timeout)
        mission.wait_for_result(timeout=10.0)
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
        lifecycle=mission.transitions,
        map_applied=search.maps_received,
        wind_readings=cycle.wind_readings,
        wind_messages=sim.wind_messages,
        feedback_messages=mission.feedback,
        result=mission.result,
        wall_seconds=wall,
        goals_received=sim.goals,
        dropped_readings=cycle.dropped_readings,
        recorded_messages=counts if writer is not None else {},
        bag=str(record) if record is not None else None,
    )
    summary["records"] = cycle.records
    return summary


class Mission:
    """What a robot's mission software does with the search node, over ROS: configure and
    activate it through its lifecycle services (``<node>/change_state``), publish the site's
    obstacles on ``map`` (latched), start a search with ``dcee/start``, count the
    ``dcee/feedback`` messages and keep the ``dcee/result``."""

    def __init__(self, context: Any, target: str, scenario: Any) -> None:
        import rclpy
        from lifecycle_msgs.srv import ChangeState
        from nav_msgs.msg import OccupancyGrid
        from std_msgs.msg import String
        from std_srvs.srv import Trigger

        from dcee.ros.parameters import LATCHED, RELIABLE

        self.node = rclpy.create_node("dcee_mission", context=context)
        self.scenario = scenario
        self.change_state = self.node.create_client(ChangeState, f"{target}/change_state")
        self.start_search = self.node.create_client(Trigger, "dcee/start")
        self.map_pub = self.node.create_publisher(OccupancyGrid, "map", LATCHED)
        self.transitions: list[str] = []
        self.feedback = 0
        self.result: dict[str, Any] | None = None
        self._result_event = threading.Event()
        self.node.create_subscription(String, "dcee/feedback", self._on_feedback, RELIABLE)
        self.node.create_subscription(String, "dcee/result", self._on_result, LATCHED)

    def _on_feedback(self, msg: Any) -> None:
        self.feedback += 1

    def _on_result(self, msg: Any) -> None:
        import json

        self.result = json.loads(msg.data)
        self._result_event.set()

    def _call(self, client: Any, request: Any, timeout: float) -> Any:
        if not client.wait_for_service(timeout_sec=timeout):
            raise DceeInputError("ros", f"service {client.srv_name} is not available")
        future = client.call_async(request)
        deadline = time.monotonic() + timeout
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.01)
        if not future.done():
            raise DceeInputError("ros", f"service {client.srv_name} did not answer")
        return future.result()

    def start(self, timeout: float) -> None:
        from lifecycle_msgs.msg import Transition
        from lifecycle_msgs.srv import ChangeState
        from std_srvs.srv import Trigger

        for label, tid in (
            ("configure", Transition.TRANSITION_CONFIGURE),
            ("activate", Transition.TRANSITION_ACTIVATE),
        ):
            reply = self._call(
                self.change_state, ChangeState.Request(transition=Transition(id=tid)), timeout
            )
            if not reply.success:
                raise DceeInputError("ros", f"the search node refused to {label}")
            self.transitions.append(label)
        site = self.scenario.make_site()
        if site is not None:
            self.map_pub.publish(occupancy_grid(site))
            time.sleep(0.2)  # latched: the node has it before the first decision
        reply = self._call(self.start_search, Trigger.Request(), timeout)
        if not reply.success:
            raise DceeInputError("ros", f"dcee/start: {reply.message}")

    def wait_for_result(self, timeout: float) -> None:
        self._result_event.wait(timeout)


def occupancy_grid(site: Any, frame_id: str = "map") -> Any:
    """A :class:`~dcee.models.site.SiteMap` as a nav_msgs/OccupancyGrid (100 blocked, 0 free)."""
    from nav_msgs.msg import OccupancyGrid

    msg = OccupancyGrid()
    msg.header.frame_id = frame_id
    msg.info.resolution = float(site.resolution)
    msg.info.height, msg.info.width = (int(v) for v in site.shape)
    msg.info.origin.position.x, msg.info.origin.position.y = (float(v) for v in site.origin)
    msg.info.origin.orientation.w = 1.0
    msg.data = [100 if b else 0 for b in site.blocked.ravel()]
    return msg


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
@click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="PATH=VALUE",
    help="Override any scenario setting (repeatable; VALUE is TOML), e.g. "
    "--set anemometer.enabled=true.",
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
    settings: tuple[str, ...],
    timeout: float,
) -> None:
    """Search over ROS 2 topics: the dcee node against a simulated unicycle robot."""
    from dcee.io import check_writable_file, write_json
    from dcee.scenarios.files import parse_setting

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
        overrides=dict(parse_setting(s) for s in settings),
    )
    summary.pop("records")
    if json_file is not None:
        write_json(json_file, summary)
    print_summary(summary, record, where="topics recorded in")


def main(argv: list[str] | None = None) -> None:
    """Entry point: user errors → one line on stderr and exit 2."""
    run_command(cli, "dcee-ros-demo", argv)


__all__ = ["RECORDED", "Mission", "main", "occupancy_grid", "run_demo"]
