"""Compiled (numba) filter kernel; NumPy reference:
:func:`dcee.estimation.particle_filter.history_log_likelihood_reference`."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dcee.models.plume_kernels import plume_at, plume_terms
from dcee.models.sensor_kernels import SensorParams, log_likelihood


@njit(cache=True, parallel=True)
def history_log_likelihood(
    theta: np.ndarray,
    active: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    rmin: float,
    meander: float,
    sp: SensorParams,
    out: np.ndarray,
):
    """out[i] = Σ_k multiplicity[k] · log p(readings[k] | C(positions[k]; theta[i])).

    Particles with ``active[i]`` False get −inf (used for proposals outside the prior's support).
    theta (N, 8); positions (K, 3); readings, multiplicity (K,); out (N,).
    """
    n = theta.shape[0]
    k_count = readings.shape[0]
    for i in prange(n):
        if not active[i]:
            out[i] = -np.inf
            continue
        terms = plume_terms(theta, i)
        acc = 0.0
        for k in range(k_count):
            c, r = plume_at(terms, positions[k, 0], positions[k, 1], positions[k, 2], rmin, meander)
            acc += multiplicity[k] * log_likelihood(readings[k], c, r, sp)
        out[i] = acc
