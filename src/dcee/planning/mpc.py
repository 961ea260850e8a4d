"""Classic stochastic MPC (the paper's eq. for MPC): exploitation only."""

from __future__ import annotations

from typing import Any

import numpy as np

from dcee.models.agent import GridAgent
from dcee.planning.base import Belief, Planner, register


@register("mpc")
class MPCPlanner(Planner):
    """J(u) = ‖p_{k+1} − s̄_{k|k}‖²: move towards the current posterior mean (the term P_{k|k}
    does not depend on u and is dropped). No hypothesised readings are needed."""

    summary = "MPC: move towards the posterior mean (exploitation only)"

    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        d = candidates - belief.source_mean()[None, :]
        return np.einsum("mk,mk->m", d, d), {}
