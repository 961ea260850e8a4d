"""The sums of one-stage tasks that need neither the location moments nor more than the
evidence and the KL divergence (infotaxis, entrotaxis): weights and sums in one pass (issue 46).

The general kernel (:func:`dcee.planning.predicted_kernels._grouped_stats`) stores each
reading's relative weights e_i = exp(ll_i − bound) for a block of particles and forms the sums
as matrix products with the five weighted columns, which pays when the moments are wanted. A
planner that reads only Σ w e and Σ w e ll gets them here while the weights are computed:
nothing stored, no BLAS call per block and reading. The sums are reassociated (eight SIMD
partial sums, LLVM's order), so they differ from the general kernel's in the last bits (about
1e-15 relative); measured on Stone Soup's STE workload (10,000 particles, 9 moves × 4
readings): 0.08 against 0.17 ms per decision's sums, hot.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import HALF_LOG_2PI, exp_scalar, log_scalar
from dcee.planning.block_sums import BLOCK
from dcee.planning.multi_stage_kernels import EXP_FLOOR  # weights stay normal floats
from dcee.planning.reading_terms import task_setup


@njit(cache=True, parallel=True, fastmath={"contract", "reassoc"}, error_model="numpy")
def one_stage_sums(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    group_start: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_out: np.ndarray,
    bound: np.ndarray,
    sp: SensorParams,
    want_kl: bool,
    partial: np.ndarray,
) -> None:
    """partial[b, s] = (Σ w e, 0, 0, 0, 0, Σ w e ll) of one-stage task s over particle block b
    (:data:`~dcee.planning.block_sums.BLOCK` particles), e = exp(ll − bound[s]) with ll the
    log-likelihood of the task's reading less the Jacobian; the last sum is 0 without
    ``want_kl``. Inputs as :func:`dcee.planning.predicted_kernels._grouped_stats` takes them
    (a vector-path sensor: no false alarms): the position terms (P, N), weights (N,), tasks
    grouped by position (group_start (G + 1,)), task_positions (S, 1), the transformed reading
    v and outlier term of each task (S, 1), bound (S,); partial (n_blocks, S, 6)."""
    n = weights.shape[0]
    n_groups = group_start.shape[0] - 1
    n_blocks = (n + BLOCK - 1) // BLOCK
    det_add = sp.log_keep - HALF_LOG_2PI
    with_outlier = sp.log_outlier > -np.inf
    for item in prange(n_groups * n_blocks):
        g = item // n_blocks
        b = item % n_blocks
        s0 = group_start[g]
        i0 = b * BLOCK
        m = min(n, i0 + BLOCK) - i0
        p = task_positions[s0, 0]
        lo, lnd, isg, dof = loc[p], log_nd[p], inv_sigma[p], det_offset[p]
        for s in range(s0, group_start[g + 1]):
            v = task_v[s, 0]
            bnd = bound[s]
            total = 0.0
            weighted_ll = 0.0
            # one branch-free loop per case (a test inside the loop would stop LLVM vectorising)
            if v < sp.v_threshold:
                for q in range(m):
                    i = np.uint64(i0 + q)
                    lq = lnd[i] - bnd
                    we = weights[i] * exp_scalar(min(max(lq, EXP_FLOOR), 0.0))
                    total += we
                    weighted_ll += we * lq
            elif with_outlier:
                # p(z | C) = e^a + e^out: e = e^(a − bnd) + e^(out − bnd), ll − bnd = log e
                out_term = exp_scalar(min(task_out[s, 0] - bnd, 0.0))
                for q in range(m):
                    i = np.uint64(i0 + q)
                    r = (v - lo[i]) * isg[i]
                    a = max(dof[i] + det_add - 0.5 * r * r - bnd, EXP_FLOOR)
                    e = exp_scalar(min(a, 0.0)) + out_term
                    we = weights[i] * e
                    total += we
                    if want_kl:
                        weighted_ll += we * log_scalar(e)
            else:
                for q in range(m):
                    i = np.uint64(i0 + q)
                    r = (v - lo[i]) * isg[i]
                    lq = dof[i] + det_add - 0.5 * r * r - bnd
                    we = weights[i] * exp_scalar(min(max(lq, EXP_FLOOR), 0.0))
                    total += we
                    weighted_ll += we * lq
            partial[b, s, 0] = total
            for c in range(1, 5):
                partial[b, s, c] = 0.0
            # Σ w e ll = Σ w e (ll − bound) + bound Σ w e
            partial[b, s, 5] = weighted_ll + bnd * total if want_kl else 0.0


@njit(cache=True)
def one_stage_task_sums(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    sp: SensorParams,
    want_kl: bool,
    interpolate_from: int,
) -> tuple[bool, tuple, np.ndarray]:
    """The tasks' bounds (:func:`task_setup`), their one-pass sums and the sums' totals over
    the blocks (S, 6) (block 0, then 1, ...: ``partial.sum(axis=0)`` bit for bit) in one call,
    for :func:`~dcee.planning.predicted_kernels.predicted_posterior_stats`' one-stage tasks
    without the moments. The NumPy calls it replaces between the kernels took 70 µs of a 0.9
    ms decision on Stone Soup's workload when another program's work had evicted the Python
    code from the caches (lab, 2026-11-29). Inputs as :func:`one_stage_sums` takes them.

    Returns (done, :func:`task_setup`'s tuple, sums): not done, no sums, when a group has
    ``interpolate_from`` tasks or more (the caller sums those over interpolation nodes)."""
    s_count = task_positions.shape[0]
    sums = np.zeros((s_count, 6))
    # bounds from the model's ceilings where the sensor has them (task_setup)
    setup = task_setup(
        task_positions, task_v, task_fa, task_out, log_nd, det_offset, weights, sp, True
    )
    group_start, bound, largest, _, _ = setup
    if largest >= interpolate_from:
        return False, setup, sums
    n_blocks = (weights.shape[0] + BLOCK - 1) // BLOCK
    partial = np.empty((n_blocks, s_count, 6))
    one_stage_sums(
        loc, log_nd, inv_sigma, det_offset, weights, group_start, task_positions,
        task_v, task_out, bound, sp, want_kl, partial,
    )  # fmt: skip
    for b in range(n_blocks):
        for s in range(s_count):
            for c in range(6):
                sums[s, c] += partial[b, s, c]
    return True, setup, sums


@njit(cache=True)
def finish_one_stage(
    sums: np.ndarray,
    bound: np.ndarray,
    task_jac: np.ndarray,
    slack: float,
    want_kl: bool,
    log_evidence: np.ndarray,
    kl: np.ndarray,
) -> bool:
    """From one-stage tasks' sums (S, 6) (:func:`one_stage_task_sums`) and bounds (S,): the log
    evidence (S,) (less the Jacobians task_jac (S, T)) and, with ``want_kl``, the KL divergence
    (S,) (NaN without), as :func:`~dcee.planning.predicted_kernels.predicted_posterior_stats`
    forms them; False, nothing written, where a task's weights all lie more than ``slack`` nats
    below its bound (the caller redoes it exactly). One compiled call instead of a dozen NumPy
    steps (each a few µs when another program has run since: Stone Soup's workload)."""
    s_count = sums.shape[0]
    for s in range(s_count):
        if not np.log(sums[s, 0]) > -slack:  # also for 0 and NaN
            return False
    for s in range(s_count):
        s0 = sums[s, 0]
        log_ev = bound[s] + np.log(s0)
        kl[s] = sums[s, 5] / s0 - log_ev if want_kl else np.nan
        jac = 0.0
        for t in range(task_jac.shape[1]):
            jac += task_jac[s, t]
        log_evidence[s] = log_ev + jac
    return True
