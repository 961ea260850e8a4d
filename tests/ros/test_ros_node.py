"""The ROS 2 node, the simulated robot node, bag recording and replay, over real ROS 2 topics.

Runs where rclpy is installed (``bash scripts/setup-ros.sh``; ``scripts/test.sh`` runs this
folder in ``.venv-ros`` with ``DCEE_REQUIRE_ROS=1``, which turns a missing rclpy into a failure
instead of a skip). Each test uses its own ROS context and domain id.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

if os.environ.get("DCEE_REQUIRE_ROS"):
    import rclpy  # noqa: F401  (a missing ROS must fail here, not skip)
else:
    pytest.importorskip("rclpy")

import itertools

from dcee.errors import DceeInputError
from dcee.robot.replay import replay_bag
from dcee.ros.demo import run_demo
from dcee.scenarios import load_scenario


def _domain() -> int:
    return 100 + os.getpid() % 50  # 100-149; test_ros_interface.py: 150-199; the GNSS test 200-229


def test_demo_finds_the_source_over_topics_and_replay_reprocesses_its_bag(tmp_path) -> None:
    bag = tmp_path / "bag"
    summary = run_demo(
        "lab:upwind",
        "infotaxis",
        seed=0,
        particles=1000,
        record=bag,
        budget=120.0,
        speedup=100.0,
        timeout=300.0,
        domain_id=_domain(),
    )
    live = summary["records"]
    assert summary["transport"] == "ros2"
    assert len(live) >= 15  # a move takes about 3.5-6 s with settling and the 1.5 s hold
    # a goal after every reading but the last (or after it too, when the budget ran out on the
    # way there); every goal published reached the robot and the bag
    assert len(live) - 1 <= summary["goals_received"] <= len(live)
    assert summary["recorded_messages"]["goal_pose"] == summary["goals_received"]
    assert summary["plume_acquired"]
    assert live[-1]["rmse"] < live[0]["rmse"]  # the search got somewhere in 120 s
    assert summary["final_time"] <= 120.0

    scenario = load_scenario("lab:upwind").with_overrides(
        **{"search.particles": 1000, "search.budget": 120.0}
    )
    replay = replay_bag(bag, scenario, seed=0)
    rec = replay.records
    # the same cycle on the same messages: the readings at the same places, at about the same
    # times (the node stamps a reading with its clock on arrival, the bag with the recorder's)
    assert len(rec) == len(live)
    dt = np.array([abs(a["time"] - b["time"]) for a, b in zip(live, rec, strict=True)])
    assert np.mean(dt <= 0.051) >= 0.8 and dt.max() <= 0.5
    for a, b in zip(live, rec, strict=True):
        assert math.hypot(a["x"] - b["x"], a["y"] - b["y"]) < 0.02
    assert replay.summary["strategy"] == "replay"


def test_demo_searches_a_gaden_room_over_topics() -> None:
    """The node and the simulated robot on a GADEN simulation folder (its room's scenario, the
    robot reading GADEN's filaments): readings arrive, goals go out, the search closes in."""
    room = Path(__file__).resolve().parents[1] / "data" / "gaden" / "empty-room"
    summary = run_demo(
        str(room),
        "dcee",
        seed=0,
        particles=1000,
        budget=90.0,
        speedup=100.0,
        timeout=300.0,
        domain_id=_domain(),
    )
    live = summary["records"]
    assert summary["transport"] == "ros2" and summary["scenario"] == "gaden:empty-room"
    assert len(live) >= 10 and summary["plume_acquired"]
    assert live[-1]["rmse"] < live[0]["rmse"]


def test_node_refuses_a_bad_pose_type_and_leaves_no_node_behind() -> None:
    """The refusal is one line, and the half-built node is gone from the graph at once, as is a
    node destroyed: left to the garbage collector they were finalised inside a later node's
    set-up, where Fast DDS deadlocked (the garbage collector is held off here, so only an
    explicit destruction passes; SearchNode.destroy_node)."""
    import gc

    import rclpy
    from rclpy.parameter import Parameter

    from dcee.ros.node import SearchNode

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    gc.disable()
    try:
        with pytest.raises(DceeInputError, match="pose_type"):
            SearchNode(
                context=context,
                name="refused_search",
                parameter_overrides=[
                    Parameter("pose_type", value="gps"),
                    Parameter("particles", value=200),
                ],
            )
        done = SearchNode(
            context=context,
            name="destroyed_search",
            parameter_overrides=[Parameter("particles", value=200)],
        )
        done.destroy_node()
        probe = rclpy.create_node("probe", context=context)
        names = probe.get_node_names()
        probe.destroy_node()
    finally:
        gc.enable()
        rclpy.try_shutdown(context=context)
    assert "probe" in names, names
    assert "refused_search" not in names and "destroyed_search" not in names, names


def test_yaw_and_quaternion_round_trip() -> None:
    from geometry_msgs.msg import Quaternion

    from dcee.robot.bag import quaternion_of, yaw_of

    for yaw in np.linspace(-3.1, 3.1, 13):
        x, y, z, w = quaternion_of(yaw)
        assert yaw_of(Quaternion(x=x, y=y, z=z, w=w)) == pytest.approx(yaw)


def test_stamps_round_the_whole_time() -> None:
    from dcee.ros.sim_node import stamp_of

    for t, (sec, ns) in {
        96.99999999999: (97, 0),
        0.05: (0, 50_000_000),
        12.5: (12, 500_000_000),
    }.items():
        s = stamp_of(t)
        assert (s.sec, s.nanosec) == (sec, ns)


def test_node_command_line_errors_are_one_line_exit_2() -> None:
    import subprocess
    import sys
    from pathlib import Path

    exe = Path(sys.executable).parent / "dcee-ros-node"
    for args, field in ((["-p", "pose_type:=gps"], "pose_type"), (["-p", "seed:=abc"], "seed")):
        proc = subprocess.run(
            [str(exe), "--ros-args", *args], capture_output=True, text=True, timeout=60
        )
        assert proc.returncode == 2
        lines = proc.stderr.strip().splitlines()
        assert (
            len(lines) == 1 and lines[0].startswith("dcee-ros-node: error:") and field in lines[0]
        )


def test_a_particle_count_the_robot_cannot_hold_is_refused_at_configure(monkeypatch) -> None:
    from dcee import search_memory
    from dcee.ros.parameters import PARAMETERS, scenario_from_parameters

    monkeypatch.setattr(search_memory, "available_bytes", lambda: 2**30)  # a 1 GiB computer
    scenario_from_parameters({**PARAMETERS, "scenario": "lab:upwind", "particles": 20_000})
    with pytest.raises(DceeInputError, match="1,000,000 particles need about") as exc:
        scenario_from_parameters({**PARAMETERS, "scenario": "lab:upwind", "particles": 10**6})
    assert exc.value.field == "particles"


def test_node_with_pose_with_covariance_input_takes_readings_and_publishes_a_goal() -> None:
    """A robot that reports PoseWithCovarianceStamped (AMCL-style): speeds come from successive
    poses; standing still, it gets a reading after the hold and a goal one step away."""
    import rclpy
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import Float32

    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import LATCHED, RELIABLE

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("pose_type", value="pose_with_covariance"),
                Parameter("pose_topic", value="amcl_pose"),
                Parameter("particles", value=300),
                Parameter("strategy", value="mpc"),
            ],
        )
        robot = rclpy.create_node("robot", context=context)
        pose_pub = robot.create_publisher(PoseWithCovarianceStamped, "amcl_pose", RELIABLE)
        conc_pub = robot.create_publisher(Float32, "concentration", RELIABLE)
        goals = []
        robot.create_subscription(PoseStamped, "goal_pose", goals.append, LATCHED)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(robot)
        start = node.scenario.agent.start
        # from 1 s: a zero stamp means "unstamped" (the node would use its own clock)
        _drive_until(executor, node, pose_pub, conc_pub, goals, 1, 1.0, start,
                     PoseWithCovarianceStamped)  # fmt: skip
        g = goals[0].pose.position
        assert math.hypot(g.x - start[0], g.y - start[1]) == pytest.approx(0.3)
        rec = node.cycle.records[0]
        assert rec["reading"] == 0.0 and rec["time"] >= node.scenario.dwell - 1e-9
    finally:
        rclpy.try_shutdown(context=context)


