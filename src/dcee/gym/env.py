"""``dcee/SourceSearch-v0``: one robot, one particle filter, a simulated release."""

from __future__ import annotations

from typing import Any, ClassVar, SupportsFloat

import gymnasium
import numpy as np
from gymnasium import spaces

from dcee.errors import DceeInputError
from dcee.gym.common import (
    EnvOptions,
    action_mask,
    heading_target,
    observation_space,
    observe,
)
from dcee.planning.base import Belief
from dcee.runs import EpisodeResult, SearchSimulation


class SourceSearchEnv(gymnasium.Env):
    """Source search as a Gymnasium environment.

    One episode is one simulated search (:class:`~dcee.runs.SearchSimulation`):
    the robot starts where the scenario says, takes a reading, and each action moves it one
    step along a heading, after which it takes the next reading and the particle filter
    assimilates it. With the same seed and the same moves it makes exactly the readings that
    ``dcee run`` makes.

    **Actions**: ``Discrete(H)``, H = the scenario's ``agent.n_headings`` (8 in the paper: 0 = +x,
    then counter-clockwise in 45° steps; with ``agent.climb`` > 0 two more, H − 2 up and H − 1
    down). ``info["action_mask"]`` (H,) int8 marks the headings
    that stay inside the search area; an inadmissible action keeps the robot in place (time
    passes, a reading is taken there) and sets ``info["inadmissible"]``.

    **Observation**: a belief summary, not raw particles; ``Box`` float32 (13,), names in
    :data:`OBSERVATION_FIELDS`: position (x, y, z) as fractions of the area; log(1 + reading in
    g/m³); detection flag; posterior mean of the source (x, y, z) as fractions of the area;
    posterior standard deviations (x, y, z) as fractions of the area's sides; effective
    sample size / particles; elapsed time / budget. Everything lies in [0, 1] except the log
    reading (in [0, :data:`MAX_LOG_READING`]); a flat axis (z in a 2-D area) reads 0.

    **Reward** (keywords): ``reward`` is one of :data:`REWARDS` (default ``spread``: the drop of
    the posterior spread over the step, in m), minus ``time_penalty`` per step, plus
    ``success_bonus`` when the episode terminates.

    **End**: *terminated* when the posterior spread √tr P falls below ``converged_spread`` m
    (default 0.5 m: the belief has converged; whether it converged on the truth is in
    ``info["rmse"]``); *truncated* when no further move fits the scenario's budget.

    **Keywords**: ``scenario`` (a built-in name or a TOML path, default ``paper:1``),
    ``particles`` (default 2,000: 10× fewer than the paper, for training speed; pass 20,000 for
    paper scale), ``unknown`` (``source`` | ``full``), ``truth`` (``isotropic`` | ``filament`` |
    a recording's path), ``likelihood`` (the filter's reading model), ``budget`` (s), and
    ``render_mode`` ``"rgb_array"`` (the ``dcee run`` figure as an (H, W, 3) uint8 array).

    Not in the observation but available to reference policies: :attr:`belief`,
    :attr:`position`, :attr:`agent` (see :class:`dcee.gym.PlannerPolicy`).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(self, **options: Any) -> None:
        self.options = EnvOptions.from_keywords(**options)
        self.scenario, self.rules = self.options.build()
        render_mode = self.options.render_mode
        if self.scenario.agent.count != 1:
            raise DceeInputError(
                "agent.count", "SourceSearchEnv flies one robot; use dcee.gym.multi_search_env"
            )
        self.render_mode = render_mode
        self.action_space = spaces.Discrete(self.scenario.make_agent().n_moves)
        self.observation_space = observation_space()
        self.simulation: SearchSimulation | None = None

    # -- what reference policies may see ------------------------------------------------------
    def _sim(self) -> SearchSimulation:
        if self.simulation is None:
            raise DceeInputError("reset", "call reset() before step() or render()")
        return self.simulation

    @property
    def belief(self) -> Belief:
        """The particle filter's current belief (particles, weights, models)."""
        return self._sim().searcher.belief()

    @property
    def position(self) -> np.ndarray:
        """(3,) the robot's position in m."""
        return self._sim().position.copy()

    @property
    def agent(self) -> Any:
        """The robot's move model (:class:`dcee.models.agent.GridAgent`)."""
        return self._sim().agent

    def action_mask(self) -> np.ndarray:
        """(H,) int8: 1 for the headings that keep the robot inside the area."""
        sim = self._sim()
        return action_mask(sim, sim.position)

    # -- Gymnasium API --------------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start a new search. ``seed`` is the search's seed (as in ``dcee run --seed``); without
        one, a seed is drawn from the environment's own generator."""
        super().reset(seed=seed)
        run_seed = int(seed) if seed is not None else int(self.np_random.integers(2**31))
        self.simulation = SearchSimulation(self.scenario, run_seed)
        self._done = False
        rec = self.simulation.sense()[0]
        return self._observation(rec), self._info(rec, inadmissible=False)

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        sim = self._sim()
        if not self.action_space.contains(action):
            raise DceeInputError(
                "action", f"must be a heading index in [0, {self.action_space.n}), got {action!r}"
            )
        if self._done:
            raise DceeInputError("step", "the episode has ended; call reset()")
        before = sim.records[-1]
        target = heading_target(sim, sim.position, int(action))
        inadmissible = target is None
        # an inadmissible heading keeps the robot where it is for one step (time still passes)
        sim.move(sim.position if target is None else target)
        rec = sim.sense()[0]
        reward, terminated, truncated = self.rules.outcome(before, rec, sim.finished)
        self._done = terminated or truncated
        return self._observation(rec), reward, terminated, truncated, self._info(rec, inadmissible)

    def render(self) -> np.ndarray | None:  # type: ignore[override]
        if self.render_mode != "rgb_array":
            return None
        from dcee.analysis.figures import render_search

        return render_search(self.result("policy"), self.scenario, self._sim().truth)

    # -- results --------------------------------------------------------------------------------
    def result(self, strategy: str) -> EpisodeResult:
        """The search so far as a saved-search object (records, summary under the name
        ``strategy``, final posterior), with the same metrics as ``dcee run``."""
        sim = self._sim()
        summary = sim.summary(strategy)
        config = {"scenario": self.scenario.model_dump(mode="json"), "strategy": strategy}
        pf = sim.filter
        return EpisodeResult(sim.records, summary, pf.theta.copy(), pf.weights.copy(), [], config)

    # -- helpers --------------------------------------------------------------------------------
    _done = False

    def _observation(self, rec: dict[str, Any]) -> np.ndarray:
        return observe(self._sim(), rec, self._sim().position)

    def _info(self, rec: dict[str, Any], inadmissible: bool) -> dict[str, Any]:
        return {
            "action_mask": self.action_mask(),
            "inadmissible": inadmissible,
            "time": rec["time"],
            "spread": rec["spread"],
            "rmse": rec["rmse"],
            "mean_error": rec["mean_error"],
            "detection": rec["detection"],
        }
