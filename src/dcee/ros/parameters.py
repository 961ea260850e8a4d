"""The search node's parameters (:data:`PARAMETERS`: names and defaults; what the scenario, the
cycle's settings and a new search's searcher become from them) and the quality-of-service
profiles the dcee nodes share (:mod:`dcee.ros.node`, :mod:`dcee.ros.sim_node`,
:mod:`dcee.ros.demo`).

Parameters
    ``scenario`` (name or TOML path), ``strategy``, ``seed``, ``particles`` (0: the
    scenario's), ``frame_id`` ("map"), ``calibration`` (1.0), ``noise_floor`` (g/m³ a
    sample may read below zero and still be clean air's noise; -1: the sensor's threshold),
    ``concentration_topic``,
    ``pose_topic``, ``goal_topic``, ``pose_type`` (:data:`POSE_TYPES`),
    ``checkpoint`` (a file: the searcher is saved there after every reading and resumed from
    it at start), ``marker_particles`` (500); when the robot has settled for a reading:
    ``goal_tolerance`` (0.05 m), ``settle_speed`` (0.02 m/s), ``settle_turn_rate`` (5 °/s),
    ``settle_time`` (0.2 s). The hold and the averaging are the scenario's (``agent.dwell``,
    ``sensor.average``). The search ends when the budget is spent or, by default, once the
    source is localised (:mod:`dcee.stopping`): ``stop_spread`` m and ``stop_hold`` s (< 0:
    the scenario's ``search.stop_spread``/``stop_hold``, unset there: spread below
    0.15 × ``search.acquired_rmse`` for 60 s; ``stop_spread`` 0: never). ``gas_walls``
    (true): a map on the map topic makes the estimator's gas flow round its walls
    (:mod:`dcee.robot.map_gas`).
"""

from __future__ import annotations

import math
from typing import Any

from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy

from dcee.errors import DceeInputError
from dcee.robot.cycle import CycleSettings
from dcee.robot.gps import map_frame
from dcee.runs import make_searcher, planner_defaults, streams
from dcee.scenarios import Scenario, load_scenario
from dcee.search_memory import check_search_memory
from dcee.searcher import Searcher

RELIABLE = QoSProfile(depth=50, reliability=QoSReliabilityPolicy.RELIABLE)
LATCHED = QoSProfile(
    depth=1,
    reliability=QoSReliabilityPolicy.RELIABLE,
    durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
)

POSE_TYPES = ("odometry", "pose_with_covariance", "navsatfix")
"""What the pose topic carries: nav_msgs/Odometry, geometry_msgs/PoseWithCovarianceStamped
(speeds from successive poses) or sensor_msgs/NavSatFix (GNSS fixes placed in the scenario's map
frame, heading and speeds from successive fixes: :mod:`dcee.robot.gps`)."""

PARAMETERS: dict[str, Any] = {
    "scenario": "lab:upwind",
    "strategy": "infotaxis",
    "seed": 0,
    "particles": 0,
    "frame_id": "map",
    "calibration": 1.0,
    # g/m³ below zero a sample may read and still be clean air's noise; < 0: the sensor's
    # detection threshold (dcee.robot.cycle.CycleSettings)
    "noise_floor": -1.0,
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
    # a map on the map topic makes the estimator's gas flow round its walls (next search on)
    "gas_walls": True,
}


MAX_CONSECUTIVE_ERRORS = 20
"""Unexpected callback errors in a row after which the search ends cleanly (reason "error")."""


def scenario_from_parameters(p: dict[str, Any], given: Scenario | None = None) -> Scenario:
    """The scenario the parameters ``p`` name (or ``given``, built in Python) with their
    particle count and stop rule; a bad value raises :class:`DceeInputError`."""
    scenario = given if given is not None else load_scenario(str(p["scenario"]))
    if int(p["particles"]) > 0:
        scenario = scenario.with_overrides(**{"search.particles": int(p["particles"])})
    # a robot's computer: a search that would outgrow its memory is refused at configure, not
    # killed by the system part way through the mission
    check_search_memory(
        scenario.search.particles, scenario.estimator.max_sources, field="particles"
    )
    for key in ("stop_spread", "stop_hold"):
        if float(p[key]) >= 0:
            scenario = scenario.with_overrides(**{f"search.{key}": float(p[key])})
    if p["pose_type"] not in POSE_TYPES:
        raise DceeInputError("pose_type", f"must be one of {', '.join(POSE_TYPES)}")
    if p["pose_type"] == "navsatfix":
        map_frame(scenario, "pose_type")  # refused where the scenario has no map
    return scenario


def cycle_settings(p: dict[str, Any], scenario: Scenario) -> CycleSettings:
    """When the robot has settled for a reading, from the parameters (angles in °/s)."""
    floor = float(p["noise_floor"])
    return CycleSettings.from_scenario(
        scenario,
        calibration=float(p["calibration"]),
        **({} if floor < 0 else {"noise_floor": floor}),  # NaN reaches the check
        goal_tolerance=float(p["goal_tolerance"]),
        settle_speed=float(p["settle_speed"]),
        settle_turn_rate=math.radians(float(p["settle_turn_rate"])),
        settle_time=float(p["settle_time"]),
    )


def new_searcher(p: dict[str, Any], scenario: Scenario, number: int) -> Searcher:
    """A fresh searcher for the node's search ``number`` (0, 1, …): the parameters' planner,
    seeded with ``seed + number``."""
    from dcee.planning import get as get_planner

    strategy = str(p["strategy"])
    planner = get_planner(strategy, **planner_defaults(strategy, scenario, None))
    _, filter_rng, planner_rng, _ = streams(int(p["seed"]) + number)
    return make_searcher(scenario, planner, filter_rng, planner_rng)


__all__ = [
    "LATCHED",
    "MAX_CONSECUTIVE_ERRORS",
    "PARAMETERS",
    "POSE_TYPES",
    "RELIABLE",
    "cycle_settings",
    "new_searcher",
    "scenario_from_parameters",
]
