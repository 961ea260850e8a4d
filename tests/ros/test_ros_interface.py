"""The ROS 2 interface by the conventions: the managed node's lifecycle and its start/cancel
services with feedback and result, the parameter file, the package manifests and launch
description, and the simulated-robot demo through all of it with a map and a measured wind.

Runs where rclpy is installed (see test_ros_node.py)."""

from __future__ import annotations

import ast
import json
import os
import time
from pathlib import Path

import numpy as np
import pytest

if os.environ.get("DCEE_REQUIRE_ROS"):
    import rclpy  # noqa: F401
else:
    pytest.importorskip("rclpy")

from dcee.ros.demo import run_demo
from dcee.scenarios import load_scenario

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "ros" / "dcee_ros"
PARAMS = PACKAGE / "config" / "dcee_search.yaml"


def _domain() -> int:
    return 150 + os.getpid() % 50  # 150-199; tests/ros/test_ros_node.py: 100-149


def test_the_manifests_parse_as_colcon_reads_them():
    from catkin_pkg.package import parse_package

    node_pkg = parse_package(str(PACKAGE))
    assert node_pkg.name == "dcee_ros" and node_pkg.get_build_type() == "ament_python"
    deps = {d.name for d in node_pkg.exec_depends}
    assert {"rclpy", "std_srvs", "lifecycle_msgs", "nav_msgs", "diagnostic_msgs"} <= deps
    iface = parse_package(str(ROOT / "ros" / "dcee_interfaces"))
    assert [g.name for g in iface.member_of_groups] == ["rosidl_interface_packages"]
    action = (ROOT / "ros" / "dcee_interfaces" / "action" / "SearchSource.action").read_text()
    sections = [s for s in action.split("\n---\n")]
    assert len(sections) == 3  # goal, result, feedback


def test_the_launch_description_starts_the_managed_node_with_the_parameter_file():
    """launch_ros is not installable from PyPI: the file is checked as far as possible (it
    parses, it launches a LifecycleNode named as the parameter file addresses it)."""
    source = (PACKAGE / "launch" / "dcee_search.launch.py").read_text()
    tree = ast.parse(source)
    calls = {
        n.func.id
        for n in ast.walk(tree)
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)
    }
    assert {"LaunchDescription", "LifecycleNode", "DeclareLaunchArgument"} <= calls
    assert 'name="dcee_search"' in source and "generate_launch_description" in source


def test_the_parameter_file_loads_in_rclpy_and_configures_the_node():
    import rclpy
    from rclpy.parameter import parameter_dict_from_yaml_file

    from dcee.ros.node import SearchNode
    from dcee.ros.parameters import PARAMETERS

    params = parameter_dict_from_yaml_file(str(PARAMS), target_nodes=["dcee_search"])
    assert set(params) == set(PARAMETERS)  # every parameter, none unknown
    context = rclpy.Context()
    # the way dcee-ros-node reads it: --ros-args --params-file
    rclpy.init(
        context=context, args=["--ros-args", "--params-file", str(PARAMS)], domain_id=_domain()
    )
    try:
        node = SearchNode(context=context)
        assert node.get_parameter("strategy").value == "dcee-cl"
        assert node.get_parameter("autostart").value is False
        assert node.searcher is None  # managed: waits for its lifecycle manager
    finally:
        rclpy.try_shutdown(context=context)


def test_lifecycle_and_the_start_cancel_contract():
    """Unconfigured → configure → activate; dcee/start refused before activation, starts a
    search after; dcee/cancel ends it with a result (reason cancelled) on dcee/result; a new
    search starts after it; deactivate pauses; cleanup drops the search."""
    import rclpy
    from lifecycle_msgs.msg import State
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_msgs.msg import String
    from std_srvs.srv import Trigger

    from dcee.ros.node import LATCHED, SearchNode

    context = rclpy.Context()
    rclpy.init(context=context, args=[], domain_id=_domain())
    try:
        node = SearchNode(
            context=context,
            parameter_overrides=[
                Parameter("autostart", value=False),
                Parameter("particles", value=300),
                Parameter("strategy", value="mpc"),
            ],
        )
        client_node = rclpy.create_node("client", context=context)
        start = client_node.create_client(Trigger, "dcee/start")
        cancel = client_node.create_client(Trigger, "dcee/cancel")
        results = []
        client_node.create_subscription(String, "dcee/result", results.append, LATCHED)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        executor.add_node(client_node)

        def call(client):
            assert client.wait_for_service(timeout_sec=10)
            future = client.call_async(Trigger.Request())
            executor.spin_until_future_complete(future, timeout_sec=10)
            return future.result()

        assert node._state_machine.current_state[1] == "unconfigured"
        assert not call(start).success  # not active yet
        node.trigger_configure()
        node.trigger_activate()
        assert node._state_machine.current_state[0] == State.PRIMARY_STATE_ACTIVE
        assert node.searcher is None  # a managed node searches on dcee/start
        reply = call(start)
        assert reply.success and node.searcher is not None
        assert not call(start).success  # one search at a time
        assert call(cancel).success
        deadline = time.monotonic() + 10
        while not results and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
        result = json.loads(results[-1].data)
        assert result["reason"] == "cancelled" and not result["success"]
        assert len(result["mean"]) == 3 and np.array(result["covariance"]).shape == (3, 3)
        assert call(start).success and node.searches_started == 2
        node.trigger_deactivate()
        assert not node.active and not call(start).success
        node.trigger_cleanup()
        assert node.searcher is None
    finally:
        rclpy.try_shutdown(context=context)


