"""Entrotaxis (Hutchinson et al. 2018): sample where the next reading is least predictable."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import Belief, register
from dcee.planning.predicted import OneStepPlanner, SequenceStats


@register("entrotaxis")
class EntrotaxisPlanner(OneStepPlanner):
    """Maximise the entropy of the predictive distribution of the next reading,
    p(ẑ | Z_k) = Σ_i w_i p(ẑ | Θ_i), estimated by Monte Carlo over the shared hypothesised
    readings (which are draws from p(ẑ | Z_k)): H ≈ −mean_j log P(ẑ_j). Cost = −H.

    The reading is part discrete (non-detection) and part continuous, so its entropy needs a
    resolution: we discretise detections at the sensor's own noise scale σ(z) = σ_frac·z + σ_min,
    i.e. P(ẑ) = p(ẑ)·σ(ẑ) for a detection and the probability mass for a non-detection. A raw
    density in (g/m³)⁻¹ would make the entropy depend on the concentration unit and, at these
    scales (σ ~ 1e-4 g/m³), negative, so the rule would *avoid* informative places.
    """

    needs_moments = False
    needs_kl = False

    def cost_from_stats(
        self, candidates: np.ndarray, stats: SequenceStats, belief: Belief
    ) -> np.ndarray:
        s = belief.sensor
        z = stats.readings[..., 0]
        resolution = np.where(z >= s.threshold, s.sigma_frac * z + s.sigma_min, 1.0)
        return np.mean(stats.log_evidence + np.log(resolution), axis=1)