def test_node_keeps_planning_through_hostile_message_streams() -> None:
    """A robot at rest at each goal, readings at 20 Hz, and between them bursts of hostile
    messages: readings above the sensor's maximum (a glitch reporting 1e9), inf, NaN and
    negative readings; odometry with a NaN position, a NaN orientation, a pose 1 km away and
    a stamp going backwards; plus one unexpected error inside the planner. Fails if the node
    raises out of a callback (spin_once would re-raise it) or stops planning."""
    import time

    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import Float32

    from dcee.robot.cycle import REJECTION_REASONS
    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import LATCHED, RELIABLE
    from dcee.ros.sim_node import stamp_of

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("particles", value=300),
                Parameter("strategy", value="mpc"),
                Parameter("stop_spread", value=0.0),  # plan on; this test is about inputs
            ],
        )
        ask = node.searcher.ask
        failures = {"left": 1}

        def flaky_ask():  # one unexpected error inside a callback
            if failures["left"]:
                failures["left"] -= 1
                raise RuntimeError("planner failure injected by the test")
            return ask()

        node.searcher.ask = flaky_ask
        robot = rclpy.create_node("robot", context=context)
        odom_pub = robot.create_publisher(Odometry, "odom", RELIABLE)
        conc_pub = robot.create_publisher(Float32, "concentration", RELIABLE)
        goals, diagnostics = [], []
        robot.create_subscription(PoseStamped, "goal_pose", goals.append, LATCHED)
        robot.create_subscription(DiagnosticArray, "/diagnostics", diagnostics.append, RELIABLE)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(robot)
        max_reading = node.searcher.filter.sensor.max_reading

        def odom(t: float, x: float, y: float, qw: float = 1.0) -> Odometry:
            msg = Odometry()
            msg.header.stamp = stamp_of(t)
            msg.header.frame_id = "map"
            msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
            msg.pose.pose.orientation.w = qw
            return msg

        here = list(node.scenario.agent.start[:2])
        t, k = 1.0, 0
        deadline = time.monotonic() + 90
        while len(goals) < 12 and time.monotonic() < deadline:
            if goals:  # at rest on the latest goal
                here = [goals[-1].pose.position.x, goals[-1].pose.position.y]
            if k % 10 == 5:  # a burst of hostile messages
                for value in (1e9, 2 * max_reading, math.inf, -math.inf, math.nan, -1.0):
                    conc_pub.publish(Float32(data=float(value)))
                odom_pub.publish(odom(t, math.nan, here[1]))
                odom_pub.publish(odom(t, here[0], here[1], qw=math.nan))
                odom_pub.publish(odom(t, 1000.0, -1000.0))
                odom_pub.publish(odom(t - 10.0, here[0], here[1]))
            conc_pub.publish(Float32(data=0.0))
            odom_pub.publish(odom(t, *here))
            for _ in range(6):
                executor.spin_once(timeout_sec=0.005)
            t += 0.05
            k += 1
        for _ in range(30):  # let the diagnostics timer fire
            executor.spin_once(timeout_sec=0.05)
        assert len(goals) >= 12, f"the node stopped planning after {len(goals)} goals"
        assert not node.done.is_set()
        assert node.callback_errors == 1  # the injected failure: logged, the search went on
        rejected = node.cycle.rejected
        for reason in (
            "reading above max_reading",
            "reading not finite",
            "reading below the noise floor",
            "pose not finite",
            "pose far outside the area",
            "pose stamp went backwards",
        ):
            assert rejected.get(reason, 0) > 0, (reason, rejected)
        assert set(rejected) <= set(REJECTION_REASONS)
        # no impossible value reached the estimator
        readings = [r["reading"] for r in node.cycle.records]
        assert all(0 <= v <= max_reading for v in readings)
        assert diagnostics, "no diagnostics published"
        status = diagnostics[-1].status[0]
        assert status.level == DiagnosticStatus.ERROR  # a callback failed once
        values = {kv.key: kv.value for kv in status.values}
        assert int(values["dropped: reading above max_reading"]) > 0
        assert int(values["readings used"]) == len(node.cycle.records)
    finally:
        rclpy.try_shutdown(context=context)


