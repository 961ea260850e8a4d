"""The robot-facing ask/tell search object. The simulator drives this same object."""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcee.blas import one_blas_thread
from dcee.errors import DceeInputError
from dcee.estimation.base import Estimator, UpdateInfo
from dcee.exploration import ApproachingAgent, RestrictedAgent, exploration_goal, wander_goal
from dcee.io import write_atomic
from dcee.models.agent import GridAgent, stall_start
from dcee.planning.base import Belief, Decision, Planner
from dcee.planning.particle_terms import ParticleTerms
from dcee.planning.team import decide_team
from dcee.stopping import DEFAULT_STOP_RULE, DEFAULT_STOP_SHARE, StopRule


@dataclass(frozen=True)
class SourceEstimate:
    """Posterior summary of the source location: mean (3,) m, covariance (3, 3) m², and spread
    √tr(cov) in m (the RMSE the filter expects of itself)."""

    mean: np.ndarray
    cov: np.ndarray

    @property
    def spread(self) -> float:
        return float(math.sqrt(max(np.trace(self.cov), 0.0)))


DEFAULT_STALL_GUARD = 30.0
"""s: after the agent has stayed this long within one step of one position while the belief is
still wide, its next move must take it further from that position (:class:`Searcher`). Half the
60 s a stall may last by issue 28's bar; chosen by that bar, not tuned on any configuration."""

DEFAULT_GUARD_SPREAD = DEFAULT_STOP_SHARE * 3.0
"""m (0.45): the guard acts while the belief's spread √tr P exceeds this: the default stop rule's
threshold at the paper's 3 m acquisition bar, so a robot may hover only where it could also stop
(``search.guard_share``, docs/turbulent.md)."""

WANDER_RADIUS = 7.5
"""m: the region the wander guard watches (the radius of :data:`dcee.runs.metrics.WANDER_RADIUS`,
which the summaries count)."""

WANDER_GUARD = 60.0
"""s in one region with a belief wider than it before the wander guard sends the robot out
(half the 120 s a study may allow, issue 44)."""

STALL_HISTORY = 64
"""Told positions the stall guard looks back over (more than 30 s of readings at 1 s)."""


class LeavingAgent(RestrictedAgent):
    """The moves that take the agent further from ``target`` (3,) m, the stall's anchor, than
    it is: what the stall guard hands a planner. Where no move leaves the anchor (a corner),
    the moves that leave the agent's own horizontal position: a climbing agent could otherwise
    hold its stall by climbing and descending on one spot (random:1049, filament, held out:
    75 s in a corner)."""

    def allowed(self, cands: np.ndarray) -> np.ndarray:
        now = math.hypot(*(self.start[:2] - self.target[:2]))
        away = np.hypot(*(cands[:, :2] - self.target[:2]).T) > now + 0.5 * self.agent.step
        if not away.any():  # cornered: at least leave this spot (no climb or descent in place)
            away = np.hypot(*(cands[:, :2] - self.start[:2]).T) > 0.5 * self.agent.step
        return away


CHECKPOINT_FORMAT = "dcee-searcher-checkpoint-2"
"""Identifies a :meth:`Searcher.save` file and its layout version (1 was a Python pickle, no
longer read: reading a pickle runs whatever code its author put in it)."""


