"""Summaries of a weighted particle set that every estimator reports: the RMSE about a point and
whether a point lies in the posterior's credible region."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dcee.numeric import read_only_view


@njit(cache=True)
def _weighted_sq_distance(points: np.ndarray, weights: np.ndarray, truth: np.ndarray) -> float:
    total = 0.0
    for i in range(points.shape[0]):
        d2 = 0.0
        for c in range(points.shape[1]):
            d = points[i, c] - truth[c]
            d2 += d * d
        total += weights[i] * d2
    return total


def weighted_rmse(points: np.ndarray, weights: np.ndarray, truth: np.ndarray) -> float:
    """√(Σ wᵢ ‖xᵢ − x‖²) of points (N, D) with normalised weights (N,) about ``truth`` (D,).

    Compiled: it runs after every reading of a simulated search (the record's RMSE), where the
    NumPy form took 0.4 ms at 20,000 particles."""
    p = np.asarray(points, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    truth = np.asarray(truth, dtype=np.float64)
    return float(math.sqrt(_weighted_sq_distance(read_only_view(p), w, truth)))


@njit(cache=True)
def _location_moments(p: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The three-column case unrolled into scalars (the source location after every reading:
    0.11 against 0.6 ms for the general loop at 20,000 particles)."""
    t = sx = sy = sz = 0.0
    for i in range(p.shape[0]):
        wi = weights[i]
        t += wi
        sx += wi * p[i, 0]
        sy += wi * p[i, 1]
        sz += wi * p[i, 2]
    mx, my, mz = sx / t, sy / t, sz / t
    cxx = cxy = cxz = cyy = cyz = czz = 0.0
    for i in range(p.shape[0]):
        wi = weights[i]
        dx = p[i, 0] - mx
        dy = p[i, 1] - my
        dz = p[i, 2] - mz
        cxx += wi * dx * dx
        cxy += wi * dx * dy
        cxz += wi * dx * dz
        cyy += wi * dy * dy
        cyz += wi * dy * dz
        czz += wi * dz * dz
    cov = np.array([[cxx, cxy, cxz], [cxy, cyy, cyz], [cxz, cyz, czz]]) / t
    return np.array([mx, my, mz]), cov


@njit(cache=True)
def _weighted_moments(points: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n, d = points.shape
    if d == 3:
        return _location_moments(points, weights)
    total = 0.0
    mean = np.zeros(d)
    for i in range(n):
        total += weights[i]
        for c in range(d):
            mean[c] += weights[i] * points[i, c]
    mean /= total
    cov = np.zeros((d, d))
    dev = np.empty(d)
    for i in range(n):
        for c in range(d):
            dev[c] = points[i, c] - mean[c]
        for a in range(d):
            wa = weights[i] * dev[a]
            for b in range(a, d):
                cov[a, b] += wa * dev[b]
    for a in range(d):
        for b in range(a, d):
            cov[a, b] /= total
            cov[b, a] = cov[a, b]
    return mean, cov


def weighted_moments(points: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted mean (D,) and covariance (D, D) of points (N, D) with weights (N,) ≥ 0 (not
    necessarily normalised): Σ wᵢ xᵢ / Σ wᵢ and Σ wᵢ (xᵢ − x̄)(xᵢ − x̄)ᵀ / Σ wᵢ, what
    ``np.cov(points, rowvar=False, aweights=weights, ddof=0)`` gives (tested), in two compiled
    passes: the posterior summary is formed after every reading (at 20,000 particles NumPy took
    1.2 ms, a sixth of a whole MPC step)."""
    p = np.asarray(points, dtype=np.float64)  # a column view of the particles is read in place
    return _weighted_moments(read_only_view(p), np.asarray(weights, dtype=np.float64))


REGION_DRAWS = 20000
"""Draws of the floored posterior (:func:`in_credible_ellipsoid` with ``floor`` > 0): its 95 %
quantile then moves by about 1 % between two sets of draws."""

REGION_SEED = 20261202
"""Seed of the floored region's draws: a fixed generator, so the same particles give the same
answer (the region is a summary, not part of the search)."""


def credible_ellipsoid(
    points: np.ndarray,
    weights: np.ndarray,
    level: float = 0.95,
    floor: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, float]:
    """The ``level`` credible region of the weighted points (N, D), weights (N,) normalised, as
    (mean (D,), inverse covariance (D, D), cutoff): the points x with
    (x − mean)ᵀ inv (x − mean) ≤ cutoff.

    The region is the ellipsoid, shaped by the weighted covariance, that holds ``level`` of the
    mass: the cutoff is the weighted ``level`` quantile of the points' Mahalanobis distances (no
    Gaussian assumption on the radial profile). Over many searches a calibrated filter contains
    the truth ``level`` of the time.

    ``floor`` σ (m, ≥ 0) is a model-discrepancy scale: the region is that of the posterior
    convolved with an isotropic normal N(0, σ² I), the source's location as the points place it
    up to an error of the reading model that no reading removes (a point-source model of a
    plume released over an area, say). It is formed from :data:`REGION_DRAWS` draws of that
    mixture by a generator seeded with :data:`REGION_SEED`; 0 gives the points' own region.
    """
    if floor > 0.0:
        rng = np.random.default_rng(REGION_SEED)
        w = np.asarray(weights, dtype=np.float64)
        idx = rng.choice(len(w), size=REGION_DRAWS, p=w / w.sum())
        points = points[idx] + floor * rng.standard_normal((REGION_DRAWS, points.shape[1]))
        weights = np.full(REGION_DRAWS, 1.0 / REGION_DRAWS)
    mean, cov = weighted_moments(points, weights)
    inv = np.linalg.pinv(cov)
    d = points - mean
    dist = np.einsum("ij,jk,ik->i", d, inv, d)
    order = np.argsort(dist)
    cum = np.cumsum(weights[order])
    cutoff = dist[order][min(int(np.searchsorted(cum, level)), len(cum) - 1)]
    return mean, inv, float(cutoff)


def in_credible_ellipsoid(
    points: np.ndarray,
    weights: np.ndarray,
    truth: np.ndarray,
    level: float = 0.95,
    floor: float = 0.0,
) -> bool:
    """Whether ``truth`` (D,) lies in the ``level`` credible region of the weighted points
    (:func:`credible_ellipsoid`)."""
    mean, inv, cutoff = credible_ellipsoid(points, weights, level, floor)
    t = np.asarray(truth, dtype=np.float64) - mean
    return bool(t @ inv @ t <= cutoff)


def credible_ellipse_boundary(
    points: np.ndarray,
    weights: np.ndarray,
    level: float = 0.95,
    floor: float = 0.0,
    vertices: int = 72,
) -> np.ndarray:
    """(vertices, 2) points on the boundary of the ``level`` credible region of the weighted 2-D
    points (N, 2) (:func:`credible_ellipsoid`), counter-clockwise, not closed."""
    mean, inv, cutoff = credible_ellipsoid(points, weights, level, floor)
    values, vectors = np.linalg.eigh(inv)
    radii = np.sqrt(cutoff / np.maximum(values, 1e-300))
    angle = np.linspace(0.0, 2.0 * np.pi, vertices, endpoint=False)
    unit = np.stack([np.cos(angle), np.sin(angle)], axis=1) * radii
    boundary = mean + unit @ vectors.T
    if np.linalg.det(vectors) < 0:  # a reflection turns the order clockwise
        boundary = boundary[::-1]
    return boundary


__all__ = [
    "REGION_DRAWS",
    "REGION_SEED",
    "credible_ellipse_boundary",
    "credible_ellipsoid",
    "in_credible_ellipsoid",
    "weighted_moments",
    "weighted_rmse",
]
