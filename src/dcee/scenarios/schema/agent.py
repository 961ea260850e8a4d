"""The ``[agent]`` and ``[search]`` sections: the mobile sensor(s) and how they move, and the
search's scale, budget and success criterion."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, Field

from dcee.scenarios.schema.common import FIELD_MARK, FROZEN, Finite, Positive
from dcee.stopping import DEFAULT_STOP_HOLD, DEFAULT_STOP_SHARE


def team_starts(
    start: np.ndarray, step: float, count: int, low: np.ndarray, high: np.ndarray
) -> np.ndarray | None:
    """(count, 3) start positions: robot k at ``start`` + k · step along +y, or along −y where
    the row would leave [low, high]; None when neither fits."""
    for sign in (1.0, -1.0):
        rows = np.repeat(np.asarray(start, dtype=np.float64)[None, :], count, axis=0)
        rows[:, 1] += sign * step * np.arange(count)
        if np.all(rows >= low - 1e-9) and np.all(rows <= high + 1e-9):
            return rows
    return None


AUTO_CLIMB = 1.0
"""m, ``agent.climb`` when unset in a turbulent plume (fluctuation likelihood, grid UAV). Measured
on the tuning range random:13-40 (both turbulent truths, all eight unknown): dcee-cl 38/56 →
53/56 acquired with it, 55-56/56 with the 2.5 m near-source length; on the isotropic truth no
loss (docs/turbulent.md). A fixed altitude cannot meet a plume from a source far below it: in
the held-out fixed-altitude searches the failures were low sources (median 0.5 m) in strong
wind. Left at 0 for the paper's likelihood, so the paper's study flies the paper's agent; but
1 m with the count of releases unknown in open terrain (``estimator.max_sources`` > 1): a weak
release near the ground shows at the paper's fixed 4 m only in a patch a few metres wide.
Measured on the tuning ranges random3:1-60 and random2:1-60 (isotropic truth, dcee-cl:
docs/results/source-count-tune ``-60-climb``, docs/multi-source.md)."""


def unset_climb(
    likelihood: str,
    model: str,
    on_robot: bool = False,
    max_sources: int = 1,
    open_terrain: bool = True,
) -> float:
    """m, what an unset ``agent.climb`` resolves to: :data:`AUTO_CLIMB` for the grid UAV with the
    fluctuation likelihood (a turbulent plume expected) or with the count of releases unknown
    (``estimator.max_sources`` > 1) in open terrain (where it was measured), else 0; on a
    robot's cycle always 0 (it reads planar poses)."""
    several = max_sources > 1 and open_terrain
    climbing = likelihood == "fluctuation" or several
    return AUTO_CLIMB if climbing and model == "grid" and not on_robot else 0.0


AUTO_LOOKAHEAD = 3
"""moves ``dcee-cl`` looks ahead when ``search.lookahead`` is unset in a turbulent plume (grid
UAV, fluctuation likelihood, one release, open terrain). Chosen on the tuning range random:13-40
of filament and puffs, each step by a rule written before its run (acquisition not lower, truth
in the 95 % region not lower by more than 2 points, median paired final error no more than
0.05 m worse): two moves against one (56/56 both, region 96.4 against 98.2 %, final RMSE 0.44
against 0.54 m, paired -0.05 m, Wilcoxon p = 0.016; docs/results/tuning-horizon-13-40), then
three against two (56/56 both, region 53 against 54 of 56, final RMSE 0.43 against 0.44 m,
paired -0.01 m, p = 0.56; docs/results/tuning-lookahead3-13-40; against one move the region is
53 against 55 of 56, the two steps' losses added). On the held-out lbm plume three moves changed
nothing against two (region 86 against 84 %, p = 0.86; docs/plumes.md). A decision costs about
7x one move's, 1.8x two moves' (docs/results/perf/horizon-timing.json). Not measured with
several releases, at a site with the wall-blind estimator or on the unicycle robot, which keep 1
(at a site with the wall-aware estimator: :data:`SITE_LOOKAHEAD`)."""


