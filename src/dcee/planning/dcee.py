"""DCEE: dual control for exploration and exploitation (the paper's theorem 1)."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import Belief, register
from dcee.planning.predicted import OneStepPlanner, SequenceStats, dcee_cost


@register("dcee")
class DCEEPlanner(OneStepPlanner):
    """J(u) = E_ẑ[‖p_{k+1} − s̄_{k+1|k}‖² + tr P_{k+1|k}]: move towards where the source will be
    believed to be *after* the next reading, penalising the uncertainty that will remain."""

    needs_kl = False

    def cost_from_stats(
        self, candidates: np.ndarray, stats: SequenceStats, belief: Belief
    ) -> np.ndarray:
        return dcee_cost(candidates, stats)
