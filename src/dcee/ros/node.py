"""The dcee ROS 2 node (``dcee-ros-node``): the search cycle of :mod:`dcee.robot.cycle` on topics.

Subscribes
    ``concentration`` (std_msgs/Float32, sensor units × ``calibration`` = g/m³), stamped on
    arrival with the node's clock (set ``use_sim_time`` to follow ``/clock``);
    ``odom`` (nav_msgs/Odometry; or geometry_msgs/PoseWithCovarianceStamped with
    ``pose_type:=pose_with_covariance``, speeds then from successive poses; or GNSS fixes,
    sensor_msgs/NavSatFix with ``pose_type:=navsatfix`` on a scenario on a map, placed in its
    frame, :mod:`dcee.robot.gps`);
    ``wind`` (geometry_msgs/Vector3Stamped, the air's velocity in m/s in the map frame, from
    the robot's anemometer; averaged over ``anemometer.period`` s into one reading; used when
    the scenario's ``[anemometer]`` is enabled, else ignored with one warning);
    ``map`` (nav_msgs/OccupancyGrid, transient local as Nav2's map server publishes it):
    occupied and unknown cells become obstacles for every later decision, on top of the
    scenario's own ``[world]`` (:func:`dcee.models.site.compose_site`).
Publishes
    ``goal_pose`` (geometry_msgs/PoseStamped, what Nav2's bt_navigator accepts; its
    orientation faces the move), ``dcee/estimate`` (geometry_msgs/PointStamped, posterior mean
    of the source), ``dcee/estimate_covariance`` (geometry_msgs/PoseWithCovarianceStamped, the
    same mean with the 3 × 3 location covariance in the position block), on a scenario on a map
    ``dcee/estimate_fix`` (sensor_msgs/NavSatFix: the mean's latitude and longitude with the
    covariance), ``dcee/particles``
    (visualization_msgs/MarkerArray, a weighted sample of source hypotheses), ``dcee/path``
    (nav_msgs/Path, where the readings were taken), ``/diagnostics``
    (diagnostic_msgs/DiagnosticArray, once a second: the search's state, readings used and every
    input message dropped, by reason).
Inputs are validated (:meth:`dcee.robot.cycle.SearchCycle.reading_problem`, ``pose_problem``):
    an impossible reading or pose is dropped, counted and reported (a throttled warning and
    the diagnostics) and never reaches the estimator; an unexpected error inside a callback
    is logged and the search continues, and after :data:`MAX_CONSECUTIVE_ERRORS` in a row it
    ends cleanly with its estimate (``finish_reason`` "error"). The node never exits because
    of its inputs.
Parameters
    :data:`dcee.ros.parameters.PARAMETERS` (names, defaults and what each does).

Conventions (docs/guide/robot.md): frames are REP-103 ENU (x east, y north, yaw
counter-clockwise from +x); dcee's wind direction φ is the direction the wind comes *from*,
counter-clockwise from +x (meteorological direction = 90° − φ, clockwise from north);
concentrations are g/m³.
"""

from __future__ import annotations

import collections
import dataclasses
import functools
import json
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import (
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    Vector3Stamped,
)
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.msg import Path as PathMsg
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.parameter import Parameter
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import Float32, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import MarkerArray

from dcee.errors import DceeInputError
from dcee.robot.cycle import Pose, SearchCycle
from dcee.robot.map_gas import MapGas
from dcee.ros.inputs import NodeInputs
from dcee.ros.outputs import NodeOutputs
from dcee.ros.parameters import (
    LATCHED,
    MAX_CONSECUTIVE_ERRORS,
    PARAMETERS,
    RELIABLE,
    cycle_settings,
    new_searcher,
    scenario_from_parameters,
)
from dcee.runs import scenario_key
from dcee.scenarios import Scenario
from dcee.searcher import Searcher


