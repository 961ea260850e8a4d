"""Weights of hypothesised reading sequences (several stages) over one block of particles,
vectorised over the particles (numba), for :func:`dcee.planning.predicted_kernels._grouped_stats`.

A task of T stages (a candidate sequence of T positions and one hypothesised reading at each)
gives particle i the relative weight e_i = exp(Σ_t ll_ti − bound) and, for the KL divergence,
e_i (Σ_t ll_ti − bound). The stages are summed one at a time into a block-long buffer: which case
a stage is (non-detection, detection with or without the outlier component) is decided once per
stage, outside the loop over particles, so every loop is branch-free arithmetic that LLVM turns
into SIMD. With the outlier component a detection stage's log(e^a + e^out) is split into
max(a, out), added, and 1 + e^-|a − out|, multiplied: one ``exp`` per detection stage and one
for the weight. The sums then come from :func:`dcee.planning.block_sums.task_sums` (two matrix
products per block and candidate sequence), as for one stage.

Measured (issue 46, 2026-11-27, `dcee-ms`, paper:1, 20,000 particles, one core): the previous
kernel looped over the hypotheses inside the loop over particles (about 15 ns per particle and
two-stage task); see docs/performance.md for this one's figure.

False alarms make a detection's term a log-sum-exp of two particle-dependent parts; tasks with
them keep the exact scalar loop of :mod:`dcee.planning.predicted_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import HALF_LOG_2PI, exp_scalar, log_scalar

EXP_FLOOR = -680.0
"""Exponents below this are taken as e^-680 (see dcee.planning.predicted_kernels._EXP_FLOOR)."""


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _add_stage(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    i0: int,
    n: int,
    v: float,
    out: float,
    sp: SensorParams,
    ll: np.ndarray,
    prod: np.ndarray,
) -> None:
    """Add one stage's log-likelihood of transformed reading v (outlier term ``out``) at one
    position row (1-D rows of :func:`~dcee.planning.position_kernels.position_rows`) to ll[q]
    for particles i = i0 + q, q < n; with the outlier component the detection's log-sum-exp
    factor 1 + e^-|a − out| is multiplied into prod[q]."""
    if v < sp.v_threshold:
        for q in range(n):
            ll[np.uint64(q)] += log_nd[np.uint64(i0 + q)]
        return
    det_add = sp.log_keep - HALF_LOG_2PI
    if sp.log_outlier > -np.inf:
        for q in range(n):
            i = np.uint64(i0 + q)
            r = (v - loc[i]) * inv_sigma[i]
            a = det_offset[i] + det_add - 0.5 * r * r
            hi = max(a, out)
            ll[np.uint64(q)] += hi
            prod[np.uint64(q)] *= 1.0 + exp_scalar(max(min(a, out) - hi, EXP_FLOOR))
        return
    for q in range(n):
        i = np.uint64(i0 + q)
        r = (v - loc[i]) * inv_sigma[i]
        ll[np.uint64(q)] += det_offset[i] + det_add - 0.5 * r * r


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def multi_stage_weights(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    positions: np.ndarray,
    i0: int,
    n: int,
    v: np.ndarray,
    out: np.ndarray,
    bnd: float,
    sp: SensorParams,
    want_kl: bool,
    e: np.ndarray,
    el: np.ndarray,
    ll: np.ndarray,
    prod: np.ndarray,
) -> None:
    """e[q] = exp(ll_i − bnd) and, with ``want_kl``, el[q] = e[q] (ll_i − bnd) for particles
    i = i0 + q, q < n, and one task of T stages: positions (T,) rows of the position terms
    loc, log_nd, inv_sigma, det_offset (P, N); v, out (T,) its transformed readings and outlier
    terms; ll_i = Σ_t log p(v_t | C_i(p_t)) less the Jacobians; ``bnd`` an upper bound of ll
    over the particles (:func:`~dcee.planning.reading_terms.task_bound`). ll, prod (≥ n,):
    scratch buffers."""
    for q in range(n):
        ll[np.uint64(q)] = -bnd
        prod[np.uint64(q)] = 1.0
    with_outliers = False
    for t in range(positions.shape[0]):
        p = positions[t]
        _add_stage(
            loc[p], log_nd[p], inv_sigma[p], det_offset[p], i0, n, v[t], out[t], sp, ll, prod
        )
        with_outliers |= v[t] >= sp.v_threshold and sp.log_outlier > -np.inf
    for q in range(n):
        x = ll[np.uint64(q)]
        e[np.uint64(q)] = exp_scalar(min(max(x, EXP_FLOOR), 0.0)) * prod[np.uint64(q)]
    if not want_kl:
        return
    if with_outliers:
        for q in range(n):
            el[np.uint64(q)] = e[np.uint64(q)] * (ll[np.uint64(q)] + log_scalar(prod[np.uint64(q)]))
        return
    for q in range(n):
        el[np.uint64(q)] = e[np.uint64(q)] * ll[np.uint64(q)]
