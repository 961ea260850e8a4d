"""The dcee ROS 2 node (``dcee-ros-node``): the search cycle of :mod:`dcee.robot.cycle` on topics.

Subscribes
    ``concentration`` (std_msgs/Float32, sensor units × ``calibration`` = g/m³), stamped on
    arrival with the node's clock (set ``use_sim_time`` to follow ``/clock``);
    ``odom`` (nav_msgs/Odometry; or geometry_msgs/PoseWithCovarianceStamped with
    ``pose_type:=pose_with_covariance``, speeds then from successive poses);
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
    same mean with the 3 × 3 location covariance in the position block), ``dcee/particles``
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
    ``scenario`` (name or TOML path), ``strategy``, ``seed``, ``particles`` (0: the
    scenario's), ``frame_id`` ("map"), ``calibration`` (1.0), ``concentration_topic``,
    ``pose_topic``, ``goal_topic``, ``pose_type`` ("odometry" | "pose_with_covariance"),
    ``checkpoint`` (a file: the searcher is saved there after every reading and resumed from
    it at start), ``marker_particles`` (500); when the robot has settled for a reading:
    ``goal_tolerance`` (0.05 m), ``settle_speed`` (0.02 m/s), ``settle_turn_rate`` (5 °/s),
    ``settle_time`` (0.2 s). The hold and the averaging are the scenario's (``agent.dwell``,
    ``sensor.average``). The search ends when the budget is spent or, by default, once the
    source is localised (:mod:`dcee.stopping`): ``stop_spread`` m and ``stop_hold`` s (< 0:
    the scenario's ``search.stop_spread``/``stop_hold``, unset there: spread below
    0.15 × ``search.acquired_rmse`` for 60 s; ``stop_spread`` 0: never).

Conventions (docs/guide/robot.md): frames are REP-103 ENU (x east, y north, yaw
counter-clockwise from +x); dcee's wind direction φ is the direction the wind comes *from*,
counter-clockwise from +x (meteorological direction = 90° − φ, clockwise from north);
concentrations are g/m³.
"""

from __future__ import annotations

import json
import math
import threading
from pathlib import Path
from typing import Any

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
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
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy
from std_msgs.msg import Float32, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import Marker, MarkerArray

from dcee.console import error_exit
from dcee.errors import DceeInputError
from dcee.robot.bag import quaternion_of, yaw_of
from dcee.robot.cycle import CycleSettings, Pose, SearchCycle
from dcee.runs import make_searcher, planner_defaults, streams
from dcee.scenarios import Scenario, load_scenario
from dcee.searcher import Searcher

RELIABLE = QoSProfile(depth=50, reliability=QoSReliabilityPolicy.RELIABLE)
LATCHED = QoSProfile(
    depth=1,
    reliability=QoSReliabilityPolicy.RELIABLE,
    durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
)

PARAMETERS: dict[str, Any] = {
    "scenario": "lab:upwind",
    "strategy": "infotaxis",
    "seed": 0,
    "particles": 0,
    "frame_id": "map",
    "calibration": 1.0,
    "concentration_topic": "concentration",
    "pose_topic": "odom",
    "map_topic": "map",
    "wind_topic": "wind",
    "goal_topic": "goal_pose",
    "pose_type": "odometry",
    "checkpoint": "",
    "marker_particles": 500,
    # when a reading is taken (dcee.robot.cycle.CycleSettings); hold and averaging: the scenario's
    "goal_tolerance": 0.05,
    "settle_speed": 0.02,
    "settle_turn_rate": 5.0,
    "settle_time": 0.2,
    # when the search ends early (dcee.stopping): < 0 keeps the scenario's search.stop_spread /
    # search.stop_hold (unset: spread below 0.15 x acquired_rmse for 60 s); stop_spread 0: never
    "stop_spread": -1.0,
    "stop_hold": -1.0,
    # configure and activate at start (a node without a lifecycle manager); false: wait for one
    "autostart": True,
}


MAX_CONSECUTIVE_ERRORS = 20
"""Unexpected callback errors in a row after which the search ends cleanly (reason "error")."""


def seconds(stamp: Any) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


