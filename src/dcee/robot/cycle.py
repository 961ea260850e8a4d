"""The robot's search cycle without ROS: arrive → settle → hold (average the readings) → tell →
ask → publish. The ROS 2 node (:mod:`dcee.ros.node`) feeds it the messages it receives and
publishes what it returns; ``dcee replay`` (:mod:`dcee.robot.replay`) feeds it a recorded bag
with the goals as recorded. Everything here is plain Python and tested without ROS.

Time is the robot's clock in seconds (message stamps, simulated time in the demo); the search's
own clock starts at the first pose, so ``search.budget`` counts from there.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from numbers import Real
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.anemometer import wind_from_vector
from dcee.runs import reading_record
from dcee.scenarios import Scenario
from dcee.searcher import Searcher


@dataclass(frozen=True)
class Pose:
    """A pose sample: ``t`` s, position ``x``, ``y`` m, ``heading`` rad counter-clockwise from
    +x (REP-103 ENU yaw), forward speed ``v`` m/s and turn rate ``omega`` rad/s."""

    t: float
    x: float
    y: float
    heading: float = 0.0
    v: float = 0.0
    omega: float = 0.0


@dataclass(frozen=True)
class CycleSettings:
    """When a reading is taken. ``hold`` s held still on the waypoint (``agent.dwell``);
    ``average`` s of readings averaged at the end of the hold (0: the last sample, an
    instantaneous reading; ``sensor.average``); ``calibration`` g/m³ per sensor unit (a PID in
    ppm: the gas's g/m³ per ppm); settled = within ``goal_tolerance`` m of the goal, slower than
    ``settle_speed`` m/s and ``settle_turn_rate`` rad/s for ``settle_time`` s; ``altitude`` m of
    the readings (a ground robot's sensor height, the scenario's start z); ``budget`` s of
    search; ``shortest_move`` s, the fastest any move can be (a move that cannot end in the
    budget is not asked for); ``noise_floor`` g/m³, how far below zero a sample may read and
    still be a measurement (from a scenario: its detection threshold ``sensor.threshold``). A
    zero-centred instrument (a PID or an electrochemical cell after its baseline is taken
    off) reads a little below zero in clean air; dropping those samples kept only the
    positive half of the noise, and the hold's mean of them read gas where there was none. A
    sample further below zero than the threshold, which the instrument's noise is below by
    the threshold's definition, is a fault."""

    hold: float
    average: float
    budget: float
    altitude: float
    shortest_move: float
    calibration: float = 1.0
    noise_floor: float = 0.0
    goal_tolerance: float = 0.05
    settle_speed: float = 0.02
    settle_turn_rate: float = math.radians(5.0)
    settle_time: float = 0.2

    @classmethod
    def from_scenario(cls, scenario: Scenario, **changes: Any) -> CycleSettings:
        """The scenario's hold, averaging, budget, altitude, move bound and noise floor (its
        sensor's threshold); ``changes`` (calibration, noise floor, tolerances) override."""
        climb = scenario.agent.climb  # unset: one altitude on a robot (resolved_climb)
        if climb is not None and climb > 0:  # the cycle tells the estimator a fixed altitude
            raise DceeInputError(
                "agent.climb",
                f"must be 0 on a robot (got {scenario.agent.climb:g} m): the robot cycle reads "
                "planar poses and flies at agent.start's altitude; climbing is for simulation",
            )
        motion = scenario.make_motion()
        values: dict[str, Any] = {
            "hold": scenario.dwell,
            "average": scenario.average,
            "budget": scenario.search.budget,
            "altitude": scenario.agent.start[2],
            "shortest_move": motion.shortest_move_time(scenario.agent.step),
            "noise_floor": scenario.sensor.threshold,
        }
        values.update(changes)
        for name in (
            "hold",
            "average",
            "budget",
            "calibration",
            "noise_floor",
            "goal_tolerance",
            "settle_speed",
            "settle_turn_rate",
            "settle_time",
        ):
            value = values.get(name, getattr(cls, name, 0.0))
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise DceeInputError(name, f"must be a finite number >= 0, got {value!r}")
        if values["average"] > values["hold"] + 1e-9:
            raise DceeInputError("average", "must not be longer than the hold")
        return cls(**values)


@dataclass
class CycleOutput:
    """What one message caused: a new ``goal`` (3,) m to publish, a ``record`` of an
    assimilated reading (the per-reading record of a search), ``finished`` when the search
    is over, and why (``reason``: "budget", no further move fits it; "localised", the
    searcher's stop rule holds, :attr:`~dcee.searcher.Searcher.localised`)."""

    goal: np.ndarray | None = None
    record: dict[str, Any] | None = None
    finished: bool = False
    reason: str = ""


@dataclass
class SearchCycle:
    """One robot's search cycle around a :class:`~dcee.searcher.Searcher`.

    ``plan``: ask the searcher's planner for the next goal after each reading (the node);
    False: the goals come from outside through :meth:`on_goal` (a replay). ``true_location``
    (3,) m, when known, gives the records an RMSE. States: ``driving`` (to the goal; also at
    the start, to where it stands), ``settling``, ``holding``, ``waiting`` (for a goal, replay
    only), ``done``."""

    searcher: Searcher
    settings: CycleSettings
    plan: bool = True
    true_location: np.ndarray | None = None
    state: str = "driving"
    goal: np.ndarray | None = None
    start_time: float | None = None
    records: list[dict[str, Any]] = field(default_factory=list)
    dropped_readings: int = 0
    wind_period: float = 1.0
    """s over which wind samples are averaged into one anemometer reading (the scenario's
    ``anemometer.period``)"""
    wind_readings: int = 0
    """anemometer readings told to the searcher"""
    rejected: dict[str, int] = field(default_factory=dict)
    """messages dropped before they could reach the estimator, by reason (see
    :data:`REJECTION_REASONS`)"""
    path_length: float = 0.0
    _pose: Pose | None = None
    _since: float = 0.0
    _samples: list[tuple[float, float]] = field(default_factory=list)
    _drive_started: float = 0.0
    _pending_goal: np.ndarray | None = None
    _wind: list[tuple[float, float]] = field(default_factory=list)
    _wind_since: float | None = None
    clock_offset: float = 0.0
    """s added to every stamp since the clock jumped back (:data:`CLOCK_JUMP`)"""
    clock_jumps: int = 0
    """how many times the clock jumped back and the search's clock carried on"""
    _behind: list[float] = field(default_factory=list)

    @property
    def search_time(self) -> float:
        """s since the search started (its first pose)."""
        if self._pose is None or self.start_time is None:
            return 0.0
        return self._pose.t - self.start_time

    @property
    def starved(self) -> bool:
        """True while a hold has lasted 5 s beyond its length without one reading (no
        concentration messages arrive: the node warns)."""
        if self.state != "holding" or self._samples or self._pose is None:
            return False
        return self._pose.t - self._since > self.settings.hold + 5.0

    def on_goal(self, goal: np.ndarray) -> None:
        """A goal from outside (replay): drive to it."""
        if self.state == "done":
            return
        goal = np.asarray(goal, dtype=np.float64)
        if self.state == "waiting":
            self.goal, self.state = goal, "driving"
        else:  # published while this replay still holds (clock skew): the next goal
            self._pending_goal = goal

    def _reject(self, reason: str) -> None:
        self.rejected[reason] = self.rejected.get(reason, 0) + 1

    def reading_problem(self, value: object) -> str | None:
        """Why a sample (sensor units) cannot be a measurement, or None: not a real number,
        not finite, further below zero than the noise floor (``noise_floor`` g/m³ after
        ``calibration``), or above the sensor's physical maximum (``sensor.max_reading`` g/m³:
        a glitch, a saturated or stuck sensor). A sample between the floor and zero is kept:
        the hold's mean of it is the reading, a non-detection to the estimator."""
        if isinstance(value, bool) or not isinstance(value, Real):
            return "reading not a number"
        if not math.isfinite(value):
            return "reading not finite"
        concentration = value * self.settings.calibration  # g/m³
        if concentration < -self.settings.noise_floor:
            return "reading below the noise floor"
        if concentration > self.searcher.filter.sensor.max_reading:
            return "reading above max_reading"
        return None

    def pose_problem(self, pose: Pose) -> str | None:
        """Why a pose cannot be the robot's, or None: a non-finite time, position, heading or
        speed; a position farther outside the search area than the area is wide; a stamp
        earlier than the last accepted pose's."""
        values = (pose.t, pose.x, pose.y, pose.heading, pose.v, pose.omega)
        if not all(isinstance(v, Real) and math.isfinite(v) for v in values):
            return "pose not finite"
        volume = self.searcher.agent.volume
        lo, hi = np.asarray(volume.low, float), np.asarray(volume.high, float)
        margin = float(np.max(hi[:2] - lo[:2]))
        if not (
            lo[0] - margin <= pose.x <= hi[0] + margin
            and lo[1] - margin <= pose.y <= hi[1] + margin
        ):
            return "pose far outside the area"
        if self._pose is not None and pose.t < self._pose.t:
            return "pose stamp went backwards"
        return None

    def on_reading(self, t: float, value: float) -> None:
        """A concentration sample (sensor units) received at ``t`` s; kept while holding.
        A sample that cannot be a measurement (:meth:`reading_problem`) is dropped and
        counted (:attr:`rejected`, :attr:`dropped_readings`); it never reaches the
        estimator."""
        problem = self.reading_problem(value)
        if problem is not None:
            self.dropped_readings += 1
            self._reject(problem)
            return
        if self.state == "holding":
            # arrived while holding: part of this hold, even when its stamp lags the pose's
            # (a subscriber's clock behind the odometry's)
            t = float(t) + self.clock_offset
            self._samples.append((max(t, self._since), float(value)))

    def on_wind(self, t: float, vx: float, vy: float) -> bool:
        """A wind sample received at ``t`` s: the air's velocity (vx, vy) m/s in the map frame.
        Samples are averaged over ``wind_period`` s and the mean told to the searcher as one
        anemometer reading (so a 20 Hz sensor does not count as 20 independent readings).
        A sample that cannot be a wind (not finite, faster than 100 m/s) is dropped and
        counted. Returns True when a reading was told."""
        values = (t, vx, vy)
        if not all(isinstance(v, Real) and math.isfinite(v) for v in values):
            self._reject("wind not finite")
            return False
        if math.hypot(vx, vy) > MAX_WIND:
            self._reject("wind above 100 m/s")
            return False
        t = float(t) + self.clock_offset
        if self._wind_since is None or t < self._wind_since:
            self._wind_since, self._wind = float(t), []
        self._wind.append((float(vx), float(vy)))
        if t - self._wind_since < self.wind_period - 1e-9:
            return False
        mean = np.mean(self._wind, axis=0)
        self._wind_since, self._wind = float(t), []
        speed, direction = wind_from_vector(float(mean[0]), float(mean[1]))
        self.searcher.tell_wind(speed, direction)
        self.wind_readings += 1
        return True

    def on_pose(self, pose: Pose) -> CycleOutput:
        """A pose sample: advances the cycle; returns what to publish. A pose that cannot be
        the robot's (:meth:`pose_problem`) is dropped and counted (:attr:`rejected`)."""
        if self.clock_offset:
            pose = dataclasses.replace(pose, t=pose.t + self.clock_offset)
        problem = self.pose_problem(pose)
        if problem == "pose stamp went backwards":
            jump = self._clock_jump(pose)
            if jump is not None:
                pose = dataclasses.replace(pose, t=pose.t + jump)
                problem = self.pose_problem(pose)
        if problem is not None:
            self._reject(problem)
            return CycleOutput()
        self._behind = []
        out = CycleOutput()
        if self._pose is not None:
            self.path_length += math.hypot(pose.x - self._pose.x, pose.y - self._pose.y)
        self._pose = pose
        if self.start_time is None:
            # a searcher resumed from a checkpoint: the search's time carries on from its last
            # reading (the estimator takes no reading from before it, and the budget counts on)
            self.start_time = pose.t - self.searcher.time
            self._drive_started = pose.t
        s = self.settings
        if self.state != "done" and self.search_time > s.budget + 1e-9:
            self.state = "done"  # the budget ran out on the way: no reading is taken
            return CycleOutput(finished=True, reason="budget")
        still = abs(pose.v) <= s.settle_speed and abs(pose.omega) <= s.settle_turn_rate
        if self.state == "driving":
            near = self.goal is None or math.hypot(
                pose.x - self.goal[0], pose.y - self.goal[1]
            ) <= max(s.goal_tolerance, 1e-9)
            if near and still:
                self.state, self._since = "settling", pose.t
        if self.state == "settling":
            if not still:
                self.state = "driving"
            elif pose.t - self._since >= s.settle_time - 1e-9:
                self.state, self._since, self._samples = "holding", pose.t, []
        if self.state == "holding" and pose.t - self._since >= s.hold - 1e-9 and self._samples:
            out = self._complete(pose)
        return out

    def _clock_jump(self, pose: Pose) -> float | None:
        """The jump (s) when ``pose``, its stamp behind the last accepted one, is the
        :data:`CLOCK_JUMP_POSES`-th in a row each more than :data:`CLOCK_JUMP` s behind and each
        later than the one before: the clock jumped back (a time source reset, a simulation
        restarted); it did not merely deliver a pose late. Then the search's clock carries on
        from the last accepted pose (:attr:`clock_offset` grows by the jump, which is counted)
        instead of dropping every pose until the new clock catches up. None otherwise."""
        assert self._pose is not None
        if self._pose.t - pose.t <= CLOCK_JUMP or (self._behind and pose.t <= self._behind[-1]):
            self._behind = []
            return None
        self._behind.append(pose.t)
        if len(self._behind) < CLOCK_JUMP_POSES:
            return None
        jump = self._pose.t - self._behind[0]
        self.clock_offset += jump
        self.clock_jumps += 1
        self._behind = []
        return jump

    def _complete(self, pose: Pose) -> CycleOutput:
        s = self.settings
        if s.average > 0:
            window = [v for t, v in self._samples if t >= pose.t - s.average - 1e-9]
            value = float(np.mean(window)) if window else self._samples[-1][1]
        else:
            value = self._samples[-1][1]
        reading = value * s.calibration
        time = self.search_time
        position = np.array([pose.x, pose.y, s.altitude])
        info = self.searcher.tell(position, reading, time)
        sensor = self.searcher.filter.sensor  # the estimator's: the same threshold
        record = reading_record(
            self.searcher,
            info,
            step=len(self.records),
            robot=0,
            time=time,
            position=position,
            told=position,
            reading=reading,
            detection=bool(sensor.is_detection(reading)),
            true_location=self.true_location,
            heading=math.degrees(pose.heading),
            travel_time=self._since - self._drive_started - s.settle_time,
        )
        record["path_length"] = self.path_length
        self.records.append(record)
        out = CycleOutput(record=record)
        if time + s.shortest_move + s.hold > s.budget + 1e-9:
            self.state, out.finished, out.reason = "done", True, "budget"
            return out
        if self.plan and self.searcher.localised:  # a replay follows the recorded goals
            self.state, out.finished, out.reason = "done", True, "localised"
            return out
        self._drive_started = pose.t
        if self.plan:
            # moved on before asking: should ask fail (the node logs it), the robot is taken
            # to be at its goal and reads again where it stands, then asks again
            self.goal, self.state = None, "driving"
            self.goal = self.searcher.ask()
            record["decision_seconds"] = self.searcher.last_decision_seconds
            self.state = "driving"
            out.goal = self.goal.copy()
        elif self._pending_goal is not None:
            self.goal, self.state, self._pending_goal = self._pending_goal, "driving", None
        else:
            self.goal, self.state = None, "waiting"
        return out


CLOCK_JUMP = 1.0
"""s: a pose stamp further than this behind the last accepted one is not a late message; three
such in a row, each later than the one before, are a clock that jumped back
(:meth:`SearchCycle.on_pose`)."""

CLOCK_JUMP_POSES = 3

MAX_WIND = 100.0
"""m/s: a faster wind sample is a sensor fault."""

REJECTION_REASONS = (
    "reading not a number",
    "reading not finite",
    "reading below the noise floor",
    "reading above max_reading",
    "pose not finite",
    "pose far outside the area",
    "pose stamp went backwards",
    "wind not finite",
    "wind above 100 m/s",
)
"""Every reason :class:`SearchCycle` drops an input message for (the keys of
:attr:`SearchCycle.rejected`)."""

__all__ = ["REJECTION_REASONS", "CycleOutput", "CycleSettings", "Pose", "SearchCycle"]
