"""Infotaxis in its KL form: move where the next reading is expected to teach the most."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import Belief, register
from dcee.planning.hypothesis import HypothesisPlanner
from dcee.planning.predicted import SequenceStats


@register("infotaxis")
class InfotaxisPlanner(HypothesisPlanner):
    """Maximise the expected information gain E_ẑ[KL(p(Θ | Z_k, ẑ) ‖ p(Θ | Z_k))] (the mutual
    information between the next reading and Θ). Loss = −KL."""

    summary = "Infotaxis: maximise the expected information gain (KL)"

    needs_moments = False

    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        return -stats.kl