def test_demo_runs_the_managed_node_through_its_contract_with_a_map_and_wind(tmp_path):
    """The simulated-robot demo: a mission client configures and activates the node through
    its lifecycle services, sends the obstacles as an occupancy grid on map (the node's own
    scenario has none), and starts the search with dcee/start; the robot publishes wind. The
    search ends with a result, never enters the wall, uses the wind and finds the source."""
    wall = [{"kind": "rectangle", "low": [1.5, 2.3], "high": [1.7, 3.5]}]  # beside the start
    summary = run_demo(
        "lab:upwind",
        "infotaxis",
        seed=0,
        particles=1000,
        budget=200.0,
        speedup=100.0,
        timeout=300.0,
        domain_id=_domain(),
        overrides={"world.obstacles": wall, "anemometer.enabled": True},
    )
    assert summary["lifecycle"] == ["configure", "activate"]
    assert summary["map_applied"] == 1
    assert summary["wind_messages"] > 0 and summary["wind_readings"] > 0
    assert summary["feedback_messages"] == len(summary["records"])
    result = summary["result"]
    assert result is not None and result["success"]
    # the believed wind as a compass bearing: lab:upwind's wind comes from the west (270°)
    assert abs((result["wind_from"] - 270.0 + 180.0) % 360.0 - 180.0) < 20.0
    assert result["wind_speed"] > 0
    assert result["reason"] == summary["finish_reason"]
    sc = load_scenario("lab:upwind").with_overrides(**{"world.obstacles": wall})
    xy = np.array([[r["x"], r["y"]] for r in summary["records"]])
    assert not sc.in_obstacle(xy).any()
    assert summary["records"][-1]["rmse"] < sc.search.acquired_rmse


def test_a_map_on_the_map_topic_makes_the_next_search_s_gas_flow_round_its_walls():
    """A managed node whose scenario can take the wall-aware plume (wind known): a map received
    before dcee/start makes the search's gas flow round the map's walls (``gas_walls``, on by
    default); with ``gas_walls`` false it stays in open terrain."""
    import rclpy
    from nav_msgs.msg import OccupancyGrid
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from std_srvs.srv import Trigger

    from dcee.models.site import Rectangle, SiteMap
    from dcee.models.site_plume import SitePlume
    from dcee.ros.node import LATCHED, SearchNode
    from dcee.scenarios import load_scenario

    scenario = load_scenario("paper:1").with_overrides(
        **{"unknown": "source", "estimator.likelihood": "fluctuation", "search.particles": 300}
    )
    wall = Rectangle((20.0, 30.0), (40.0, 31.0))
    site = SiteMap.from_shapes((0.0, 0.0), (50.0, 50.0), [wall], resolution=0.5)
    msg = OccupancyGrid()
    msg.header.frame_id = "map"
    msg.info.resolution = 0.5
    msg.info.width, msg.info.height = site.shape[1], site.shape[0]
    msg.info.origin.orientation.w = 1.0
    msg.data = [100 if b else 0 for b in site.blocked.ravel()]
    for enabled, expected in ((True, "walls"), (False, "open")):
        context = rclpy.Context()
        rclpy.init(context=context, args=[], domain_id=_domain())
        try:
            node = SearchNode(
                context=context,
                scenario=scenario,
                parameter_overrides=[
                    Parameter("autostart", value=False),
                    Parameter("strategy", value="infotaxis"),
                    Parameter("gas_walls", value=enabled),
                ],
            )
            robot = rclpy.create_node("robot", context=context)
            map_pub = robot.create_publisher(OccupancyGrid, "map", LATCHED)
            start = robot.create_client(Trigger, "dcee/start")
            executor = SingleThreadedExecutor(context=context)
            executor.add_node(node)
            executor.add_node(robot)
            node.trigger_configure()
            node.trigger_activate()
            map_pub.publish(msg)
            deadline = time.monotonic() + 30
            while node.maps_received == 0 and time.monotonic() < deadline:
                executor.spin_once(timeout_sec=0.02)
            assert start.wait_for_service(timeout_sec=10)
            future = start.call_async(Trigger.Request())
            executor.spin_until_future_complete(future, timeout_sec=60)
            assert future.result().success
            assert node.gas_model == expected
            plume = node.searcher.filter.plume
            assert isinstance(plume, SitePlume) == (expected == "walls")
            if expected == "walls":  # the map's wall is a wall for the gas
                assert plume.weights(np.array([[30.0, 30.5]]))[1].sum() == 0
            for n in (node, robot):  # no latched map left for a later test
                n.destroy_node()
        finally:
            rclpy.try_shutdown(context=context)