def test_a_negative_clock_message_does_not_end_the_node_s_spin() -> None:
    """With use_sim_time, rclpy's own /clock callback raises on a negative time ("Seconds value
    must not be negative"), which ends executor.spin() and with it the search.
    spin_through_errors counts and logs it and spins on: the clock follows the next good
    message."""
    import threading
    import time

    import rclpy
    from builtin_interfaces.msg import Time
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from rosgraph_msgs.msg import Clock

    from dcee.ros.launch import spin_through_errors
    from dcee.ros.node import SearchNode

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("use_sim_time", value=True),
                Parameter("particles", value=300),
                Parameter("autostart", value=False),
            ],
        )
        clock_node = rclpy.create_node("clock", context=context)
        clock_pub = clock_node.create_publisher(Clock, "/clock", 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        spinner = threading.Thread(target=spin_through_errors, args=(executor, node), daemon=True)
        spinner.start()

        def publish_until(sec: int, seen) -> None:
            deadline = time.monotonic() + 10
            while not seen() and time.monotonic() < deadline:
                clock_pub.publish(Clock(clock=Time(sec=sec)))
                time.sleep(0.02)

        def clock_at(sec: int):
            return lambda: node.get_clock().now().nanoseconds == sec * 10**9

        publish_until(5, clock_at(5))
        assert clock_at(5)()
        publish_until(-3, lambda: node.callback_errors > 0)
        assert node.callback_errors >= 1
        assert spinner.is_alive(), "the negative /clock ended the node's spin"
        publish_until(7, clock_at(7))
        assert clock_at(7)(), "the node's clock stopped following /clock"
        assert not node.done.is_set()
    finally:
        rclpy.try_shutdown(context=context)
    spinner.join(timeout=10)
    assert not spinner.is_alive(), "spin_through_errors did not end with its context"


def test_node_plans_around_a_map_from_the_map_topic() -> None:
    """A wall arrives on ``map`` (nav_msgs/OccupancyGrid, transient local): every later goal
    and every move to it stays clear of it; a map that does not cover the search area is
    logged and ignored, the node keeps running."""
    import time

    import rclpy
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import OccupancyGrid, Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import Float32

    from dcee.models.site import Rectangle, SiteMap
    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import LATCHED, RELIABLE
    from dcee.ros.sim_node import stamp_of

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("particles", value=300),
                Parameter("strategy", value="mpc"),
                Parameter("stop_spread", value=0.0),
            ],
        )
        robot = rclpy.create_node("robot", context=context)
        map_pub = robot.create_publisher(OccupancyGrid, "map", LATCHED)
        odom_pub = robot.create_publisher(Odometry, "odom", RELIABLE)
        conc_pub = robot.create_publisher(Float32, "concentration", RELIABLE)
        goals = []
        robot.create_subscription(PoseStamped, "goal_pose", goals.append, LATCHED)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(robot)

        def grid(width: float, height: float) -> OccupancyGrid:
            res = 0.05
            wall = Rectangle((0.0, 1.0), (3.0, 1.2))  # across the room below the start
            site = SiteMap.from_shapes((0.0, 0.0), (width, height), [wall], res)
            msg = OccupancyGrid()
            msg.header.frame_id = "map"
            msg.info.resolution = res
            msg.info.width, msg.info.height = site.shape[1], site.shape[0]
            msg.info.origin.orientation.w = 1.0
            msg.data = [100 if b else 0 for b in site.blocked.ravel()]
            return msg

        map_pub.publish(grid(2.0, 2.0))  # too small: logged, ignored
        for _ in range(20):
            executor.spin_once(timeout_sec=0.02)
        assert node.maps_received == 0 and node.callback_errors == 1
        map_pub.publish(grid(4.5, 3.5))
        deadline = time.monotonic() + 30
        while node.maps_received == 0 and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.02)
        assert node.maps_received == 1
        site = node.searcher.agent.site
        assert site is not None and site.is_blocked(np.array([[1.5, 1.1]]))[0]

        here = np.array(node.scenario.agent.start[:2], float)
        t = 1.0
        visited = [here.copy()]
        deadline = time.monotonic() + 60
        while len(goals) < 25 and time.monotonic() < deadline:
            if goals:
                here = np.array([goals[-1].pose.position.x, goals[-1].pose.position.y])
                if not np.allclose(here, visited[-1]):
                    visited.append(here.copy())
            msg = Odometry()
            msg.header.stamp = stamp_of(t)
            msg.pose.pose.position.x, msg.pose.pose.position.y = float(here[0]), float(here[1])
            msg.pose.pose.orientation.w = 1.0
            conc_pub.publish(Float32(data=0.0))
            odom_pub.publish(msg)
            for _ in range(4):
                executor.spin_once(timeout_sec=0.005)
            t += 0.1
        assert len(goals) >= 25
        pts = np.array(visited)
        assert not site.is_blocked(pts).any()
        for a, b in itertools.pairwise(pts):
            assert site.segment_clear(a, b[None])[0]
    finally:
        rclpy.try_shutdown(context=context)