class SearchNode(LifecycleNode):
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
        self._errors_in_a_row = 0
        self._rejected_reported = 0
        self._wind_warned = False
        self._lock = threading.Lock()
        self._last_pose: Pose | None = None
        self._map_site: Any = None
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
        scenario = self._given_scenario
        if scenario is None:
            scenario = load_scenario(str(p["scenario"]))
        if int(p["particles"]) > 0:
            scenario = scenario.with_overrides(**{"search.particles": int(p["particles"])})
        for key in ("stop_spread", "stop_hold"):
            if float(p[key]) >= 0:
                scenario = scenario.with_overrides(**{f"search.{key}": float(p[key])})
        if p["pose_type"] not in ("odometry", "pose_with_covariance"):
            raise DceeInputError("pose_type", "must be odometry or pose_with_covariance")
        self.settings = CycleSettings.from_scenario(
            scenario,
            calibration=float(p["calibration"]),
            goal_tolerance=float(p["goal_tolerance"]),
            settle_speed=float(p["settle_speed"]),
            settle_turn_rate=math.radians(float(p["settle_turn_rate"])),
            settle_time=float(p["settle_time"]),
        )
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
        self.create_subscription(
            Float32, str(p["concentration_topic"]), self._on_concentration, RELIABLE
        )
        self.create_subscription(OccupancyGrid, str(p["map_topic"]), self._on_map, LATCHED)
        self.create_subscription(Vector3Stamped, str(p["wind_topic"]), self._on_wind, RELIABLE)
        if p["pose_type"] == "odometry":
            self.create_subscription(Odometry, str(p["pose_topic"]), self._on_odometry, RELIABLE)
        else:
            self.create_subscription(
                PoseWithCovarianceStamped, str(p["pose_topic"]), self._on_pose_cov, RELIABLE
            )

    def _new_search(self) -> None:
        """A fresh search (resumed from the checkpoint file when there is one, the first time)."""
        p, scenario = self.params, self.scenario
        if self.searches_started == 0 and self.checkpoint is not None and self.checkpoint.exists():
            searcher = Searcher.load(self.checkpoint)
            self.get_logger().info(f"resumed the search from {self.checkpoint}")
        else:
            from dcee.planning import get as get_planner

            strategy = str(p["strategy"])
            planner = get_planner(strategy, **planner_defaults(strategy, scenario, None))
            seed = int(p["seed"]) + self.searches_started
            _, filter_rng, planner_rng, _ = streams(seed)
            searcher = make_searcher(scenario, planner, filter_rng, planner_rng)
        if self._map_site is not None:  # the map topic's obstacles outlive a search
            import dataclasses

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

    def _on_start(self, request: Any, response: Any) -> Any:
        if not self.active:
            response.success, response.message = False, "not active (configure and activate)"
        elif self.cycle is not None and not self.done.is_set():
            response.success, response.message = False, "a search is running (cancel it first)"
        else:
            self._new_search()
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
            self.callback_errors += 1
            self._errors_in_a_row += 1
            self.get_logger().error(
                f"{what}: {type(exc).__name__}: {exc} (message ignored, the search continues)",
                throttle_duration_sec=5.0,
            )
            if self._errors_in_a_row >= MAX_CONSECUTIVE_ERRORS and not self.done.is_set():
                self._finish("error")
        self._report_rejections()

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

    def _on_concentration(self, msg: Float32) -> None:
        self._guarded("concentration", self._reading, msg)

    def _reading(self, msg: Float32) -> None:
        with self._lock:
            if self.active and self.cycle is not None:
                self.cycle.on_reading(self._now(), float(msg.data))

    def _on_wind(self, msg: Vector3Stamped) -> None:
        self._guarded("wind", self._wind, msg)

    def _wind(self, msg: Vector3Stamped) -> None:
        if not self.scenario.anemometer.enabled:
            if not self._wind_warned:
                self._wind_warned = True
                self.get_logger().warning(
                    "wind readings ignored: the scenario has no [anemometer] (enabled = true)"
                )
            return
        t = seconds(msg.header.stamp) or self._now()
        with self._lock:
            if self.active and self.cycle is not None:
                self.cycle.on_wind(t, msg.vector.x, msg.vector.y)

    def _on_map(self, msg: OccupancyGrid) -> None:
        self._guarded("map", self._map, msg)

    def _map(self, msg: OccupancyGrid) -> None:
        """Apply an occupancy grid: a map that cannot be used (rotated, not covering the
        search area, malformed) is logged and ignored; the search goes on with the last map."""
        import dataclasses

        from dcee.models.site import SiteMap, compose_site
        from dcee.robot.bag import yaw_of

        info = msg.info
        if info.width == 0 or info.height == 0 or len(msg.data) != info.width * info.height:
            raise DceeInputError("map", f"{len(msg.data)} cells for {info.width} x {info.height}")
        if abs(yaw_of(info.origin.orientation)) > 1e-6:
            raise DceeInputError("map", "a rotated map (origin yaw != 0) is not supported")
        occ = np.asarray(msg.data, dtype=float).reshape(info.height, info.width)
        occ = np.where(occ < 0, np.nan, occ / 100.0)
        grid = SiteMap.from_occupancy(
            occ, (info.origin.position.x, info.origin.position.y), info.resolution, name="map topic"
        )
        sc = self.scenario
        site = compose_site(
            tuple(sc.volume.low[:2]),
            tuple(sc.volume.high[:2]),
            maps=[grid],
            resolution=sc.site_resolution,
            clearance=sc.world.clearance,
            name="map topic",
        )
        own = sc.make_site()  # the scenario's own obstacles, zones and map file stay
        if own is not None:
            site.blocked |= own.blocked
        with self._lock:
            self._map_site = site
            if self.searcher is not None:
                self.searcher.agent = dataclasses.replace(self.searcher.agent, site=site)
        self.maps_received += 1
        self.get_logger().info(
            f"map applied: {info.width} x {info.height} cells of {info.resolution:g} m, "
            f"{int(site.blocked.sum())} of {site.blocked.size} planning cells blocked"
        )

    def _on_odometry(self, msg: Odometry) -> None:
        self._guarded("odometry", self._odometry, msg)

    def _odometry(self, msg: Odometry) -> None:
        p = msg.pose.pose
        t = seconds(msg.header.stamp) or self._now()
        self._step(
            Pose(
                t,
                p.position.x,
                p.position.y,
                yaw_of(p.orientation),
                msg.twist.twist.linear.x,
                msg.twist.twist.angular.z,
            )
        )

    def _on_pose_cov(self, msg: PoseWithCovarianceStamped) -> None:
        self._guarded("pose", self._pose_cov, msg)

    def _pose_cov(self, msg: PoseWithCovarianceStamped) -> None:
        p = msg.pose.pose
        t = seconds(msg.header.stamp) or self._now()
        x, y, yaw = p.position.x, p.position.y, yaw_of(p.orientation)
        v = w = 0.0
        last = self._last_pose
        if last is not None and t > last.t and math.isfinite(t - last.t):
            # speeds from successive poses
            v = math.hypot(x - last.x, y - last.y) / (t - last.t)
            w = math.remainder(yaw - last.heading, 2 * math.pi) / (t - last.t)
        self._step(Pose(t, x, y, yaw, v, w))

    def _step(self, pose: Pose) -> None:
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
            if self.checkpoint is not None:
                self.searcher.save(self.checkpoint)
        if out.goal is not None:
            self._publish_goal(out.goal, pose)
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

    def result(self) -> dict[str, Any]:
        """The search's result (the ``dcee/result`` message): ``success`` (the source was
        localised or the budget spent with a reading; False when cancelled or failed),
        ``reason``, the estimate's ``mean`` (3,) m and location ``covariance`` (3 × 3) m²,
        ``spread`` m, ``readings``, and the believed wind: ``wind_from`` (a compass bearing,
        °, where it comes from, clockwise from north) and ``wind_speed`` m/s."""
        from dcee.models.compass import estimated_bearing
        from dcee.models.plume import PARAMETER_NAMES

        est = self.searcher.estimate()
        readings = len(self.cycle.records)
        belief, weights = self.searcher.filter.theta, self.searcher.filter.weights
        phi, u = (belief[:, PARAMETER_NAMES.index(k)] for k in ("phi", "u"))
        return {
            "success": self.finish_reason in ("localised", "budget") and readings > 0,
            "reason": self.finish_reason,
            "mean": [float(v) for v in est.mean],
            "covariance": [[float(v) for v in row] for row in est.cov],
            "spread": float(est.spread),
            "readings": readings,
            "wind_from": estimated_bearing(phi, weights),
            "wind_speed": float(weights @ u),
        }

    def _publish_feedback(self, record: dict[str, Any]) -> None:
        est = self.searcher.estimate()
        feedback = {
            "state": self.cycle.state,
            "readings": len(self.cycle.records),
            "mean": [float(v) for v in est.mean],
            "spread": float(est.spread),
            "elapsed": float(record["time"]),
        }
        self.feedback_pub.publish(String(data=json.dumps(feedback)))

    def diagnostics(self) -> DiagnosticStatus:
        """The search's state and its input health as one DiagnosticStatus: WARN once input
        messages were dropped, ERROR once a callback failed."""
        status = DiagnosticStatus()
        status.name = f"{self.get_name()}: source search"
        status.hardware_id = "dcee"
        if self.cycle is None:
            status.level = DiagnosticStatus.OK
            status.message = "configured, no search yet" if self.active else "inactive"
            status.values = [KeyValue(key="state", value="inactive")]
            return status
        rejected = self.cycle.rejected
        if self.callback_errors:
            status.level = DiagnosticStatus.ERROR
            status.message = f"{self.callback_errors} callback errors (messages ignored)"
        elif rejected:
            status.level = DiagnosticStatus.WARN
            status.message = f"{sum(rejected.values())} input messages dropped"
        else:
            status.level = DiagnosticStatus.OK
            status.message = "inputs healthy"
        values = {
            "state": self.cycle.state,
            "finish_reason": self.finish_reason,
            "readings used": str(len(self.cycle.records)),
            "callback errors": str(self.callback_errors),
            **{f"dropped: {k}": str(v) for k, v in sorted(rejected.items())},
        }
        status.values = [KeyValue(key=k, value=v) for k, v in values.items()]
        return status

    def _publish_diagnostics(self) -> None:
        msg = DiagnosticArray()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.status = [self.diagnostics()]
        self.diagnostics_pub.publish(msg)

    # --- outputs ------------------------------------------------------------------------------

    def _header(self, msg: Any) -> None:
        msg.header.frame_id = self.frame_id
        msg.header.stamp = self.get_clock().now().to_msg()

    def _publish_goal(self, goal: np.ndarray, pose: Pose) -> None:
        msg = PoseStamped()
        self._header(msg)
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = (float(v) for v in goal)
        yaw = math.atan2(goal[1] - pose.y, goal[0] - pose.x)
        q = quaternion_of(yaw)
        o = msg.pose.orientation
        o.x, o.y, o.z, o.w = q
        self.goal_pub.publish(msg)

    def _publish_belief(self, record: dict[str, Any]) -> None:
        est = self.searcher.estimate()
        point = PointStamped()
        self._header(point)
        point.point.x, point.point.y, point.point.z = (float(v) for v in est.mean)
        self.estimate_pub.publish(point)
        cov = PoseWithCovarianceStamped()
        self._header(cov)
        pos = cov.pose.pose.position
        pos.x, pos.y, pos.z = (float(v) for v in est.mean)
        cov.pose.pose.orientation.w = 1.0
        full = np.zeros((6, 6))
        full[:3, :3] = est.cov
        full[3:, 3:] = np.eye(3) * 1e9  # orientation unknown
        cov.pose.covariance = [float(v) for v in full.ravel()]
        self.cov_pub.publish(cov)
        self.particles_pub.publish(self._particle_markers())
        stamped = PoseStamped()
        self._header(stamped)
        stamped.pose.position.x = float(record["x"])
        stamped.pose.position.y = float(record["y"])
        stamped.pose.position.z = float(record["z"])
        stamped.pose.orientation.w = 1.0
        self.path_msg.header.stamp = stamped.header.stamp
        self.path_msg.poses.append(stamped)
        self.path_pub.publish(self.path_msg)

    def _particle_markers(self) -> MarkerArray:
        from geometry_msgs.msg import Point

        pf = self.searcher.filter
        n = min(int(self.params["marker_particles"]), pf.n)
        idx = self._marker_rng.choice(pf.n, size=n, p=pf.weights)
        marker = Marker()
        self._header(marker)
        marker.ns, marker.id = "dcee_particles", 0
        marker.type, marker.action = Marker.POINTS, Marker.ADD
        marker.scale.x = marker.scale.y = 0.03
        marker.color.r, marker.color.g, marker.color.b, marker.color.a = 0.1, 0.4, 0.9, 0.8
        marker.pose.orientation.w = 1.0
        for x, y, z in pf.source_locations[idx]:
            marker.points.append(Point(x=float(x), y=float(y), z=float(z)))
        return MarkerArray(markers=[marker])


def main(argv: list[str] | None = None) -> None:
    """``dcee-ros-node [--ros-args -p scenario:=lab:upwind -p strategy:=infotaxis ...]``."""
    import sys

    rclpy.init(args=argv if argv is not None else sys.argv)
    from rclpy.exceptions import InvalidParameterTypeException, ParameterException

    from dcee.allocator import tune_allocator

    tune_allocator()  # this process is the node's own (see dcee.allocator)

    try:
        node = SearchNode()
    except (DceeInputError, ParameterException, InvalidParameterTypeException) as exc:
        rclpy.try_shutdown()
        error_exit("dcee-ros-node", str(exc) or type(exc).__name__)
    # one thread: the node's callbacks share one mutually exclusive group anyway, and the
    # single-threaded executor has 3-4x the throughput (measured with the demo)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


__all__ = ["PARAMETERS", "SearchNode", "main"]
