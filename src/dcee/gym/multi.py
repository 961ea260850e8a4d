"""``dcee/MultiSearch-v0``: K robots, one shared particle filter, as a PettingZoo ParallelEnv."""

from __future__ import annotations

import functools
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from dcee.errors import DceeInputError
from dcee.gym.common import (
    EnvOptions,
    action_mask,
    heading_target,
    observation_space,
    observe,
)
from dcee.runs import SearchSimulation


class MultiSearchEnv(ParallelEnv):
    """K robots search together; every reading updates one shared particle filter
    (centralised fusion), as in ``dcee run --agents K``.

    Agents ``robot_0`` … ``robot_{K-1}``. Each acts with ``Discrete(H)`` headings (its own
    ``infos[agent]["action_mask"]``) and observes the single-robot observation of
    :class:`~dcee.gym.SourceSearchEnv` with *its own* position, reading and detection and the
    *shared* belief summary. All robots move at once, in agent order: an inadmissible heading,
    or a move onto the cell an earlier robot has just taken (a collision), keeps that robot in
    place and sets ``infos[agent]["blocked"]``. The reward is shared (the team's posterior
    spread drop, as in the single-robot environment, minus ``time_penalty``, plus
    ``success_bonus`` on convergence); termination and truncation are the single-robot ones and
    end the episode for every robot at once.

    Keywords: ``agents`` K (default 2) and those of :class:`~dcee.gym.SourceSearchEnv`.
    """

    metadata: ClassVar[dict[str, Any]] = {
        "name": "dcee_multi_search_v0",
        "render_modes": ["rgb_array"],
        "is_parallelizable": True,
    }

    def __init__(self, **options: Any) -> None:
        options.setdefault("agents", 2)
        self.options = EnvOptions.from_keywords(**options)
        self.scenario, self.rules = self.options.build()
        render_mode = self.options.render_mode
        agents = self.scenario.agent.count
        self.render_mode = render_mode
        self.possible_agents = [f"robot_{k}" for k in range(agents)]
        self.agents: list[str] = []
        self.simulation: SearchSimulation | None = None
        self._rng = np.random.default_rng()

    @functools.cache  # noqa: B019 -- PettingZoo wants the same space object every call
    def observation_space(self, agent: str) -> spaces.Box:
        return observation_space()

    @functools.cache  # noqa: B019
    def action_space(self, agent: str) -> spaces.Discrete:
        return spaces.Discrete(self.scenario.make_agent().n_moves)

    def _sim(self) -> SearchSimulation:
        if self.simulation is None:
            raise DceeInputError("reset", "call reset() before step() or render()")
        return self.simulation

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict[str, Any]]]:
        """Start a new search with search seed ``seed`` (as ``dcee run --seed``); without one,
        a seed is drawn from the environment's own generator (seeded by the last seed given)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        run_seed = int(seed) if seed is not None else int(self._rng.integers(2**31))
        self.simulation = SearchSimulation(self.scenario, run_seed)
        self.agents = list(self.possible_agents)
        records = self.simulation.sense()
        blocked = dict.fromkeys(self.agents, False)
        return self._observations(records), self._infos(records, blocked)

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], ...]:
        sim = self._sim()
        if not self.agents:
            raise DceeInputError("step", "the episode has ended; call reset()")
        if not isinstance(actions, dict):
            raise DceeInputError(
                "actions", f"must be a dict of robot name to heading index, got {actions!r}"
            )
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise DceeInputError("actions", f"give an action for every robot; missing {missing}")
        unknown = sorted(str(a) for a in actions if a not in self.possible_agents)
        if unknown:  # a misspelt name would otherwise be ignored
            raise DceeInputError(
                "actions", f"no robot named {unknown}; the robots: {self.possible_agents}"
            )
        before = sim.records[-1]
        targets, blocked = [], {}
        for k, agent in enumerate(self.agents):
            action = actions[agent]
            if not self.action_space(agent).contains(action):
                raise DceeInputError(
                    "actions", f"{agent}: a heading index in [0, {self.action_space(agent).n})"
                )
            target = heading_target(sim, sim.positions[k], int(action))
            taken = any(np.allclose(target, t) for t in targets) if target is not None else False
            blocked[agent] = target is None or taken
            targets.append(sim.positions[k].copy() if blocked[agent] else target)
        sim.move(np.array(targets))
        records = sim.sense()
        reward, terminated, truncated = self.rules.outcome(before, records[-1], sim.finished)
        agents = list(self.agents)
        obs, infos = self._observations(records), self._infos(records, blocked)
        if terminated or truncated:
            self.agents = []
        return (
            obs,
            dict.fromkeys(agents, reward),
            dict.fromkeys(agents, terminated),
            dict.fromkeys(agents, truncated),
            infos,
        )

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        from dcee.analysis.figures import render_search
        from dcee.runs import EpisodeResult

        sim = self._sim()
        result = EpisodeResult(
            sim.records, sim.summary("policy"), sim.filter.theta, sim.filter.weights, [], {}
        )
        return render_search(result, self.scenario, sim.truth)

    def close(self) -> None:
        pass

    def _observations(self, records: list[dict[str, Any]]) -> dict[str, np.ndarray]:
        sim = self._sim()
        return {
            agent: observe(sim, records[k], sim.positions[k])
            for k, agent in enumerate(self.possible_agents)
        }

    def _infos(
        self, records: list[dict[str, Any]], blocked: dict[str, bool]
    ) -> dict[str, dict[str, Any]]:
        sim = self._sim()
        shared = records[-1]
        return {
            agent: {
                "action_mask": action_mask(sim, sim.positions[k]),
                "blocked": blocked[agent],
                "time": shared["time"],
                "spread": shared["spread"],
                "rmse": shared["rmse"],
                "detection": records[k]["detection"],
            }
            for k, agent in enumerate(self.possible_agents)
        }


def multi_search_env(**kwargs: Any) -> MultiSearchEnv:
    """A :class:`MultiSearchEnv` (``dcee/MultiSearch-v0``): K robots (``agents``, default 2)
    sharing one belief, as a PettingZoo ``ParallelEnv``."""
    return MultiSearchEnv(**kwargs)