SITE_LOOKAHEAD = 3
"""moves ``dcee-cl`` looks ahead when ``search.lookahead`` is unset at a site with the wall-aware
estimator (``estimator.plume = "walls"``; grid UAV, fluctuation likelihood, one release). Chosen
on the tuning sites random-site:1-20 (lbm truth round random buildings) among 1, 2 and 3 by a rule
written before the run (most acquired; within one search the lower median final error; within
0.05 m fewer moves): 12/20 acquired each (the same searches), median final error 0.65, 0.61 and
0.55 m; three against one -0.06 m at the median pair (Wilcoxon p = 0.02)
(docs/results/sites-walls-tune/lookahead). On the four held-out sites (docs/results.md §8b):
40/40 acquired, median final error 0.61 m, against 38/40 and 0.63 m one move ahead at the same
code (paired -0.08 m, p = 0.009); a decision 1.04-1.41x the same search's in open terrain at the
same look-ahead. With the wall-blind estimator a site keeps 1 (not measured)."""


def unset_lookahead(
    likelihood: str, model: str, max_sources: int, open_terrain: bool, wall_aware: bool = False
) -> int:
    """Moves ``dcee-cl`` looks ahead when ``search.lookahead`` is unset: where it was chosen
    (the grid UAV, the fluctuation likelihood, one release) :data:`AUTO_LOOKAHEAD` in open
    terrain and :data:`SITE_LOOKAHEAD` at a site with the wall-aware estimator (``wall_aware``),
    else 1 (the look-ahead before the setting existed)."""
    chosen_here = likelihood == "fluctuation" and model == "grid" and max_sources == 1
    if not chosen_here:
        return 1
    if open_terrain:
        return AUTO_LOOKAHEAD
    return SITE_LOOKAHEAD if wall_aware else 1


class UnicycleSpec(BaseModel):
    """The differential-drive robot of ``agent.model = "unicycle"`` (:mod:`dcee.models.motion`).
    Its top speed is ``agent.speed``. Defaults: a Turtlebot-2-class robot as Nav2 drives it
    (0.5 m/s² and 60°/s, 180°/s²); a 0.3 m move then takes 1.9-4.4 s depending on the heading
    change, against 1.5 s for the grid agent at 0.2 m/s."""

    model_config = FROZEN
    max_accel: Positive = 0.5
    """m/s², forward acceleration and braking"""
    max_turn_rate: Annotated[float, Field(gt=0, le=720, allow_inf_nan=False)] = 60.0
    """°/s"""
    max_turn_accel: Annotated[float, Field(gt=0, le=7200, allow_inf_nan=False)] = 180.0
    """°/s²"""
    lookahead: Positive = 0.15
    """m, pure-pursuit look-ahead along the segment to the waypoint"""
    turn_in_place: Annotated[float, Field(gt=0, le=180, allow_inf_nan=False)] = 45.0
    """°: a waypoint further off the heading is first faced by turning on the spot"""
    goal_tolerance: Positive = 0.02
    """m: settled within this distance of the waypoint (and nearly still)"""
    control_dt: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.05
    """s, control and integration period"""