class Searcher:
    """Ask/tell source search: ``tell`` a reading, ``ask`` for the next waypoint.

    >>> searcher.tell(position, reading, time)   # after every sample
    >>> waypoint = searcher.ask()                # where to sample next (3,)

    The planner's random draws come from ``rng`` (seeded by the caller); the filter owns its own.

    The stall guard (``stall_guard`` s, 0 = off): when the told positions of the last
    ``stall_guard`` seconds or more all lie within one step of the first of them (the robot has
    paced or hovered there) while the belief's spread √tr P exceeds ``guard_spread`` m (the
    source is not yet located), :meth:`ask` offers the planner only the moves that take the robot
    further from that position (:class:`LeavingAgent`). A planner whose candidates' costs tie
    where no reading can tell the hypotheses apart then still moves on to gain information. It
    never fires in a search that does not pace, so such searches are unchanged. It guards
    :meth:`ask` (one robot); a team's :meth:`ask_team` is not guarded.

    Stopping when localised (``stop_rule``, :class:`~dcee.stopping.StopRule`; None = never):
    :attr:`localised` turns True once the spread √tr P has stayed below the rule's threshold
    for its hold (by default :data:`~dcee.stopping.DEFAULT_STOP_RULE`, 0.45 m for 60 s at the
    paper's scale; :func:`dcee.runs.make_searcher` scales it to the scenario). A robot's loop
    ends there (``while not searcher.localised``); :meth:`ask` still answers for a robot that
    keeps refining.

    A Searcher changes no process-wide state: a program of its own may apply
    :func:`dcee.allocator.tune_allocator` (the command line, campaign workers and the ROS node
    do), and ``tell``/``ask`` limit BLAS to one thread only while they run.
    """

    def __init__(
        self,
        particle_filter: Estimator,
        planner: Planner | None,
        agent: GridAgent,
        rng: np.random.Generator,
        stall_guard: float = DEFAULT_STALL_GUARD,
        guard_spread: float = DEFAULT_GUARD_SPREAD,
        stop_rule: StopRule | None = DEFAULT_STOP_RULE,
        explore_guard: bool = False,
    ) -> None:
        for name, value in (("stall_guard", stall_guard), ("guard_spread", guard_spread)):
            if isinstance(value, bool) or not (
                isinstance(value, int | float) and math.isfinite(value) and value >= 0
            ):
                raise DceeInputError(name, f"must be a number >= 0, got {value!r}")
        if stop_rule is not None and not isinstance(stop_rule, StopRule):
            raise DceeInputError("stop_rule", f"must be a StopRule or None, got {stop_rule!r}")
        self.stop_rule = stop_rule
        self.below_since = math.nan
        """time s of the first told reading of the current run below the stop threshold"""
        self.stall_guard = float(stall_guard)
        self.guard_spread = float(guard_spread)
        self.recent: list[tuple[float, np.ndarray]] = []
        """(time s, position (3,) m) of the last told readings, for the stall guard"""
        self.guard_fired = 0
        """how many decisions the stall guard restricted"""
        self.explore_guard = bool(explore_guard)
        self.explore_fired = 0
        """how many decisions the exploration guard restricted (:mod:`dcee.exploration`)"""
        self.wander_fired = 0
        """how many of them because the robot kept to one region (:meth:`wander_goal`)"""
        self.wander_target: np.ndarray | None = None
        """where the wander guard sends the robot, held until it is within a step of it"""
        self.filter = particle_filter
        self.planner = planner
        self.agent = agent
        self.rng = rng
        self.position: np.ndarray | None = None
        self.time = 0.0
        self.last_update: UpdateInfo | None = None
        self.last_decision: Decision | None = None
        self.last_team_decisions: list[Decision | None] = []
        self.last_update_seconds = 0.0
        self.last_decision_seconds = 0.0
        # merged particles and per-position terms kept across decisions while the particles
        # are unchanged (dcee.planning.particle_terms; exact, about a third of a decision)
        self.planning_cache = ParticleTerms()
        self.checkpoint_code: dict[str, Any] | None = None
        """the code version that wrote the checkpoint this searcher was loaded from"""
        self.scenario_key: dict[str, str] | None = None
        """the scenario this search belongs to (name and identity digest,
        :func:`dcee.runs.scenario_key`): saved with a checkpoint and checked when one is
        resumed"""

    def tell(self, position: np.ndarray, reading: float, time: float | None = None) -> UpdateInfo:
        """Assimilate a reading (g/m³) taken at ``position`` (m) at ``time`` (s)."""
        if time is not None and (
            isinstance(time, bool)
            or not isinstance(time, int | float | np.integer | np.floating)
            or not (math.isfinite(time) and time >= self.time)
        ):
            raise DceeInputError(
                "time", f"must be a finite, non-decreasing number of s, got {time!r}"
            )
        t0 = _time.perf_counter()
        with one_blas_thread():
            self.last_update = self.filter.update(position, reading)  # validates both
        self.last_update_seconds = _time.perf_counter() - t0
        self.position = np.asarray(position, dtype=np.float64)
        if time is not None:
            self.time = float(time)
        self.recent = [*self.recent[-(STALL_HISTORY - 1) :], (self.time, self.position.copy())]
        if self.stop_rule is not None:
            self.below_since = self.stop_rule.advance(
                self.below_since, self.time, self.estimate().spread
            )
        return self.last_update

    def tell_wind(self, speed: float, direction: float) -> UpdateInfo:
        """Assimilate an anemometer reading: wind ``speed`` m/s from ``direction`` rad
        (counter-clockwise from +x, as the source term's φ; in a scenario's degrees: convert).
        The filter must have an anemometer model (``[anemometer] enabled``)."""
        with one_blas_thread():
            return self.filter.update_wind(speed, direction)

    @property
    def localised(self) -> bool:
        """True once the stop rule holds: the spread has stayed below its threshold for its
        hold (always False without a rule). The same test as
        :meth:`dcee.stopping.StopRule.stop_index` on the told readings."""
        return self.stop_rule is not None and self.stop_rule.holds(self.below_since, self.time)

    def ask(self) -> np.ndarray:
        """Next waypoint (3,) in m, chosen by the planner from the last told position."""
        if self.position is None:
            raise DceeInputError("ask", "tell() at least one reading before ask()")
        if self.planner is None:
            raise DceeInputError("planner", "this searcher has no planner to ask")
        t0 = _time.perf_counter()
        agent = self.decision_agent()
        if isinstance(agent, LeavingAgent):
            self.guard_fired += 1
        with one_blas_thread():
            self.last_decision = self.planner.decide(self.belief(), self.position, agent, self.rng)
        self.last_decision_seconds = _time.perf_counter() - t0
        return self.last_decision.position.copy()

    def decision_agent(self) -> GridAgent | LeavingAgent | ApproachingAgent:
        """The agent the next :meth:`ask` plans with: :attr:`agent`, a :class:`LeavingAgent`
        that only offers moves away from the stall while the stall guard fires
        (:meth:`stall_anchor`), or with ``explore_guard`` an
        :class:`~dcee.exploration.ApproachingAgent` that only offers moves towards where
        readings are informative when no move within reach is
        (:func:`~dcee.exploration.exploration_goal`)."""
        anchor = self.stall_anchor()
        if anchor is not None:
            return LeavingAgent(self.agent, anchor, self.position)
        if self.explore_guard:
            goal = self.wander_goal()
            if goal is None:
                goal = exploration_goal(self.filter, self.position, self.agent)
            if goal is not None:
                self.explore_fired += 1
                return ApproachingAgent(self.agent, goal, self.position)
        return self.agent

    def wander_goal(self) -> np.ndarray | None:
        """The exploration guard's region-wide part: once the told positions of the last
        :data:`WANDER_GUARD` s or more all lie within :data:`WANDER_RADIUS` m of the first of
        them while the belief is wider than that region (its spread √tr P above the radius:
        readings in the region cannot resolve it), head for the grid point outside the region
        that tells the most (:func:`~dcee.exploration.wander_goal`), and keep heading there
        until within one step of it or until the belief is no wider than the region (the
        reason to leave is gone; held until the stop rule's spread instead, on
        ``area:fontvieille`` seed 1 a belief that fell from 8.6 m to 2.8 m within 40 s of
        leaving still took the robot on to its goal, 87 m from the posterior mean: 285 of the
        search's 900 s). None when the guard does not fire."""
        if self.wander_target is not None:
            reached = math.dist(self.wander_target[:2], self.position[:2]) <= self.agent.step
            if reached or self.estimate().spread <= WANDER_RADIUS:
                self.wander_target = None
            else:
                self.wander_fired += 1
                return self.wander_target
        if len(self.recent) < 2:
            return None
        first = stall_start(np.array([p for _, p in self.recent]), WANDER_RADIUS)
        if self.recent[-1][0] - self.recent[first][0] < WANDER_GUARD:
            return None
        if self.estimate().spread <= WANDER_RADIUS:
            return None
        self.wander_target = wander_goal(
            self.filter, self.recent[first][1], self.agent, WANDER_RADIUS, self.position
        )
        if self.wander_target is not None:
            self.wander_fired += 1
            self.recent = self.recent[-1:]  # a new region starts once it has left this one
        return self.wander_target

    def stall_anchor(self) -> np.ndarray | None:
        """The position (3,) m the robot has stayed within one step of for at least
        ``stall_guard`` s (the first of the latest run of told positions all within one step of
        it, as :func:`dcee.runs.metrics.longest_stall` measures) while the belief's spread
        exceeds ``guard_spread``; None when the guard does not fire."""
        if self.stall_guard <= 0 or len(self.recent) < 2:
            return None
        first = stall_start(np.array([p for _, p in self.recent]), self.agent.step)
        if self.recent[-1][0] - self.recent[first][0] < self.stall_guard:
            return None
        if self.estimate().spread <= self.guard_spread:
            return None  # the source is located: staying near it is what the robot should do
        return self.recent[first][1]

    def ask_team(self, positions: np.ndarray) -> np.ndarray:
        """Next waypoints (K, 3) m of K robots at ``positions`` (K, 3) that share this
        searcher's belief (every robot's readings told to this searcher), chosen jointly by
        sequential greedy planning (:func:`dcee.planning.team.decide_team`); a robot with no
        admissible, collision-free move keeps its position. :attr:`last_team_decisions` holds
        the per-robot decisions."""
        if self.position is None:
            raise DceeInputError("ask", "tell() at least one reading before ask_team()")
        if self.planner is None:
            raise DceeInputError("planner", "this searcher has no planner to ask")
        try:
            arr = np.asarray(positions, dtype=np.float64)
        except (TypeError, ValueError):
            arr = np.empty(0)
        if arr.ndim != 2 or arr.shape[1] != 3 or not np.all(np.isfinite(arr)):
            raise DceeInputError("positions", "must be a finite (K, 3) array of positions in m")
        t0 = _time.perf_counter()
        with one_blas_thread():
            decisions = decide_team(self.planner, self.belief(), arr, self.agent, self.rng)
        self.last_decision_seconds = _time.perf_counter() - t0
        self.last_team_decisions = decisions
        return np.array(
            [d.position if d is not None else p for d, p in zip(decisions, arr, strict=True)]
        )

    # --- checkpoint and restore ---------------------------------------------------------------

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["planning_cache"] = None  # a cache: rebuilt on demand, never changes a decision
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        # checkpoints written before the stall guard: it was off; before the stop rule: none
        state = {
            "stall_guard": 0.0,
            "guard_spread": 3.0,
            "recent": [],
            "guard_fired": 0,
            "stop_rule": None,
            "below_since": math.nan,
            "explore_guard": False,
            "explore_fired": 0,
            # and before the wander guard: it had not fired
            "wander_fired": 0,
            "wander_target": None,
            **state,
        }
        self.__dict__.update(state)
        self.planning_cache = ParticleTerms()

    def save(self, path: str | Path) -> Path:
        """Checkpoint the whole search to ``path`` (one file, written atomically): the filter
        (particles, weights, reading history, its random state), the planner and its options,
        the agent, the planner's random state, the last position and time. :meth:`load` gives a
        searcher that makes exactly the decisions this one would have made (tested).

        The file is data, not code (:mod:`dcee.state_file`: NumPy arrays and a JSON header with
        a checksum, read without pickle); its layout is :data:`CHECKPOINT_FORMAT`, documented
        in docs/robot.md."""
        from dcee.provenance import code_version
        from dcee.state_file import write_state

        path = Path(path)
        if path.is_dir():  # else the atomic write's rename fails with a confusing message
            raise DceeInputError(
                "path",
                f"{path} is a folder; give the checkpoint a file name, e.g. {path / 'search.ckpt'}",
            )
        meta = {"scenario": self.scenario_key}
        try:
            write_atomic(
                path, lambda p: write_state(p, CHECKPOINT_FORMAT, self, meta, code_version())
            )
        except OSError as exc:
            raise DceeInputError("path", f"cannot write checkpoint {path}: {exc}") from None
        return path

    @classmethod
    def load(cls, path: str | Path, scenario_key: dict[str, str] | None = None) -> Searcher:
        """Restore a searcher from a :meth:`save` checkpoint (the code version that wrote it is
        in :attr:`checkpoint_code`). With ``scenario_key`` (:func:`dcee.runs.scenario_key` of
        the scenario it is to resume) a checkpoint of another scenario is refused. Any file
        that is not an intact checkpoint of this dcee version: one
        :class:`~dcee.errors.DceeInputError` naming what is wrong."""
        from dcee.state_file import read_state

        path = Path(path)
        header, searcher = read_state(path, CHECKPOINT_FORMAT)
        if not isinstance(searcher, cls):
            raise DceeInputError("checkpoint", f"{path}: holds no searcher")
        for name, role in (("filter", Estimator), ("agent", GridAgent)):
            if not isinstance(getattr(searcher, name, None), role):
                raise DceeInputError("checkpoint", f"{path}: its searcher has no valid {name}")
        if searcher.planner is not None and not isinstance(searcher.planner, Planner):
            raise DceeInputError("checkpoint", f"{path}: its searcher has no valid planner")
        saved = (header.get("meta") or {}).get("scenario")
        if scenario_key is not None and saved != scenario_key:
            name = saved.get("name") if isinstance(saved, dict) else None
            now = scenario_key.get("name")
            what = f"not of {now!r}" if name != now else f"not of {now!r} with other settings"
            raise DceeInputError(
                "checkpoint",
                f"{path}: saved by a search of {name!r}, {what}: start a new search",
            )
        searcher.checkpoint_code = header.get("code")
        return searcher

    def belief(self) -> Belief:
        f = self.filter
        # the particles read-only where the estimator can hand them over so (ResampleMove's
        # planning_particles: the planner's cache then trusts them unchanged), else as they are
        frozen = getattr(f, "planning_particles", None)
        theta = f.theta if frozen is None else frozen()
        return Belief(
            theta, f.weights, f.sensor, f.plume, self.planning_cache, site=self.agent.site
        )

    def estimate(self) -> SourceEstimate:
        """Posterior mean and covariance of the source location."""
        return SourceEstimate(self.filter.source_mean(), self.filter.source_cov())
