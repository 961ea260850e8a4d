"""One-stage predicted-posterior statistics in single precision: the planners' opt-in
``precision="single"`` (issue 46).

The weights of a hypothesised reading, e_i = w_i exp(ll_i − bound), cost one ``exp`` per
particle and task, and the KL divergence one ``log`` more: at paper scale (20,000 particles,
8 moves × 41 hypotheses) these dominate a decision. Here they are float32 arithmetic
(:func:`dcee.numeric.exp_f32`, :func:`dcee.numeric.log_f32`: twice the SIMD lanes and shorter
polynomials, relative error a few 1e-7), while the weights w_i, the location offsets and every
sum stay float64, summed in the fixed order of :mod:`dcee.planning.block_sums` (results do not
depend on the thread count). Each statistic then carries a relative error of about 1e-6;
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
from dcee.planning.block_sums import product_sum as _product_sum

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
    e: np.ndarray,
    el: np.ndarray,
) -> None:
    """e[q] = exp(ll_i − bnd) and el[q] = e[q] · (ll_i − bnd), float32, for particles
    i = i0 + q, q < n, of one position row (float32 rows) and one transformed reading v
    (``out_term`` = exp(outlier term − bnd)). Branch-free loops that LLVM vectorises."""
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
            eq = _F32(exp_f32(min(a, _ZERO)) + out_term)
            e[np.uint64(q)] = eq
            el[np.uint64(q)] = _F32(eq * log_f32(eq))
        return
    for q in range(n):
        i = np.uint64(i0 + q)
        r = _F32(_F32(v - loc[i]) * inv_sigma[i])
        lq = max(_F32(_F32(det_offset[i] + det_add) - _HALF * r * r - bnd), EXP_F32_FLOOR)
        eq = exp_f32(min(lq, _ZERO))
        e[np.uint64(q)] = eq
        el[np.uint64(q)] = _F32(eq * lq)


@njit(cache=True, parallel=True, fastmath={"contract"}, error_model="numpy")
def single_stage_stats_f32(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
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
    tasks read; weighted (5, M) float64: w, w·dx, w·dy, w·dz, w·|d|² (offsets from the
    caller's centre); task_row (S,) into the U rows, equal within each group
    group_start[g]..group_start[g+1]−1; task_v, task_out (S,): transformed reading and outlier
    term; bound (S,). Sums not wanted are left at zero."""
    n = weighted.shape[1]
    n_groups = group_start.shape[0] - 1
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    v_thr = _F32(v_threshold)
    add = _F32(det_add)
    for item in prange(n_groups * n_blocks):
        g = item // n_blocks
        b = item % n_blocks
        s0 = group_start[g]
        i_start = b * _BLOCK
        nb = min(n, i_start + _BLOCK) - i_start
        p = task_row[s0]
        e = np.empty(_BLOCK, dtype=np.float32)
        el = np.empty(_BLOCK, dtype=np.float32)
        buf = np.empty(_BLOCK)
        for s in range(s0, group_start[g + 1]):
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
                e,
                el,
            )
            e0 = _product_sum(e, weighted[0], i_start, nb, buf)
            partial[b, s, 0] = e0
            for a in range(4):
                partial[b, s, 1 + a] = (
                    _product_sum(e, weighted[1 + a], i_start, nb, buf) if want_moments else 0.0
                )
            partial[b, s, 5] = (
                bound[s] * e0 + _product_sum(el, weighted[0], i_start, nb, buf) if want_kl else 0.0
            )


def single_stage_sums(
    terms: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    offsets: np.ndarray,
    weights: np.ndarray,
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
    inv_sigma, det_offset), each (P, N): the rows the tasks read are copied to float32 once."""
    used, task_row = np.unique(task_positions[:, 0], return_inverse=True)
    rows32 = [np.ascontiguousarray(t[used], dtype=np.float32) for t in terms]
    weighted = np.empty((5, len(weights)))
    weighted[0] = weights
    if want_moments:
        np.multiply(offsets, weights, out=weighted[1:])
    else:
        weighted[1:] = 0.0
    single_stage_stats_f32(
        *rows32,
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