class AgentSpec(BaseModel):
    """The mobile sensor: where it starts and how it moves (one step along one of
    ``headings`` directions per decision, at the start altitude unless ``climb`` > 0)."""

    model_config = FROZEN
    start: tuple[Finite, Finite, Finite]
    """start position (x, y, z), m; inside the volume"""
    step: Positive = 2.0
    """m per move; at least one heading from the start must stay inside the volume"""
    speed: Positive = 2.0
    """m/s; a move takes step / speed + dwell seconds"""
    dwell: Annotated[float | None, Field(ge=0, le=600, allow_inf_nan=False)] = None
    """s held at each waypoint to take a reading; None: 1 s for the isotropic truth,
    :data:`TURBULENT_HOLD` for a time-varying one"""
    headings: Annotated[int, Field(ge=1, le=64)] = 8
    """number of equally spaced move directions (0°, 45°, … for 8)"""
    climb: Annotated[float | None, Field(ge=0, le=100, allow_inf_nan=False)] = None
    """m: with > 0 the agent may also climb or descend this far at its horizontal position (a
    UAV profiling the plume's height; each such move takes as long as a horizontal one), within
    the area's altitude range; 0: the start altitude throughout (the paper's agent). Grid agent
    only. Unset: :data:`AUTO_CLIMB` (1 m) where a turbulent plume is expected
    (``estimator.likelihood = "fluctuation"``) and the agent is the grid UAV, else 0; a robot
    (the ROS 2 node, ``dcee replay``) flies at one altitude unless it is set (docs/turbulent.md)"""
    min_altitude: Annotated[float | None, Field(allow_inf_nan=False)] = None
    """m: the least altitude the agent may fly at (a climbing UAV keeping clear of the ground or
    of the crowns of a site's trees); within the area's altitude range and at most
    ``start``'s. Unset: the area's floor. Only the agent's moves are bounded by it: the
    releases' prior keeps the whole area (a release below it is still found from above)"""
    count: Annotated[int, Field(ge=1, le=16)] = 1
    """robots searching together with one shared belief; robot k starts k · step metres from
    ``start`` along +y (along −y where +y would leave the area)"""
    model: Literal["grid", "unicycle"] = "grid"
    """how the robot drives to a waypoint (:mod:`dcee.models.motion`): "grid", every move takes
    step / speed s and ends on the waypoint (the paper's); "unicycle", a differential-drive
    robot with the limits of [agent.unicycle], so the time per move comes from its dynamics"""
    unicycle: UnicycleSpec = UnicycleSpec()
    """the unicycle robot's limits and path follower, see [agent.unicycle]"""
    heading: Finite = 0.0
    """start heading, ° counter-clockwise from +x"""
    localisation_sd: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.0
    """m: standard deviation of the localisation error (per axis, horizontal) on the position
    told to the estimator with every reading; the reading itself is taken at the true position"""

    def checked_min_altitude(self, floor: float, top: float) -> None:
        """Raise ValueError (one line) where ``min_altitude`` is outside the area's altitude
        range [``floor``, ``top``] m or above the start's altitude."""
        least = self.min_altitude
        if least is None:
            return
        if not floor <= least <= top:
            raise ValueError(
                f"{FIELD_MARK}agent.min_altitude: {least:g} m is outside the area's altitude "
                f"range {floor:g}..{top:g} m"
            )
        if least > self.start[2]:
            raise ValueError(
                f"{FIELD_MARK}agent.min_altitude: {least:g} m is above agent.start's altitude "
                f"{self.start[2]:g} m; allowed: at most the start's altitude"
            )


