"""Summaries of a weighted particle set that every estimator reports: the RMSE about a point and
whether a point lies in the posterior's credible region."""

from __future__ import annotations

import math

import numpy as np


def weighted_rmse(points: np.ndarray, weights: np.ndarray, truth: np.ndarray) -> float:
    """√(Σ wᵢ ‖xᵢ − x‖²) of points (N, D) with normalised weights (N,) about ``truth`` (D,)."""
    d = points - np.asarray(truth)[None, :]
    return float(math.sqrt(weights @ np.einsum("ij,ij->i", d, d)))


def in_credible_ellipsoid(
    points: np.ndarray, weights: np.ndarray, truth: np.ndarray, level: float = 0.95
) -> bool:
    """Whether ``truth`` (D,) lies in the ``level`` credible region of the weighted points
    (N, D), weights (N,) normalised.

    The region is the ellipsoid, shaped by the weighted covariance, that holds ``level`` of the
    mass: the truth is inside when its Mahalanobis distance is at most the weighted ``level``
    quantile of the points' distances (no Gaussian assumption on the radial profile). Over many
    searches a calibrated filter contains the truth ``level`` of the time.
    """
    mean = weights @ points
    cov = np.atleast_2d(np.cov(points, rowvar=False, aweights=weights, ddof=0))
    inv = np.linalg.pinv(cov)
    d = points - mean
    dist = np.einsum("ij,jk,ik->i", d, inv, d)
    t = np.asarray(truth, dtype=np.float64) - mean
    order = np.argsort(dist)
    cum = np.cumsum(weights[order])
    cutoff = dist[order][min(int(np.searchsorted(cum, level)), len(cum) - 1)]
    return bool(t @ inv @ t <= cutoff)


__all__ = ["in_credible_ellipsoid", "weighted_rmse"]