def test_node_takes_wind_from_the_wind_topic() -> None:
    """Vector3Stamped wind samples at 20 Hz become anemometer readings (one per period) when
    the scenario's [anemometer] is enabled; without it they are ignored, never fatal."""
    import time

    import rclpy
    from geometry_msgs.msg import Vector3Stamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import RELIABLE
    from dcee.ros.sim_node import stamp_of

    for enabled in (True, False):
        context = rclpy.Context()
        rclpy.init(context=context, args=[], domain_id=_domain())
        try:
            sc = load_scenario("lab:upwind").with_overrides(
                **{"anemometer.enabled": enabled, "search.particles": 300}
            )
            node = SearchNode(
                context=context,
                scenario=sc,
                parameter_overrides=[Parameter("strategy", value="mpc")],
            )
            robot = rclpy.create_node("robot", context=context)
            wind_pub = robot.create_publisher(Vector3Stamped, "wind", RELIABLE)
            executor = SingleThreadedExecutor(context=context)
            executor.add_node(node)
            executor.add_node(robot)
            t = 1.0
            deadline = time.monotonic() + 20
            while t < 4.0 and time.monotonic() < deadline:
                msg = Vector3Stamped()
                msg.header.stamp = stamp_of(t)
                msg.header.frame_id = "map"
                msg.vector.x, msg.vector.y = 1.5, 0.0  # air moving east: wind from phi = pi
                wind_pub.publish(msg)
                for _ in range(3):
                    executor.spin_once(timeout_sec=0.005)
                t += 0.05
            for _ in range(20):
                executor.spin_once(timeout_sec=0.01)
            if enabled:
                assert node.cycle.wind_readings >= 2
                assert node.searcher.filter.wind.n == node.cycle.wind_readings
            else:
                assert node.cycle.wind_readings == 0 and node.callback_errors == 0
        finally:
            rclpy.try_shutdown(context=context)


