"""Policies for :class:`~dcee.gym.SourceSearchEnv`: the planners as reference policies, a random
policy, and :func:`evaluate`, which scores any of them on the same seeds with the same metrics
as ``dcee run`` / ``dcee bench``."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, Protocol

import numpy as np
import pandas as pd

from dcee.errors import DceeInputError
from dcee.gym.env import SourceSearchEnv
from dcee.planning import get as get_planner
from dcee.runs import planner_defaults, streams


class Policy(Protocol):
    """What :func:`evaluate` runs: ``reset(env, seed)`` at the start of an episode, then
    ``act(env, observation, info) -> action`` at every step. A learned policy wraps its network
    in these two methods (it may ignore ``env`` and use only the observation)."""

    name: str

    def reset(self, env: SourceSearchEnv, seed: int) -> None: ...

    def act(self, env: SourceSearchEnv, observation: np.ndarray, info: dict[str, Any]) -> int: ...


class PlannerPolicy:
    """A registered planner (``infotaxis``, ``dcee-cl:reach=6``, …) acting in the environment.

    It reads the belief from the environment (:attr:`SourceSearchEnv.belief`), which a learned
    policy sees only through the observation. Its random draws come from the planner stream of
    the episode's seed (:func:`dcee.runs.streams`), so with the same seed it makes
    exactly the decisions ``dcee run --strategy SPEC --seed S`` makes.
    """

    def __init__(self, strategy: str, **options: Any) -> None:
        get_planner(strategy, **options)  # an unknown name or a bad option fails here
        self.name = strategy
        self.options = options
        self._planner: Any = None
        self._rng: np.random.Generator | None = None

    def reset(self, env: SourceSearchEnv, seed: int) -> None:
        scenario = env.unwrapped.scenario
        opts = planner_defaults(self.name, scenario, self.options)
        self._planner = get_planner(self.name, **opts)
        self._rng = streams(seed)[2]

    def act(self, env: SourceSearchEnv, observation: np.ndarray, info: dict[str, Any]) -> int:
        if self._planner is None or self._rng is None:
            raise DceeInputError("policy", "call reset(env, seed) before act()")
        base = env.unwrapped
        return self._planner.decide(base.belief, base.position, base.agent, self._rng).heading


class RandomPolicy:
    """Uniformly random admissible headings (``info["action_mask"]``), seeded per episode."""

    name = "random"

    def reset(self, env: SourceSearchEnv, seed: int) -> None:
        self._rng = np.random.default_rng([seed, 0x52414E44])

    def act(self, env: SourceSearchEnv, observation: np.ndarray, info: dict[str, Any]) -> int:
        return int(self._rng.choice(np.flatnonzero(info["action_mask"])))


def evaluate(
    policies: Iterable[Policy],
    seeds: Iterable[int],
    make_env: Callable[[], SourceSearchEnv] | None = None,
    **env_kwargs: Any,
) -> pd.DataFrame:
    """Run every policy for one episode per seed and return one row per (policy, seed): the
    summary ``dcee run`` writes (``final_rmse``, ``source_acquired``, ``time_to_rmse_1m`` …,
    with ``strategy`` = the policy's name) plus ``return`` (the summed reward) and ``steps``.

    The environment comes from ``make_env()`` or ``SourceSearchEnv(**env_kwargs)``; every policy
    sees the same seeds, hence the same truth and the same sensor noise (common random numbers).
    """
    env = make_env() if make_env is not None else SourceSearchEnv(**env_kwargs)
    seeds = [int(s) for s in seeds]
    rows = []
    for policy in policies:
        for seed in seeds:
            obs, info = env.reset(seed=seed)
            policy.reset(env, seed)
            total, done = 0.0, False
            while not done:
                obs, reward, terminated, truncated, info = env.step(policy.act(env, obs, info))
                total += float(reward)
                done = terminated or truncated
            row = env.unwrapped.result(policy.name).summary
            row["return"] = total
            rows.append(row)
    return pd.DataFrame(rows)
