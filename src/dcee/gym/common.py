"""What the single- and multi-robot environments share: their keywords (:class:`EnvOptions`),
the reward and episode end (:class:`EpisodeRules`), the observation and the action mask."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from gymnasium import spaces

from dcee.errors import DceeInputError
from dcee.runs import SearchSimulation
from dcee.scenarios import Scenario, truth_choice
from dcee.search_memory import check_search_memory

REWARDS = ("spread", "rmse")
"""``spread``: the drop of the posterior spread √tr P over the step (m; what the robot itself
can compute); ``rmse``: the drop of the particles' RMSE about the true source (m; privileged
information, only in simulation)."""

MAX_LOG_READING = 20.0
"""The observation's log(1 + reading) is clipped here (a reading of 4.9e8 g/m³): a finite
bound for learning code, far above any plausible reading."""

OBSERVATION_FIELDS = (
    "x",
    "y",
    "z",
    "log_reading",
    "detection",
    "mean_x",
    "mean_y",
    "mean_z",
    "sd_x",
    "sd_y",
    "sd_z",
    "ess",
    "time",
)
"""Names of the observation's entries, in order (see :class:`SourceSearchEnv`)."""


@dataclass(frozen=True)
class EnvOptions:
    """The keywords of both environments (``gymnasium.make(ENV_ID, **keywords)``,
    ``multi_search_env(**keywords)``), in one place; see :class:`~dcee.gym.SourceSearchEnv`."""

    scenario: str | Scenario = "paper:1"
    """a built-in name, a TOML path or a :class:`~dcee.scenarios.Scenario`"""
    particles: int | None = 2000
    """search.particles (2,000: 10x fewer than the paper, for training speed)"""
    unknown: str | None = None
    """"source" | "full" (None: the scenario's)"""
    truth: str | None = None
    """"isotropic" | "filament" | "puffs" | a recording's path (None: the scenario's)"""
    likelihood: str | None = None
    """the filter's reading model (None: the scenario's)"""
    budget: float | None = None
    """search.budget, s (None: the scenario's)"""
    reward: str = "spread"
    """one of :data:`REWARDS`"""
    time_penalty: float = 0.0
    """subtracted from every step's reward"""
    success_bonus: float = 0.0
    """added when the episode terminates"""
    converged_spread: float = 0.5
    """m: the episode terminates when the posterior spread falls below it"""
    render_mode: str | None = None
    """None or ``"rgb_array"`` (the figure as an (H, W, 3) uint8 array)"""
    agents: int | None = None
    """robots (the multi-robot environment's; None: the scenario's agent.count)"""

    @classmethod
    def from_keywords(cls, **keywords: Any) -> EnvOptions:
        """The options from keywords; an unknown keyword is a :class:`DceeInputError` naming
        the allowed ones."""
        allowed = [f.name for f in fields(cls)]
        for key in keywords:
            if key not in allowed:
                raise DceeInputError(key, f"unknown keyword; allowed: {', '.join(allowed)}")
        return cls(**keywords)

    def build(self) -> tuple[Scenario, EpisodeRules]:
        """The scenario with the overrides applied, and the checked episode rules."""
        agents = self.agents
        if agents is not None and (isinstance(agents, bool) or not isinstance(agents, int)):
            raise DceeInputError("agents", f"must be a whole number of robots, got {agents!r}")
        check_render_mode(self.render_mode)
        scenario = make_scenario(
            self.scenario,
            self.particles,
            self.unknown,
            self.truth,
            self.likelihood,
            self.budget,
            agents,
        )
        rules = EpisodeRules.checked(
            self.reward, self.time_penalty, self.success_bonus, self.converged_spread
        )
        # an environment per process of a vectorised set: each is checked on its own
        check_search_memory(
            scenario.search.particles, scenario.estimator.max_sources, field="particles"
        )
        return scenario, rules


def make_scenario(
    scenario: str | Scenario,
    particles: int | None,
    unknown: str | None,
    truth: str | None,
    likelihood: str | None,
    budget: float | None,
    count: int | None = None,
) -> Scenario:
    """The environment's scenario: a built-in name, a TOML path or a :class:`Scenario`, with
    the keyword overrides applied (None keeps the scenario's value)."""
    from dcee.scenarios import load_scenario

    base = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    return base.with_overrides(
        **{
            "search.particles": particles,
            "search.budget": budget,
            "unknown": unknown,
            "truth.model": truth_choice(truth) if truth is not None else None,
            "estimator.likelihood": likelihood,
            "agent.count": count,
        }
    )