def test_the_node_filter_has_the_outlier_safety() -> None:
    """Issue 43: the node builds its filter with the same outlier safety as every other entry
    point (tests/test_robust_estimation.py): one 10⁶ × reading leaves most of the weight."""
    import rclpy
    from rclpy.parameter import Parameter
    from tests.helpers import spike_ess_share

    from dcee.models.sensor import OUTLIER_DEFAULT
    from dcee.ros.node import SearchNode

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("scenario", value="paper:1"),  # the zigzag of spike_ess_share's
                Parameter("particles", value=2000),
            ],
        )
        assert node.scenario.name == "paper:1"
        assert node.searcher.filter.sensor.outlier == OUTLIER_DEFAULT
        assert spike_ess_share(node.searcher.filter, node.scenario) > 0.5
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def test_node_resumes_its_own_checkpoint_and_refuses_a_tampered_or_foreign_one(tmp_path) -> None:
    """The ``checkpoint`` parameter: the node's own file resumes the search; a file with one byte
    changed, or saved under other settings, starts no search: ERROR in the diagnostics, the
    reason logged, dcee/start refused while the file is there (issue 80)."""
    import rclpy
    from diagnostic_msgs.msg import DiagnosticStatus
    from rclpy.parameter import Parameter
    from std_srvs.srv import Trigger

    from dcee.ros.node import SearchNode

    path = tmp_path / "search.ckpt"
    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())

    def node(particles: int = 300) -> SearchNode:
        return SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("particles", value=particles),
                Parameter("checkpoint", value=str(path)),
            ],
        )

    try:
        first = node()
        assert first.searcher is not None and first.checkpoint_error == ""
        first.searcher.tell(np.array(first.scenario.agent.start), 0.0, time=1.0)
        first.searcher.save(path)
        resumed = node()
        assert resumed.searcher is not None and resumed.searcher.checkpoint_code is not None
        assert resumed.searcher.filter.n_readings == 1
        assert resumed.diagnostics().level == DiagnosticStatus.OK

        foreign = node(particles=400)  # the same scenario name, other settings
        assert foreign.searcher is None and "with other settings" in foreign.checkpoint_error
        status = foreign.diagnostics()
        assert status.level == DiagnosticStatus.ERROR and "checkpoint refused" in status.message

        data = path.read_bytes()
        path.write_bytes(data[:1000] + bytes([data[1000] ^ 1]) + data[1001:])
        tampered = node()
        assert tampered.searcher is None and "digest does not match" in tampered.checkpoint_error
        answer = tampered._on_start(Trigger.Request(), Trigger.Response())
        assert not answer.success and "digest" in answer.message
        path.unlink()  # the operator removes the file: a fresh search starts
        answer = tampered._on_start(Trigger.Request(), Trigger.Response())
        assert answer.success and tampered.searcher is not None
    finally:
        rclpy.try_shutdown(context=context)


