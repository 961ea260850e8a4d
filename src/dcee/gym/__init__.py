"""Gymnasium interface: source search as a reinforcement-learning environment (extra ``gym``).

Importing this module registers ``dcee/SourceSearch-v0``::

    import gymnasium
    import dcee.gym

    env = gymnasium.make("dcee/SourceSearch-v0", scenario="paper:1", particles=2000)
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(info["action_mask"].argmax())

:class:`SourceSearchEnv` documents the observation, actions, rewards and episode end;
:class:`PlannerPolicy` lets any registered planner act in it (a reference policy scored on the
same seeds and metrics as a learned one); :func:`evaluate` runs policies over seeds.

:func:`multi_search_env` returns ``dcee/MultiSearch-v0``, K robots sharing one belief, as a
PettingZoo ``ParallelEnv`` (PettingZoo has no registry; the name is its ``metadata["name"]``
and this documentation's).
"""

from __future__ import annotations

import gymnasium

from dcee.gym.common import OBSERVATION_FIELDS, REWARDS, EnvOptions
from dcee.gym.env import SourceSearchEnv
from dcee.gym.multi import MultiSearchEnv, multi_search_env
from dcee.gym.policy import PlannerPolicy, RandomPolicy, evaluate

ENV_ID = "dcee/SourceSearch-v0"
MULTI_ENV_ID = "dcee/MultiSearch-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="dcee.gym.env:SourceSearchEnv")

__all__ = [
    "ENV_ID",
    "MULTI_ENV_ID",
    "OBSERVATION_FIELDS",
    "REWARDS",
    "EnvOptions",
    "MultiSearchEnv",
    "PlannerPolicy",
    "RandomPolicy",
    "SourceSearchEnv",
    "evaluate",
    "multi_search_env",
]
