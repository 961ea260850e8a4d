"""A simulated ground robot for the robot interfaces: a unicycle driven by its path follower
in real time steps, with a sensor sampled at every control step. The ROS 2 simulated robot node
(:mod:`dcee.ros.sim_node`) publishes what it produces; tests drive it directly.

Unlike :class:`~dcee.runs.simulation.SearchSimulation`, which jumps from reading to reading,
this robot lives in continuous time: it reports its pose and an instantaneous noisy reading
every ``control_dt`` s, and whoever drives it (the search cycle) decides when it has settled
and which samples make a reading.
"""

from __future__ import annotations

import math

import numpy as np

from dcee.models.motion import Drive, UnicycleMotion, UnicycleState
from dcee.runs.streams import motion_stream, streams
from dcee.scenarios import Scenario
from dcee.simulation.truth import TruthModel, make_truth


class SimulatedRobot:
    """A unicycle robot in ``scenario``'s world (truth, instrument) for episode ``seed``.

    The motion is the scenario's unicycle (its ``agent.model = "grid"`` robot gets the default
    unicycle limits with ``agent.speed`` as top speed). :meth:`step` advances ``control_dt``
    s; :attr:`pose` is the true pose, :meth:`odometry` the pose with the scenario's
    localisation error (a fresh draw per call from the motion stream), :meth:`sample` an
    instantaneous reading (g/m³) of the instrument at the true position now (truth stream:
    sensor noise, the paper's missed detections)."""

    def __init__(self, scenario: Scenario, seed: int, truth: TruthModel | None = None) -> None:
        self.scenario = scenario
        self.seed = int(seed)
        motion = scenario.make_motion()
        if not isinstance(motion, UnicycleMotion):
            motion = scenario.with_overrides(**{"agent.model": "unicycle"}).make_motion()
        assert isinstance(motion, UnicycleMotion)
        self.motion: UnicycleMotion = motion
        self.truth = truth or make_truth(scenario, seed)
        self.sensor = scenario.make_sensor()
        self._truth_rng = streams(seed)[0]
        self._motion_rng = motion_stream(seed)
        start = scenario.agent.start
        self.altitude = float(start[2])
        self.state = UnicycleState(start[0], start[1], math.radians(scenario.agent.heading))
        self.time = 0.0
        self.path_length = 0.0  # m driven
        self.drive: Drive | None = None

    @property
    def control_dt(self) -> float:
        return self.motion.control_dt

    @property
    def position(self) -> np.ndarray:
        """(3,) true position, m."""
        return np.array([self.state.x, self.state.y, self.altitude])

    def set_goal(self, goal: np.ndarray) -> None:
        """Drive to ``goal`` (2,) or (3,) m from where the robot is now."""
        self.drive = self.motion.start_drive(self.state, np.asarray(goal, dtype=np.float64))

    def step(self) -> None:
        """Advance ``control_dt`` s (brake and stand once settled on the goal)."""
        if self.drive is not None and self.motion.settled(self.state, self.drive):
            self.drive = None
        before = self.state
        self.state = self.motion.step(self.state, self.drive)
        self.path_length += math.hypot(self.state.x - before.x, self.state.y - before.y)
        self.time += self.control_dt

    def odometry(self) -> UnicycleState:
        """The pose as the robot's localisation reports it (true pose + N(0, sd²) per axis)."""
        sd = self.scenario.agent.localisation_sd
        if sd <= 0:
            return self.state
        dx, dy = sd * self._motion_rng.standard_normal(2)
        s = self.state
        return UnicycleState(s.x + dx, s.y + dy, s.heading, s.v, s.omega)

    def sample(self) -> float:
        """An instantaneous instrument reading (g/m³) at the true position now."""
        noise = self.sensor.draw_noise(self._truth_rng, ())
        conc = self.truth.sensed(self.position, self.time, 0.0, 0.0)
        return float(self.sensor.simulate_from(conc, noise))


__all__ = ["SimulatedRobot"]