def _drive_until(executor, node, pose_pub, conc_pub, goals, count, t0, start, kind=None) -> float:
    """Publish a robot's pose (``kind``: nav_msgs/Odometry unless given; at ``start``, then
    standing at the latest goal: it gets there at once) and zero readings until ``count``
    goals arrived; returns the next stamp."""
    import time

    from nav_msgs.msg import Odometry
    from std_msgs.msg import Float32

    from dcee.ros.sim_node import stamp_of

    t, deadline = t0, time.monotonic() + 60
    while len(goals) < count and time.monotonic() < deadline:
        msg = (kind or Odometry)()
        msg.header.stamp = stamp_of(t)
        msg.header.frame_id = "map"
        at = (goals[-1].pose.position.x, goals[-1].pose.position.y) if goals else start[:2]
        msg.pose.pose.position.x, msg.pose.pose.position.y = at[0], at[1]
        msg.pose.pose.orientation.w = 1.0
        conc_pub.publish(Float32(data=0.0))
        pose_pub.publish(msg)
        for _ in range(4):
            executor.spin_once(timeout_sec=0.01)
        t += 0.1
    assert len(goals) >= count, f"{len(goals)} goals of {count}"
    return t


def test_a_full_disk_costs_the_checkpoint_not_the_search_and_a_restart_resumes(tmp_path) -> None:
    """Checkpoints that cannot be written (the disk full, then read-only): the goal is still
    published, the failure counted, logged and WARN in the diagnostics, the search goes on. The
    node killed and started again on the same file resumes with every reading written and goes
    on (issue 80)."""
    import rclpy
    from diagnostic_msgs.msg import DiagnosticStatus
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import Float32

    import dcee.searcher
    from dcee.errors import DceeInputError
    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import LATCHED, RELIABLE

    path = tmp_path / "search.ckpt"
    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    real_save = dcee.searcher.Searcher.save

    def full_disk(self, p):
        raise DceeInputError("path", f"cannot write checkpoint {p}: [Errno 28] No space left")

    def node() -> SearchNode:
        return SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("particles", value=300),
                Parameter("strategy", value="mpc"),
                Parameter("checkpoint", value=str(path)),
            ],
        )

    try:
        dcee.searcher.Searcher.save = full_disk
        first = node()
        robot = rclpy.create_node("robot", context=context)
        pose_pub = robot.create_publisher(Odometry, "odom", RELIABLE)
        conc_pub = robot.create_publisher(Float32, "concentration", RELIABLE)
        goals: list = []
        robot.create_subscription(PoseStamped, "goal_pose", goals.append, LATCHED)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(first)
        executor.add_node(robot)
        start = first.scenario.agent.start
        t = _drive_until(executor, first, pose_pub, conc_pub, goals, 2, 1.0, start)
        assert first.checkpoint_failures >= 2 and not path.exists()
        status = first.diagnostics()
        assert status.level == DiagnosticStatus.WARN and "No space left" in status.message
        assert first.callback_errors == 0 and first.cycle.state != "done"

        def read_only(self, p):
            raise DceeInputError("path", f"cannot write checkpoint {p}: [Errno 30] Read-only")

        dcee.searcher.Searcher.save = read_only  # then mounted read-only: the same
        failures = first.checkpoint_failures
        t = _drive_until(executor, first, pose_pub, conc_pub, goals, 3, t, start)
        assert first.checkpoint_failures > failures and "Read-only" in first.checkpoint_failure
        assert first.callback_errors == 0 and not path.exists()

        dcee.searcher.Searcher.save = real_save  # writable again: the next reading is written
        t = _drive_until(executor, first, pose_pub, conc_pub, goals, 4, t, start)
        assert path.exists() and first.checkpoint_failure == ""
        written = first.searcher.filter.n_readings
        executor.remove_node(first)
        first.destroy_node()  # killed: only the file is left

        goals.clear()
        second = node()
        executor.add_node(second)
        assert second.searcher.filter.n_readings == written
        _drive_until(executor, second, pose_pub, conc_pub, goals, 2, t, start)
        assert second.searcher.filter.n_readings > written
        assert second.callback_errors == 0
    finally:
        dcee.searcher.Searcher.save = real_save
        rclpy.try_shutdown(context=context)


