"""Entrotaxis (Hutchinson et al. 2018): sample where the next reading is least predictable."""

from __future__ import annotations

import numpy as np

from dcee.planning.base import Belief, register
from dcee.planning.hypothesis import HypothesisPlanner
from dcee.planning.predicted import SequenceStats


@register("entrotaxis")
class EntrotaxisPlanner(HypothesisPlanner):
    """Maximise the entropy of the predictive distribution of the next reading,
    p(ẑ | Z_k) = Σ_i w_i p(ẑ | Θ_i), estimated over the shared hypothesised readings:
    H = −E[log P(ẑ)]. Loss = log P(ẑ).

    The reading is part discrete (non-detection) and part continuous, so its entropy needs a
    resolution: we discretise detections at the sensor's own noise scale σ(z) = σ_frac·z + σ_min,
    i.e. P(ẑ) = p(ẑ)·σ(ẑ) for a detection and the probability mass for a non-detection. A raw
    density in (g/m³)⁻¹ would make the entropy depend on the concentration unit and, at these
    scales (σ ~ 1e-4 g/m³), negative, so the rule would *avoid* informative places.
    """

    summary = "Entrotaxis: maximise the entropy of the next reading"

    needs_moments = False
    needs_kl = False

    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        s = belief.sensor
        z = stats.readings  # (S, J, T): over several stages the resolutions multiply
        resolution = np.where(z >= s.threshold, s.sigma_frac * z + s.sigma_min, 1.0)
        return stats.log_evidence + np.log(resolution).sum(axis=2)