class SearchSpec(BaseModel):
    """The estimator's and planners' scale, the flight budget and the success criterion."""

    model_config = FROZEN
    particles: Annotated[int, Field(ge=2, le=10_000_000)] = 20_000
    """particles of the filter (the paper's 20,000); ``dcee run``, ``dcee bench`` and the ROS 2
    node refuse a count whose search would not fit in the memory available
    (:mod:`dcee.search_memory`: about 1.2 kB a particle, measured)"""
    hypotheses: Annotated[int, Field(ge=1, le=10_000)] = 40
    """hypothesised readings per candidate move (the paper's 40); a planner spec's own
    ``hypotheses=`` overrides it"""
    budget: Positive = 900.0
    """s of flight (the paper's 900)"""
    acquired_rmse: Positive = 3.0
    """m: "source acquired" when the final RMSE is below it"""
    stop_spread: Annotated[float | None, Field(ge=0, allow_inf_nan=False)] = None
    """m: the search ends once the posterior spread √tr P has stayed below this for
    ``stop_hold`` s (:class:`dcee.stopping.StopRule`). None: on a robot (the ROS 2 node, a
    :class:`~dcee.searcher.Searcher` from :func:`dcee.runs.make_searcher`) the default rule,
    :data:`~dcee.stopping.DEFAULT_STOP_SHARE` × ``acquired_rmse``; in a simulated search or
    study no rule (the whole budget is flown, the paper's protocol, so studies compare equal
    budgets). 0: never stop early, anywhere"""
    stop_hold: Annotated[float, Field(ge=0, le=1e6, allow_inf_nan=False)] = DEFAULT_STOP_HOLD
    """s the spread must stay below ``stop_spread`` before the search ends"""
    stall_guard: Annotated[float, Field(ge=0, le=1e6, allow_inf_nan=False)] = 30.0
    """s: after this long within one step of one position while the posterior spread exceeds
    ``guard_share`` × ``acquired_rmse``, the next move must leave that position (0: off;
    docs/held-out.md)"""
    guard_share: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = DEFAULT_STOP_SHARE
    """the stall guard acts while the posterior spread √tr P exceeds this share of
    ``acquired_rmse`` (below it the source counts as located and the robot may stay). Default
    0.15 (0.45 m at 3 m), the stop rule's threshold: a robot may hover only where it could also
    stop. Chosen on the tuning range random:13-40 (both turbulent truths), where 1.0, the value
    before, let dcee-cl hover > 60 s at a narrow but wrong belief in 19 of 56 searches and 0.15 in
    1, acquisition and final error unchanged; isotropic random-tune searches unchanged
    (docs/turbulent.md)"""
    lookahead: Annotated[int, Field(ge=1, le=3)] | None = None
    """moves ``dcee-cl`` looks ahead (its beam search, :class:`~dcee.planning.HypothesisPlanner`'s
    ``horizon``; a spec's own ``dcee-cl:horizon=`` overrides it). None: :data:`AUTO_LOOKAHEAD` (3)
    for the grid UAV with the fluctuation likelihood, one release, in open terrain (a turbulent
    plume expected; chosen there), else 1 (see :func:`unset_lookahead`)"""
    explore_guard: bool | None = None
    """before each decision, compare how much the best move's next reading would tell (the
    mutual information of detection or not with the hypotheses) with a coarse grid over the
    area, and head for the grid's informative points when every move within reach is
    uninformative (:mod:`dcee.exploration`): the search does not wander where nothing can be
    learnt. None: on with several releases (``estimator.max_sources`` > 1) and on a site
    (a ``[world]`` that is not empty), off in open terrain (open-terrain searches unchanged)"""
    resample_threshold: Annotated[float, Field(gt=0, le=1)] = 0.5
    """resample when the effective sample size falls below this share of the particles"""
    mcmc_steps: Annotated[int, Field(ge=0, le=100)] = 1
    """least Metropolis-Hastings sweeps after a resampling"""
    global_share: Annotated[float, Field(ge=0, le=1)] = 0.2
    """share of particles proposing a source location from the prior in each sweep (keeps
    separated modes alive; 0 = random walk only)"""
    diversify: Annotated[float, Field(ge=0, le=1)] = 0.5
    """sweep until this share of the particles has moved since the resampling"""
    max_sweeps: Annotated[int, Field(ge=1, le=100)] = 8
    """most sweeps after one resampling"""
    move_history: Annotated[int | None, Field(ge=1, le=10**9)] = 1000
    """most history entries a rejuvenating sweep reads per particle: beyond it a sweep moves a
    random share move_history / entries of the particles (each still a draw of the posterior),
    so a resampling costs the same after an hour of flight as after 1,000 readings. None: every
    particle every sweep (a cost that grows with the mission). 1,000: above every study's search
    (at most 180 readings a robot, 540 for a team of three), so no stored result changes; the
    cost it bounds is measured in docs/guide/robot.md ("A day on a robot")"""