def test_the_path_message_keeps_the_last_readings_only() -> None:
    """``dcee/path`` holds the last PATH_POSES readings: on a day's mission the whole path made
    each reading's messages cost more than the last (the soak benchmark, issue 80)."""
    import rclpy
    from rclpy.parameter import Parameter

    from dcee.ros.node import SearchNode
    from dcee.ros.outputs import PATH_POSES

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(context=context, parameter_overrides=[Parameter("particles", value=200)])
        node.params["marker_particles"] = 0
        for k in range(PATH_POSES + 5):
            node._publish_belief({"x": float(k), "y": 1.0, "z": 0.0})
        poses = node.path_msg.poses
        assert len(poses) == PATH_POSES and poses[-1].pose.position.x == PATH_POSES + 4
        assert poses[0].pose.position.x == 5.0
    finally:
        rclpy.try_shutdown(context=context)


def test_node_on_a_map_takes_gnss_fixes_and_publishes_the_estimate_in_degrees() -> None:
    """A robot that reports sensor_msgs/NavSatFix (``pose_type:=navsatfix``) on the example
    site on a map: its fixes are placed in the site's frame, it gets goals one step away, and
    the estimate comes back in degrees (``dcee/estimate_fix``) where ``dcee/estimate`` puts it
    in metres (issue 81). Without a map the parameter is refused."""
    import time

    import rclpy
    from geometry_msgs.msg import PointStamped, PoseStamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import NavSatFix
    from std_msgs.msg import Float32

    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import LATCHED, RELIABLE
    from dcee.ros.sim_node import stamp_of

    context = rclpy.Context()
    # a domain of its own: a goal latched by an earlier test's node may still be discovered on
    # the shared one (its first goal then is not this node's)
    rclpy.init(context=context, args=[], domain_id=200 + os.getpid() % 30)
    try:
        # the geography, not the gas: the open plume (the site's default, the wall-aware one,
        # solves the site's flow first: seconds a decision at this test's pace)
        site = load_scenario("area:example-works").with_overrides(**{"estimator.plume": "open"})
        node = SearchNode(
            context=context,
            scenario=site,
            parameter_overrides=[
                Parameter("pose_type", value="navsatfix"),
                Parameter("pose_topic", value="fix"),
                Parameter("particles", value=500),
                Parameter("strategy", value="infotaxis"),
            ],
        )
        frame = node.scenario.world.frame.local_frame()
        robot = rclpy.create_node("robot", context=context)
        fix_pub = robot.create_publisher(NavSatFix, "fix", RELIABLE)
        conc_pub = robot.create_publisher(Float32, "concentration", RELIABLE)
        goals, fixes, points = [], [], []
        robot.create_subscription(PoseStamped, "goal_pose", goals.append, LATCHED)
        robot.create_subscription(NavSatFix, "dcee/estimate_fix", fixes.append, RELIABLE)
        robot.create_subscription(PointStamped, "dcee/estimate", points.append, RELIABLE)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(robot)
        start = node.scenario.agent.start
        t, deadline = 1.0, time.monotonic() + 60
        while len(goals) < 2 and time.monotonic() < deadline:
            at = (goals[-1].pose.position.x, goals[-1].pose.position.y) if goals else start[:2]
            lon, lat = frame.to_geo(np.array([at[0]]), np.array([at[1]]))
            msg = NavSatFix()
            msg.header.stamp = stamp_of(t)
            msg.latitude, msg.longitude, msg.altitude = float(lat[0]), float(lon[0]), math.nan
            conc_pub.publish(Float32(data=0.0))
            fix_pub.publish(msg)
            for _ in range(4):
                executor.spin_once(timeout_sec=0.01)
            t += 0.1
        for _ in range(20):
            executor.spin_once(timeout_sec=0.01)
        assert len(goals) >= 2, f"{len(goals)} goals"
        rec = node.cycle.records[0]
        assert math.hypot(rec["x"] - start[0], rec["y"] - start[1]) < 1e-6
        g = goals[0].pose.position
        assert math.hypot(g.x - start[0], g.y - start[1]) == pytest.approx(node.scenario.agent.step)
        assert fixes and points
        x, y = frame.to_local(np.array([fixes[-1].longitude]), np.array([fixes[-1].latitude]))
        assert math.hypot(x[0] - points[-1].point.x, y[0] - points[-1].point.y) < 1e-3
        assert fixes[-1].position_covariance_type == NavSatFix.COVARIANCE_TYPE_KNOWN
    finally:
        rclpy.try_shutdown(context=context)
    with pytest.raises(DceeInputError, match="pose_type: GNSS fixes"):
        from dcee.ros.parameters import PARAMETERS, scenario_from_parameters

        scenario_from_parameters({**PARAMETERS, "pose_type": "navsatfix"}, None)
