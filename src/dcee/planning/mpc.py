"""Classic stochastic MPC (the paper's eq. for MPC): exploitation only."""

from __future__ import annotations

from typing import Any

import numpy as np

from dcee.models.agent import GridAgent, travel_xy
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
        mean = belief.source_mean()
        d = candidates - mean[None, :]
        if belief.site is None:
            return np.einsum("mk,mk->m", d, d), {}
        # around obstacles: the travel distance from each candidate to the mean
        xy = np.array([travel_xy(belief.site, c, mean) for c in candidates])
        return xy * xy + d[:, 2] * d[:, 2], {}
