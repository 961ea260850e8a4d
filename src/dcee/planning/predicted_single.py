"""One-stage predicted-posterior statistics in single precision: the planners' opt-in
``precision="single"`` (issue 46).

The weights of a hypothesised reading, e_i = w_i exp(ll_i − bound), cost one ``exp`` per
particle and task, and the KL divergence one ``log`` more: at paper scale (20,000 particles,
8 moves × 41 hypotheses) these dominate a decision. Here they are float32 arithmetic
(:func:`dcee.numeric.exp_f32`, :func:`dcee.numeric.log_f32`: twice the SIMD lanes and shorter
polynomials, relative error a few 1e-7), while the weights w_i, the location offsets and every
sum stay float64 (the float32 weights are widened when stored; the sums are the matrix products
of :mod:`dcee.planning.block_sums`). Each statistic then carries a relative error of about 1e-6;
decisions taken with it are compared with the double-precision ones by ``dcee perf``'s
agreement check (docs/performance.md).

Only one-stage tasks without false alarms take this path (the one-step planners' common case);
every other task is computed in double precision.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import EXP_F32_FLOOR, exp_f32, log_f32
from dcee.planning.block_sums import BLOCK as _BLOCK
from dcee.planning.block_sums import task_sums as _task_sums

_F32 = np.float32
_ZERO = _F32(0.0)
_HALF = _F32(0.5)

BOUND_SLACK_SINGLE = 60.0
"""A task whose best particle lies more than this many nats below its bound is redone exactly
in double precision: the float32 weights reach down to e^-87 (:data:`EXP_F32_FLOOR`), so every
particle within e^-27 of the best one is still resolved."""


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _weights_f32(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    i0: int,
    n: int,
    v: np.float32,
    out_term: np.float32,
    bnd: np.float32,
    v_threshold: np.float32,
    det_add: np.float32,
    with_outliers: bool,
    want_kl: bool,
    e: np.ndarray,
    el: np.ndarray,
) -> None:
    """e[q] = exp(ll_i − bnd) and, with ``want_kl``, el[q] = e[q] · (ll_i − bnd), float32, for
    particles i = i0 + q, q < n, of one
    position row (float32 rows) and one transformed reading v (``out_term`` =
    exp(outlier term − bnd)). One branch-free loop per case, which LLVM vectorises."""
    if v < v_threshold:
        for q in range(n):
            i = np.uint64(i0 + q)
            lq = max(_F32(log_nd[i] - bnd), EXP_F32_FLOOR)
            eq = exp_f32(min(lq, _ZERO))
            e[np.uint64(q)] = eq
            el[np.uint64(q)] = _F32(eq * lq)
        return
    if with_outliers:
        for q in range(n):
            i = np.uint64(i0 + q)
            r = _F32(_F32(v - loc[i]) * inv_sigma[i])
            a = _F32(_F32(det_offset[i] + det_add) - _HALF * r * r - bnd)
            e[np.uint64(q)] = _F32(exp_f32(min(a, _ZERO)) + out_term)
        if want_kl:
            for q in range(n):
                eq = _F32(e[np.uint64(q)])
                el[np.uint64(q)] = _F32(eq * log_f32(eq))
        return
    for q in range(n):
        i = np.uint64(i0 + q)
        r = _F32(_F32(v - loc[i]) * inv_sigma[i])
        lq = max(_F32(_F32(det_offset[i] + det_add) - _HALF * r * r - bnd), EXP_F32_FLOOR)
        eq = exp_f32(min(lq, _ZERO))
        e[np.uint64(q)] = eq
        el[np.uint64(q)] = _F32(eq * lq)


@njit(cache=True, error_model="numpy")
def _widen(src: np.ndarray, dst: np.ndarray) -> None:
    """dst[q] = src[q] (float32 to float64) for q < len(src)."""
    for q in range(src.shape[0]):
        dst[np.uint64(q)] = src[np.uint64(q)]


@njit(cache=True, parallel=True, fastmath={"contract"}, error_model="numpy")
def single_stage_stats_f32(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    weighted: np.ndarray,
    group_start: np.ndarray,
    task_row: np.ndarray,
    task_v: np.ndarray,
    task_out: np.ndarray,
    bound: np.ndarray,
    v_threshold: float,
    det_add: float,
    with_outliers: bool,
    want_moments: bool,
    want_kl: bool,
    partial: np.ndarray,
) -> None:
    """partial[b, s, :] = the six sums of one-stage task s over particle block b, as
    :func:`~dcee.planning.predicted_kernels._grouped_stats` forms them: Σe, Σe·dx, Σe·dy,
    Σe·dz, Σe·|d|², Σe·ll with e_i = w_i exp(ll_i − bound_s).

    loc, log_nd, inv_sigma, det_offset (U, M) float32: the position terms of the U rows the
    tasks read; weights (M,) and weighted (M, 5) float64: w, w·dx, w·dy, w·dz, w·|d|²
    (offsets from the caller's centre); task_row (S,) into the U rows, equal within each group
    group_start[g]..group_start[g+1]−1; task_v, task_out (S,): transformed reading and outlier
    term; bound (S,). Sums not wanted are left at zero."""
    n = weights.shape[0]
    n_groups = group_start.shape[0] - 1
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    v_thr = _F32(v_threshold)
    add = _F32(det_add)
    for item in prange(n_groups * n_blocks):
        g = item // n_blocks
        b = item % n_blocks
        s0 = group_start[g]
        k = group_start[g + 1] - s0
        i_start = b * _BLOCK
        nb = min(n, i_start + _BLOCK) - i_start
        p = task_row[s0]
        e = np.empty((k, nb))
        el = np.empty((k, nb))
        # float32 rows, widened after: a loop that stores float64 from float32 arithmetic
        # vectorises at half the width (measured 1.7 against 0.8 ns per particle)
        e32 = np.empty(nb, dtype=np.float32)
        el32 = np.empty(nb, dtype=np.float32)
        for j in range(k):
            s = s0 + j
            bnd = _F32(bound[s])
            out_term = exp_f32(min(_F32(task_out[s] - bound[s]), _ZERO))
            _weights_f32(
                loc[p],
                log_nd[p],
                inv_sigma[p],
                det_offset[p],
                i_start,
                nb,
                _F32(task_v[s]),
                out_term,
                bnd,
                v_thr,
                add,
                with_outliers,
                want_kl,
                e32,
                el32,
            )
            _widen(e32, e[j])
            if want_kl:
                _widen(el32, el[j])
        sums = np.empty((k, 6))
        _task_sums(e, el, weights, weighted, i_start, want_moments, want_kl, sums)
        for j in range(k):
            for a in range(6):
                partial[b, s0 + j, a] = sums[j, a]
            if want_kl:
                partial[b, s0 + j, 5] += bound[s0 + j] * sums[j, 0]


def single_stage_sums(
    terms: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    weights: np.ndarray,
    weighted: np.ndarray,
    group_start: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_out: np.ndarray,
    bound: np.ndarray,
    sp: SensorParams,
    want_moments: bool,
    want_kl: bool,
    partial: np.ndarray,
) -> None:
    """:func:`single_stage_stats_f32` from the double-precision position terms (loc, log_nd,
    inv_sigma, det_offset), each (P, N): the rows the tasks read are copied to float32 once;
    weights (N,), weighted (N, 5) as :func:`dcee.planning.block_sums.weighted_columns` gives."""
    used, task_row = np.unique(task_positions[:, 0], return_inverse=True)
    rows32 = [np.ascontiguousarray(t[used], dtype=np.float32) for t in terms]
    single_stage_stats_f32(
        *rows32,
        weights,
        weighted,
        group_start,
        task_row.astype(np.int64),
        np.ascontiguousarray(task_v[:, 0]),
        np.ascontiguousarray(task_out[:, 0]),
        bound,
        sp.v_threshold,
        sp.log_keep - 0.5 * np.log(2.0 * np.pi),
        sp.log_outlier > -np.inf,
        want_moments,
        want_kl,
        partial,
    )
