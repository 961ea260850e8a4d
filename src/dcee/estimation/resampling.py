"""Resampling a weighted particle set: systematic resampling and the effective sample size."""

from __future__ import annotations

import numpy as np


def systematic_resample(weights: np.ndarray, rng: np.random.Generator, n: int) -> np.ndarray:
    """n indices drawn ∝ weights by systematic sampling (one uniform, O(N + n), no sorting)."""
    cumulative = np.cumsum(weights)
    cumulative[-1] = 1.0  # guard against round-off
    points = (rng.random() + np.arange(n)) / n
    return np.searchsorted(cumulative, points, side="right").clip(0, len(weights) - 1)


def effective_sample_size(weights: np.ndarray) -> float:
    """1 / Σ w², of normalised weights (N for equal weights, 1 for one particle)."""
    return float(1.0 / np.sum(weights * weights))


def normalised_weights(logw: np.ndarray) -> np.ndarray:
    """(N,) weights summing to 1 from (N,) log-weights (shifted by their maximum first)."""
    w = np.exp(logw - logw.max())
    return w / w.sum()
