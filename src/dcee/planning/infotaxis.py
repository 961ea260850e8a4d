"""Infotaxis in its KL form: move where the next reading is expected to teach the most."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import Belief, register
from dcee.planning.predicted import OneStepPlanner, SequenceStats


@register("infotaxis")
class InfotaxisPlanner(OneStepPlanner):
    """Maximise the expected information gain E_ẑ[KL(p(Θ | Z_k, ẑ) ‖ p(Θ | Z_k))] (the mutual
    information between the next reading and Θ), estimated over the shared hypothesised
    readings. Cost = −expected KL."""

    needs_moments = False

    def cost_from_stats(
        self, candidates: np.ndarray, stats: SequenceStats, belief: Belief
    ) -> np.ndarray:
        return -stats.kl.mean(axis=1)