@dataclass(frozen=True)
class EpisodeRules:
    """Reward and episode end, shared by the single- and multi-robot environments (see
    :class:`SourceSearchEnv`); built with :meth:`checked`, which names a bad keyword."""

    reward: str = "spread"
    time_penalty: float = 0.0
    success_bonus: float = 0.0
    converged_spread: float = 0.5

    @classmethod
    def checked(
        cls, reward: str, time_penalty: float, success_bonus: float, converged_spread: float
    ) -> EpisodeRules:
        if reward not in REWARDS:
            raise DceeInputError("reward", f"must be one of {', '.join(REWARDS)}, got {reward!r}")
        for name, value in (
            ("time_penalty", time_penalty),
            ("success_bonus", success_bonus),
            ("converged_spread", converged_spread),
        ):
            if isinstance(value, bool) or not (
                isinstance(value, int | float) and math.isfinite(value) and value >= 0
            ):
                raise DceeInputError(name, f"must be a finite number >= 0, got {value!r}")
        return cls(reward, float(time_penalty), float(success_bonus), float(converged_spread))

    def outcome(
        self, before: dict[str, Any], after: dict[str, Any], finished: bool
    ) -> tuple[float, bool, bool]:
        """(reward, terminated, truncated) of a step from the belief records before and after
        it; ``finished``: no further move fits the budget."""
        reward = float(before[self.reward] - after[self.reward]) - self.time_penalty
        terminated = bool(after["spread"] < self.converged_spread)
        if terminated:
            reward += self.success_bonus
        return reward, terminated, bool(not terminated and finished)


def check_render_mode(render_mode: str | None) -> None:
    """:class:`DceeInputError` unless ``render_mode`` is None or ``"rgb_array"``."""
    if render_mode not in (None, "rgb_array"):
        raise DceeInputError("render_mode", f"must be None or 'rgb_array', got {render_mode!r}")


def observation_space() -> spaces.Box:
    """The per-robot observation space (see :data:`OBSERVATION_FIELDS`)."""
    high = np.ones(len(OBSERVATION_FIELDS), dtype=np.float32)
    high[OBSERVATION_FIELDS.index("log_reading")] = MAX_LOG_READING
    return spaces.Box(np.zeros(len(OBSERVATION_FIELDS), np.float32), high, dtype=np.float32)


def action_mask(sim: SearchSimulation, position: np.ndarray) -> np.ndarray:
    """(H,) int8: 1 for the moves from ``position`` that stay inside the area (H: the headings,
    then climb and descend with ``agent.climb`` > 0)."""
    mask = np.zeros(sim.agent.n_moves, dtype=np.int8)
    mask[sim.agent.candidates(position)[1]] = 1
    return mask


def heading_target(sim: SearchSimulation, position: np.ndarray, heading: int) -> np.ndarray | None:
    """(3,) the position one step from ``position`` along ``heading``; None if it leaves the
    area."""
    candidates, headings = sim.agent.candidates(position)
    hit = np.flatnonzero(headings == heading)
    return candidates[hit[0]] if len(hit) else None


def observe(sim: SearchSimulation, rec: dict[str, Any], position: np.ndarray) -> np.ndarray:
    """One robot's observation: its ``position`` and the reading of its record ``rec``, and the
    shared belief after the step's readings (the simulation's last record)."""
    volume = sim.scenario.volume
    low = np.asarray(volume.low, dtype=np.float64)
    size = np.asarray(volume.high, dtype=np.float64) - low

    def fraction(values: np.ndarray) -> np.ndarray:
        out = np.zeros(3)
        flat = size <= 0
        out[~flat] = (values[~flat] - low[~flat]) / size[~flat]
        return out

    shared = sim.records[-1]
    sd = np.sqrt(np.maximum([shared["cov_xx"], shared["cov_yy"], shared["cov_zz"]], 0.0))
    obs = np.concatenate(
        [
            fraction(np.asarray(position, dtype=np.float64)),
            [math.log1p(max(rec["reading"], 0.0)), float(rec["detection"])],
            fraction(np.array([shared["mean_x"], shared["mean_y"], shared["mean_z"]])),
            sd / np.where(size > 0, size, np.inf),
            [shared["ess"] / sim.filter.n, shared["time"] / sim.scenario.search.budget],
        ]
    )
    space = observation_space()
    return np.clip(obs, space.low, space.high).astype(np.float32)