class SearchNode(NodeInputs, NodeOutputs, LifecycleNode):
    """The search cycle as a managed (lifecycle) ROS 2 node.

    Lifecycle: *configure* reads the parameters and the scenario (a bad value fails the
    transition with a one-line log); *activate* starts processing inputs; *deactivate* pauses
    the search (inputs are ignored, nothing is published); *cleanup* drops it. With
    ``autostart`` (the default) the node configures and activates itself at start and
    searches at once, as a node without a lifecycle manager; with ``-p autostart:=false`` a
    lifecycle manager (Nav2's ``lifecycle_manager``, ``ros2 lifecycle set``) drives it and a
    search starts on ``dcee/start``.

    The search contract, the service-and-topic form of ``action/SearchSource.action``:
    ``dcee/start`` (std_srvs/Trigger) begins a new search with a fresh belief once the last
    one is over; ``dcee/cancel`` (Trigger) ends the running one; ``dcee/feedback``
    (std_msgs/String, JSON: state, readings, mean, spread, elapsed) after every reading;
    ``dcee/result`` (std_msgs/String, JSON, latched: success, reason, mean, covariance,
    spread, readings, wind_from as a compass bearing, wind_speed) when a search ends. The area
    and budget are the scenario's.

    ``true_location`` (3,) m, when known (a simulation), gives the records an RMSE;
    ``scenario`` (a :class:`~dcee.scenarios.Scenario`) replaces the ``scenario`` and
    ``particles`` parameters when the node is built from Python. :attr:`done` is set when a
    search is over: the budget is spent, the source localised (the scenario's stop rule, on by
    default on a robot: ``search.stop_spread``), it was cancelled or failed
    (:attr:`finish_reason` says which)."""

    def __init__(
        self,
        *,
        context: Any = None,
        parameter_overrides: list[Parameter] | None = None,
        true_location: np.ndarray | None = None,
        scenario: Scenario | None = None,
        name: str = "dcee_search",
    ) -> None:
        super().__init__(name, context=context, parameter_overrides=parameter_overrides or [])
        try:
            self._set_up(true_location, scenario)
        except BaseException:
            # a node that refuses its configuration releases its DDS entities now, not when
            # the garbage collector gets to it (destroy_node says why)
            self.destroy_node()
            raise

    def destroy_node(self) -> None:
        """Destroy the node now, its lifecycle state machine with it. rclpy's ``LifecycleNode``
        (9.1) only marks its ROS 2 node for destruction while the state machine still holds the
        node's handle, so the node stayed in the graph until the garbage collector finalised the
        state machine, at a random moment: once inside another node's set-up in the same
        process, where Fast DDS deadlocked (the ROS 2 tests hung, 2026-12-05)."""
        super().destroy_node()
        machine = getattr(self, "_state_machine", None)
        if machine is not None and hasattr(machine, "destroy_when_not_in_use"):
            machine.destroy_when_not_in_use()

    def _set_up(self, true_location: np.ndarray | None, scenario: Scenario | None) -> None:
        """Everything the constructor does after the ROS 2 node exists (see ``__init__``)."""
        for key, default in PARAMETERS.items():
            if not self.has_parameter(key):
                self.declare_parameter(key, default)
        self._true_location = true_location
        self._given_scenario = scenario
        self.searcher: Searcher | None = None
        self.cycle: SearchCycle | None = None
        self.active = False
        """inputs are processed and outputs published only while active"""
        self.done = threading.Event()
        self.finish_reason = ""
        """why the last search ended: "budget", "localised" (the stop rule), "cancelled" or
        "error" (:data:`MAX_CONSECUTIVE_ERRORS` unexpected callback errors in a row)"""
        self.searches_started = 0
        self.callback_errors = 0
        """unexpected errors caught inside callbacks (each logged; the search went on)"""
        self.maps_received = 0
        """occupancy grids applied from the ``map`` topic"""
        self.configure_error: str | None = None
        """why the last configure transition failed (one line)"""
        self.checkpoint_error = ""
        """why the checkpoint file was refused (one line; empty once a search started)"""
        self.checkpoint_failures = 0
        """checkpoints that could not be written (a full or read-only disk)"""
        self.checkpoint_failure = ""
        """why the last checkpoint could not be written (empty once one was)"""
        self.step_latency: collections.deque[tuple[float, float]] = collections.deque(maxlen=1000)
        """(pose time s, wall s) of the last 1,000 goals: from the pose that completed a hold
        to the goal's publication (the reading's update, the decision, the messages)"""
        self._errors_in_a_row = 0
        self._rejected_reported = 0
        self._wind_warned = False
        self._lock = threading.Lock()
        self._last_pose: Pose | None = None
        self._map_site: Any = None
        self.map_gas = MapGas()
        self.gas_model = "open"
        """the current search's ``estimator.plume``: "walls" once a map made the gas flow
        round its walls (parameter ``gas_walls``)"""
        self.create_service(Trigger, "dcee/start", self._on_start)
        self.create_service(Trigger, "dcee/cancel", self._on_cancel)
        self._autostarting = bool(self.get_parameter("autostart").value)
        if self._autostarting:
            self.trigger_configure()  # a failure raises below: one line, no log
            if self.configure_error is not None:
                raise DceeInputError(*self.configure_error.split(": ", 1))
            self.trigger_activate()
        self._autostarting = False

    # --- lifecycle ------------------------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            self._configure()
        except DceeInputError as exc:
            self.configure_error = f"{exc.field}: {exc.message}"
            if not self._autostarting:
                self.get_logger().error(f"cannot configure: {self.configure_error}")
            return TransitionCallbackReturn.FAILURE
        self.configure_error = None
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = True
        if self._autostarting and self.searches_started == 0:
            self._new_search()  # a node on its own searches at once; a managed one on dcee/start
        return super().on_activate(state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        return super().on_deactivate(state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        self.searcher = self.cycle = None
        self.searches_started = 0
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.cycle is not None and not self.done.is_set():
            self._finish("cancelled")
        self.active = False
        return TransitionCallbackReturn.SUCCESS

    def _configure(self) -> None:
        """Read the parameters and the scenario, create the publishers and subscriptions."""
        p = {key: self.get_parameter(key).value for key in PARAMETERS}
        self.params = p
        scenario = scenario_from_parameters(p, self._given_scenario)
        self.settings = cycle_settings(p, scenario)
        self.scenario = scenario
        self.frame_id = str(p["frame_id"])
        checkpoint = str(p["checkpoint"])
        self.checkpoint = Path(checkpoint) if checkpoint else None
        self._marker_rng = np.random.default_rng(int(p["seed"]) + 1)
        if getattr(self, "goal_pub", None) is not None:
            return  # reconfigured after a cleanup: the topics are already there
        self.goal_pub = self.create_publisher(PoseStamped, str(p["goal_topic"]), LATCHED)
        self.estimate_pub = self.create_publisher(PointStamped, "dcee/estimate", RELIABLE)
        self.cov_pub = self.create_publisher(
            PoseWithCovarianceStamped, "dcee/estimate_covariance", RELIABLE
        )
        self.particles_pub = self.create_publisher(MarkerArray, "dcee/particles", RELIABLE)
        self.path_pub = self.create_publisher(PathMsg, "dcee/path", RELIABLE)
        self.feedback_pub = self.create_publisher(String, "dcee/feedback", RELIABLE)
        self.result_pub = self.create_publisher(String, "dcee/result", LATCHED)
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, "/diagnostics", RELIABLE)
        self.create_timer(1.0, lambda: self._guarded("diagnostics", self._publish_diagnostics))
        self.map_frame = (
            None if scenario.world.frame is None else scenario.world.frame.local_frame()
        )
        self.fix_pub = None if self.map_frame is None else self.create_publisher(
            NavSatFix, "dcee/estimate_fix", RELIABLE
        )  # fmt: skip
        pose_input = {
            "odometry": (Odometry, "odometry", self._odometry),
            "pose_with_covariance": (PoseWithCovarianceStamped, "pose", self._pose_cov),
            "navsatfix": (NavSatFix, "fix", self._fix),
        }[p["pose_type"]]
        inputs = (
            (Float32, "concentration_topic", "concentration", self._reading, RELIABLE),
            (OccupancyGrid, "map_topic", "map", self._map, LATCHED),
            (Vector3Stamped, "wind_topic", "wind", self._wind, RELIABLE),
            (pose_input[0], "pose_topic", pose_input[1], pose_input[2], RELIABLE),
        )  # fmt: skip
        for kind, topic, what, handler, qos in inputs:  # every callback guarded (_guarded)
            callback = functools.partial(self._guarded, what, handler)
            self.create_subscription(kind, str(p[topic]), callback, qos)

    def _new_search(self) -> bool:
        """A fresh search (resumed from the checkpoint file when there is one, the first time).
        False, with :attr:`checkpoint_error` set, logged and in the diagnostics, when that file
        is not an intact checkpoint of this scenario: no search starts from it."""
        p, scenario = self.params, self.scenario
        key = scenario_key(scenario)  # the configured scenario's (before a map's walls)
        if self.searches_started == 0 and self.checkpoint is not None and self.checkpoint.exists():
            try:
                searcher = Searcher.load(self.checkpoint, key)
            except DceeInputError as exc:
                self.checkpoint_error = exc.message
                self.get_logger().error(
                    f"no search started: {exc.message} (remove the file to start afresh)"
                )
                self._publish_diagnostics()
                return False
            self.get_logger().info(f"resumed the search from {self.checkpoint}")
        else:
            scenario, line = self.map_gas.scenario(scenario, bool(p["gas_walls"]))
            if line is not None:
                walls = scenario.plume_model == "walls"
                (self.get_logger().info if walls else self.get_logger().warning)(line)
            searcher = new_searcher(p, scenario, self.searches_started)
            searcher.scenario_key = key
        self.checkpoint_error = ""
        self.gas_model = scenario.plume_model
        if self._map_site is not None:  # the map topic's obstacles outlive a search
            searcher.agent = dataclasses.replace(searcher.agent, site=self._map_site)
        with self._lock:
            self.searcher = searcher
            self.cycle = SearchCycle(
                searcher,
                self.settings,
                true_location=self._true_location,
                wind_period=scenario.anemometer.period,
            )
            self.path_msg = PathMsg()
            self.path_msg.header.frame_id = self.frame_id
            self.finish_reason = ""
            self.done.clear()
            self._last_pose = None
            self._rejected_reported = 0
        self.searches_started += 1
        return True

    def _on_start(self, request: Any, response: Any) -> Any:
        if not self.active:
            response.success, response.message = False, "not active (configure and activate)"
        elif self.cycle is not None and not self.done.is_set():
            response.success, response.message = False, "a search is running (cancel it first)"
        elif not self._new_search():
            response.success, response.message = False, self.checkpoint_error
        else:
            response.success, response.message = True, f"search {self.searches_started} started"
        return response

    def _on_cancel(self, request: Any, response: Any) -> Any:
        if self.cycle is None or self.done.is_set():
            response.success, response.message = False, "no search is running"
        else:
            with self._lock:
                self._finish("cancelled")
            response.success, response.message = True, "search cancelled"
        return response

    # --- inputs -------------------------------------------------------------------------------

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _guarded(self, what: str, callback: Any, *args: Any) -> None:
        """Run a callback; an unexpected error is logged (throttled) and counted, the search
        goes on, and after MAX_CONSECUTIVE_ERRORS in a row it ends cleanly."""
        try:
            callback(*args)
            self._errors_in_a_row = 0
        except Exception as exc:  # a search node must never exit because of its inputs
            self.record_callback_error(what, exc)
        self._report_rejections()

    def record_callback_error(self, what: str, exc: BaseException) -> None:
        """Count and log (throttled) an unexpected error of a callback, this node's own or one
        that rclpy runs for it (:func:`dcee.ros.launch.spin_through_errors`); after
        MAX_CONSECUTIVE_ERRORS in a row the search ends cleanly."""
        self.callback_errors += 1
        self._errors_in_a_row += 1
        self.get_logger().error(
            f"{what}: {type(exc).__name__}: {exc} (message ignored, the search continues)",
            throttle_duration_sec=5.0,
        )
        if self._errors_in_a_row >= MAX_CONSECUTIVE_ERRORS and not self.done.is_set():
            self._finish("error")

    def _report_rejections(self) -> None:
        if self.cycle is None:
            return
        total = sum(self.cycle.rejected.values())
        if total > self._rejected_reported:
            self._rejected_reported = total
            counts = ", ".join(f"{k}: {v}" for k, v in sorted(self.cycle.rejected.items()))
            self.get_logger().warning(
                f"dropped {total} input messages so far ({counts})", throttle_duration_sec=5.0
            )

    def _step(self, pose: Pose) -> None:
        started = time.perf_counter()
        with self._lock:
            if not self.active or self.cycle is None or self.done.is_set():
                return
            dropped = sum(self.cycle.rejected.values())
            out = self.cycle.on_pose(pose)
            if sum(self.cycle.rejected.values()) == dropped:  # accepted: speeds start from it
                self._last_pose = pose
            starved = self.cycle.starved
        if starved:
            topic = self.params["concentration_topic"]
            self.get_logger().warning(
                f"holding for a reading, but nothing arrives on {topic}",
                throttle_duration_sec=5.0,
            )
        if out.record is not None:
            self._publish_belief(out.record)
            self._publish_feedback(out.record)
        if out.goal is not None:
            self._publish_goal(out.goal, pose)
            self.step_latency.append((pose.t, time.perf_counter() - started))
        if out.record is not None and self.checkpoint is not None:
            self._save_checkpoint()  # after the goal: the robot does not wait for the disk
        if out.finished:
            self._finish(out.reason)

    def _finish(self, reason: str) -> None:
        """End the search: log why and the estimate, publish the result and the diagnostics,
        set :attr:`done`."""
        self.finish_reason = reason
        self.cycle.state = "done"
        why = {
            "localised": "source localised",
            "budget": "budget spent",
            "cancelled": "cancelled",
        }.get(reason, f"{MAX_CONSECUTIVE_ERRORS} callback errors in a row")
        est = self.searcher.estimate()
        self.get_logger().info(
            f"search finished ({why}): {len(self.cycle.records)} readings, source estimate "
            f"({est.mean[0]:.2f}, {est.mean[1]:.2f}) m, spread {est.spread:.2f} m"
        )
        self.result_pub.publish(String(data=json.dumps(self.result())))
        self.done.set()
        self._publish_diagnostics()


__all__ = ["SearchNode"]
