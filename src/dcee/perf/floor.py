"""The "floor" reference of a decision: the same arithmetic as a hypothesis planner's kernel,
written as the plain compiled loop a careful engineer would write first (issue 17).

For every candidate position m and every hypothesised reading z_mj the predicted posterior
w'_i ∝ w_i p(z_mj | C_i(p_m)) is reduced to its log evidence, mean source location, trace of
the location covariance and KL divergence from the current weights. The plain loop hoists what
does not depend on the reading: per (position, particle) the concentration, the transformed
location, 1/σ, log P(non-detection) and log Pd − log σ (libm ``exp``/``erfc``/``log``). Then
every (m, j) task on its own makes two passes over the particles: the log-likelihood of each
(a lookup for a non-detection, a few flops for a detection) and the task's maximum, then the
weighted sums with libm ``exp``. Nothing is shared between tasks (identical readings are
evaluated again, each task loads its particle terms again), there is no bound in place of the
maximum and no vectorised ``exp``; tasks run in parallel on numba's threads like the planners'
kernels. ``dcee perf`` states the planners' decisions as a ratio to it, in the same run, on the
same belief and readings.

Tested against :func:`dcee.planning.predicted_reference.predicted_posterior_stats_reference`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.plume import IsotropicPlume
from dcee.models.plume_kernels import concentration_distance_grid
from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import (
    SensorParams,
    log_detection_probability,
    log_likelihood,
    transform,
)
from dcee.numeric import HALF_LOG_2PI, read_only_view


@njit(cache=True, parallel=True)
def _floor_position_terms(
    conc: np.ndarray,
    dist: np.ndarray,
    sp: SensorParams,
    loc: np.ndarray,
    inv_sigma: np.ndarray,
    log_nd: np.ndarray,
    det_offset: np.ndarray,
) -> None:
    """Per (position, particle): transformed location, 1/σ, log p(non-detection), log Pd − log σ."""
    m_count, n = conc.shape
    for i in prange(n):
        for m in range(m_count):
            c = conc[m, i]
            r = dist[m, i]
            mu, sigma = transform(c, r, sp)
            loc[m, i] = mu
            inv_sigma[m, i] = 1.0 / sigma
            log_nd[m, i] = log_likelihood(0.0, c, r, sp)
            det_offset[m, i] = log_detection_probability(r, sp) - math.log(sigma)


@njit(cache=True, parallel=True)
def _floor_tasks(
    conc: np.ndarray,
    dist: np.ndarray,
    loc: np.ndarray,
    inv_sigma: np.ndarray,
    log_nd: np.ndarray,
    det_offset: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    center: np.ndarray,
    readings: np.ndarray,
    sp: SensorParams,
    out: np.ndarray,
) -> None:
    """out[m, j] = (log evidence, mean x, mean y, mean z, trace, KL) of reading j at position m.

    conc, dist and the position terms (M, N); source (N, 3); weights (N,) normalised; center
    (3,) the prior mean (subtracted before second moments are formed, for accuracy); readings
    (M, J) g/m³. The plain likelihood of a detection (Gaussian or log-normal, no false alarms,
    no outliers) from the hoisted terms; other sensors take the full scalar likelihood."""
    n = conc.shape[1]
    m_count, j_count = readings.shape
    simple = sp.false_alarm == 0.0 and sp.log_outlier == -np.inf
    for task in prange(m_count * j_count):
        m = task // j_count
        j = task % j_count
        z = readings[m, j]
        detected = z >= sp.threshold
        v = 0.0
        if detected:
            v = math.log(z) if sp.lognormal > 0.0 else z
        ll = np.empty(n)
        mx = -np.inf
        for i in range(n):
            if not detected:
                li = log_nd[m, i]
            elif simple:
                x = (v - loc[m, i]) * inv_sigma[m, i]
                li = det_offset[m, i] - 0.5 * x * x - HALF_LOG_2PI
            else:
                li = log_likelihood(z, conc[m, i], dist[m, i], sp)
                if sp.lognormal > 0.0:
                    li += v  # the Jacobian −ln z is common to all particles; kept below
            ll[i] = li
            if weights[i] > 0.0 and li > mx:
                mx = li
        s0 = 0.0
        sx = 0.0
        sy = 0.0
        sz = 0.0
        ss = 0.0
        sl = 0.0
        for i in range(n):
            if weights[i] <= 0.0:
                continue
            e = weights[i] * math.exp(ll[i] - mx)
            if e == 0.0:
                continue
            x = source[i, 0] - center[0]
            y = source[i, 1] - center[1]
            h = source[i, 2] - center[2]
            s0 += e
            sx += e * x
            sy += e * y
            sz += e * h
            ss += e * (x * x + y * y + h * h)
            sl += e * ll[i]
        log_ev = mx + math.log(s0)
        mean_x = sx / s0
        mean_y = sy / s0
        mean_z = sz / s0
        # KL(w' ‖ w) = Σ w'_i (ll_i − log evidence), before the Jacobian is added
        out[m, j, 5] = sl / s0 - log_ev
        if detected and sp.lognormal > 0.0:
            log_ev -= v
        out[m, j, 0] = log_ev
        out[m, j, 1] = center[0] + mean_x
        out[m, j, 2] = center[1] + mean_y
        out[m, j, 3] = center[2] + mean_z
        out[m, j, 4] = max(ss / s0 - (mean_x * mean_x + mean_y * mean_y + mean_z * mean_z), 0.0)


def floor_decision(
    theta: np.ndarray,
    weights: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    sensor: Sensor,
    plume: IsotropicPlume,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """(M, J, 6) statistics of the predicted posterior of every (position, reading) task by the
    plain loop: theta (N, 8), weights (N,) normalised, positions (M, 3) m, readings (M, J) g/m³
    (below the threshold: a non-detection). Columns: log evidence, mean source x, y, z (m),
    trace of the location covariance (m²), KL divergence from ``weights`` (nats)."""
    theta = np.ascontiguousarray(theta, dtype=np.float64)
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    readings = np.ascontiguousarray(readings, dtype=np.float64)
    shape = (positions.shape[0], theta.shape[0])
    conc, dist = np.empty(shape), np.empty(shape)
    concentration_distance_grid(
        read_only_view(theta),
        read_only_view(positions),
        plume.min_distance,
        *plume.shape,
        conc,
        dist,
    )
    terms = tuple(np.empty(shape) for _ in range(4))
    _floor_position_terms(conc, dist, sensor.params, *terms)
    if out is None:
        out = np.empty((*readings.shape, 6))
    source = np.ascontiguousarray(theta[:, :3])
    weights = np.ascontiguousarray(weights, dtype=np.float64)
    center = weights @ source
    _floor_tasks(conc, dist, *terms, source, weights, center, readings, sensor.params, out)
    return out
