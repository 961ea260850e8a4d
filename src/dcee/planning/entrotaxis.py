"""Entrotaxis (Hutchinson et al. 2018): sample where the next reading is least predictable."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import register
from dcee.planning.predicted import OneStepPlanner, SequenceStats


@register("entrotaxis")
class EntrotaxisPlanner(OneStepPlanner):
    """Maximise the entropy H = −E[log p(ẑ | Z_k)] of the predictive distribution of the next
    reading. p(ẑ | Z_k) = Σ_i w_i p(ẑ | Θ_i) is a mixed distribution (a probability mass for a
    non-detection, a density above the threshold); H is its entropy with respect to that
    reference measure, estimated by Monte Carlo over the shared hypothesised readings, which are
    draws from p(ẑ | Z_k). Cost = −H."""

    def cost_from_stats(self, candidates: np.ndarray, stats: SequenceStats) -> np.ndarray:
        return stats.log_evidence.mean(axis=1)
