"""DCEE: dual control for exploration and exploitation (the paper's theorem 1 and its
multistage cost)."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import Belief, register
from dcee.planning.hypothesis import HypothesisPlanner, squared_distance
from dcee.planning.predicted import SequenceStats


@register("dcee")
class DCEEPlanner(HypothesisPlanner):
    """J(u) = E_ẑ[‖p_{k+1} − s̄_{k+1|k}‖² + tr P_{k+1|k}]: move towards where the source will be
    believed to be *after* the next reading, penalising the uncertainty that will remain.

    With hypotheses drawn from the predictive distribution its expectation equals the MPC cost
    plus tr P_{k|k} (law of total variance, tested): in expectation this is MPC. See
    ``dcee-cl`` for the closed-loop form that explores."""

    summary = "DCEE, theorem 1 (one step, open loop): MPC in expectation"

    needs_kl = False

    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        return squared_distance(final_positions, stats, belief.site) + stats.trace_cov


@register("dcee-ms")
class MultistageDCEEPlanner(DCEEPlanner):
    """The paper's multistage DCEE: J(U) = E[‖p_{k+H|k} − s̄_{k+H|k}‖² + tr P_{k+H|k}] over
    hypothesised readings at every stage of U = (u_k, …, u_{k+H−1}), receding horizon (default
    H = 2, beam search, see :mod:`dcee.planning.hypothesis`)."""

    summary = "multistage DCEE (the paper), receding horizon by beam search"

    default_horizon = 2
