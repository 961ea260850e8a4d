"""Step a simulated search: the world (truth, instrument, robots' motion) and the filter, one
reading and one move at a time, without deciding the moves (:mod:`dcee.runs.episode` decides
them with a planner, :mod:`dcee.gym` with a policy)."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from dcee.models.sensor import Sensor
from dcee.planning.base import Planner
from dcee.runs.assemble import make_searcher
from dcee.runs.metrics import search_summary
from dcee.runs.records import reading_record
from dcee.runs.streams import anemometer_stream, motion_stream, streams
from dcee.scenarios import Scenario
from dcee.simulation.truth import TruthModel, make_truth


def dense_path(path: np.ndarray, spacing: float = 0.05) -> np.ndarray:
    """(K, 2) points along a drive's (n, 4) (t, x, y, heading) samples, at most ``spacing`` m
    apart (a straight grid move has only its two ends)."""
    xy = path[:, 1:3]
    out = [xy[:1]]
    for a, b in itertools.pairwise(xy):
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / spacing)))
        t = np.linspace(0.0, 1.0, n + 1)[1:, None]
        out.append(a + t * (b - a))
    return np.concatenate(out)


class SearchSimulation:
    """One simulated search, a step at a time: the world (truth, instrument, robots' move
    model) and the filter, without a planner. :func:`run_episode` drives it with a planner; the
    Gymnasium and PettingZoo environments (:mod:`dcee.gym`) with a policy's actions. All
    therefore make the same readings and the same records for the same seed and moves.

    ``sense()`` takes every robot's reading at its current position and the current time,
    assimilates them into the one shared filter (robot 0 first) and appends one record per
    reading (:attr:`records`, with its ``robot``); ``move(waypoints)`` drives the robots to
    their next waypoints (:attr:`motion`), the readings follow one hold after the slowest has
    settled; ``finished`` says when no further move fits the budget (or the scenario's
    ``stop_spread`` is reached). The scenario's ``agent.count``
    sets the number of robots (:meth:`~dcee.scenarios.Scenario.starts`).
    """

    def __init__(
        self,
        scenario: Scenario,
        seed: int,
        planner: Planner | None = None,
        truth: TruthModel | None = None,
    ) -> None:
        self.scenario = scenario
        self.seed = int(seed)
        truth_rng, filter_rng, planner_rng, self.figure_rng = streams(seed)
        self._truth_rng = truth_rng
        self.sensor: Sensor = scenario.make_sensor()  # the instrument: makes the real readings
        self.truth = truth or make_truth(scenario, seed)
        self.true_location = scenario.truth_theta()[:3]
        self.searcher = make_searcher(scenario, planner, filter_rng, planner_rng, on_robot=False)
        self.agent = self.searcher.agent
        self.filter = self.searcher.filter
        self.motion = scenario.make_motion()
        self._motion_rng = motion_stream(seed)
        self.positions = scenario.starts()  # (K, 3) true positions
        self.headings = np.full(len(self.positions), math.radians(scenario.agent.heading))
        self.time = self.agent.dwell  # the first reading is taken at the start after one dwell
        self.travel_time = 0.0  # s, the last move's drive (the slowest robot's)
        self.records: list[dict[str, Any]] = []
        self.path_length = 0.0
        self.site = scenario.make_site()
        self.drives_into_obstacles = 0
        self.anemometer = scenario.make_anemometer()
        self._wind_rng = anemometer_stream(seed)
        self._wind_time = 0.0  # s, the last wind reading's time
        self.wind_readings = 0

    @property
    def position(self) -> np.ndarray:
        """(3,) robot 0's position, m (the only robot's, in a single-robot search)."""
        return self.positions[0]

    def sense(self) -> list[dict[str, Any]]:
        """Take, assimilate and record every robot's reading at the current time (after the
        anemometer's readings since the last step, when the robot has one); returns the
        step's records, one per robot."""
        self._sense_wind()
        return [self._sense_one(k) for k in range(len(self.positions))]

    def _sense_wind(self) -> None:
        """The anemometer's readings of the truth's mean wind, one per ``period`` s up to now."""
        if self.anemometer is None:
            return
        period = self.scenario.anemometer.period
        truth = self.scenario.truth_theta()
        while self._wind_time + period <= self.time + 1e-9:
            self._wind_time += period
            speed, direction = self.anemometer.simulate(truth[4], truth[5], self._wind_rng)
            self.searcher.tell_wind(speed, direction)
            self.wind_readings += 1

    def _sense_one(self, robot: int) -> dict[str, Any]:
        scenario, t = self.scenario, self.time
        position = self.positions[robot].copy()
        # the same count of noise draws per step, whatever the positions
        noise = self.sensor.draw_noise(self._truth_rng, ())
        conc = self.truth.sensed(position, t, scenario.average, scenario.sensor.response_time)
        reading = self.truth.reported(float(self.sensor.simulate_from(conc, noise)), conc, t)
        told = position.copy()  # where the robot believes it is
        sd = self.scenario.agent.localisation_sd
        if sd > 0:
            told[:2] += sd * self._motion_rng.standard_normal(2)
            told[:2] = np.clip(
                told[:2], self.scenario.volume.low[:2], self.scenario.volume.high[:2]
            )
        info = self.searcher.tell(told, reading, t)
        rec = reading_record(
            self.searcher,
            info,
            step=len(self.records) // len(self.positions),
            robot=robot,
            time=t,
            position=position,
            told=told,
            reading=reading,
            detection=bool(self.sensor.is_detection(reading)),
            true_location=self.true_location,
            heading=math.degrees(self.headings[robot]),
            travel_time=self.travel_time,
            true_concentration=conc,
        )
        self.records.append(rec)
        return rec

    @property
    def finished(self) -> bool:
        """True when no further move can fit the budget (the fastest possible drive plus the
        hold), or the scenario's stop rule holds (``search.stop_spread``; none by default in a
        simulation: :meth:`~dcee.scenarios.Scenario.stop_rule`)."""
        search = self.scenario.search
        shortest = self.motion.shortest_move_time(self.agent.step) + self.agent.dwell
        return self.time + shortest > search.budget + 1e-9 or self.searcher.localised

    @property
    def over_budget(self) -> bool:
        """True when the last move ended after the budget (a drive slower than the fastest
        possible one): its readings are not taken."""
        return self.time > self.scenario.search.budget + 1e-9

    def move(self, waypoints: np.ndarray) -> None:
        """Drive the robots to ``waypoints`` (K, 3) m (a (3,) waypoint for one robot) with the
        scenario's motion model (:mod:`dcee.models.motion`); they move together and the next
        readings are taken when the slowest has settled and held ``agent.dwell`` s."""
        waypoints = np.asarray(waypoints, dtype=np.float64).reshape(self.positions.shape)
        new = waypoints.copy()
        durations = []
        for k, (p, goal) in enumerate(zip(self.positions, waypoints, strict=True)):
            travel = self.motion.travel((p[0], p[1], self.headings[k]), goal)
            new[k, 0], new[k, 1], self.headings[k] = travel.pose
            durations.append(travel.duration)
            steps = np.diff(travel.path[:, 1:3], axis=0)
            self.path_length += float(np.hypot(steps[:, 0], steps[:, 1]).sum())
            self.path_length += abs(float(goal[2]) - float(p[2]))  # a climb or a descent
            if self.site is not None:  # the drive itself, every 5 cm, against the raw shapes
                self.drives_into_obstacles += int(
                    self.scenario.in_obstacle(dense_path(travel.path)).any()
                )
        self.positions = new
        self.travel_time = max(durations)
        self.time += self.travel_time + self.agent.dwell

    def summary(self, strategy: str) -> dict[str, Any]:
        """The search's summary (:func:`search_summary`) under the name ``strategy``; with a
        ``[world]``, ``drives_into_obstacles`` (moves whose drive touched an obstacle or no-go
        zone: 0 unless something is wrong) and ``start_to_source_travel`` (m, the shortest way
        round the obstacles, against which ``path_length`` compares); with an anemometer,
        ``wind_readings``."""
        out = search_summary(
            self.records, self.scenario, strategy, self.seed, self.path_length, self.searcher
        )
        if self.anemometer is not None:
            out["wind_readings"] = self.wind_readings
        if self.site is not None:
            out["drives_into_obstacles"] = self.drives_into_obstacles
            out["start_to_source_travel"] = float(
                self.site.travel_distance(
                    np.asarray(self.scenario.agent.start), self.true_location[None, :2]
                )[0]
            )
        return out
