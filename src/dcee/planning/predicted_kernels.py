"""Compiled (numba) predicted-posterior statistics (:func:`predicted_posterior_stats`,
:func:`location_kl`) beside their NumPy references (:func:`predicted_posterior_stats_reference`,
:func:`location_kl_reference`): one family of kernels, tested against its references.

Readings arrive in the sensor's transformed frame (:mod:`dcee.models.sensor_kernels`,
:meth:`dcee.models.sensor.Sensor.transformed_readings`): per task and stage the transformed
reading v, the false-alarm term and the outlier term; the log Jacobian, common to every particle,
is added to the log evidence by the caller. Kernels that loop over particles or hypotheses run in
parallel (``prange``); every reduction is sequential within one output element, so results do
not depend on the thread count.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import (
    SensorParams,
)
from dcee.numeric import (
    HALF_LOG_2PI,
    exp_scalar,
    logaddexp,
    vlogaddexp,
)

_BLOCK = 512  # particles per work item; fixed, so the summation order never depends on threads
_N_ACC = 6  # accumulated sums per task: Σe, Σe·dx, Σe·dy, Σe·dz, Σe·|d|², Σe·ll


@njit(cache=True, inline="always")
def _loglik_cached(
    v: float,
    fa: float,
    out: float,
    loc: float,
    lnd: float,
    inv_s: float,
    det_off: float,
    sp: SensorParams,
) -> float:
    """log p(z | C) less the log Jacobian, from :func:`position_rows` and the transformed
    reading terms; equals :func:`dcee.models.sensor_kernels.log_likelihood` minus the Jacobian."""
    if v < sp.v_threshold:
        return lnd
    r = (v - loc) * inv_s
    ld = det_off - 0.5 * r * r - HALF_LOG_2PI
    if sp.false_alarm > 0.0:
        log_missed = lnd - sp.log_not_false_alarm - sp.log_keep
        ld = logaddexp(ld, fa + log_missed)
    ld += sp.log_keep
    if sp.log_outlier > -np.inf:
        ld = logaddexp(ld, out)
    return ld


@njit(cache=True, inline="always")
def _task_bound(
    s: int,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
    sp: SensorParams,
) -> float:
    """An upper bound of Σ_t log p(z_st | C_i) (less the Jacobian) over all particles i.

    A detection's density term is at most max(log Pd − log σ) − ½ log 2π; a
    false-alarm term at most its density times max P(missed); the outlier term is exact.
    """
    b = 0.0
    for t in range(task_positions.shape[1]):
        p = task_positions[s, t]
        v = task_v[s, t]
        if v < sp.v_threshold:
            b += max_log_nd[p]
            continue
        ld = max_det_offset[p] - HALF_LOG_2PI
        if sp.false_alarm > 0.0:
            log_missed_max = max_log_nd[p] - sp.log_not_false_alarm - sp.log_keep
            ld = logaddexp(ld, task_fa[s, t] + log_missed_max)
        ld += sp.log_keep
        if sp.log_outlier > -np.inf:
            ld = logaddexp(ld, task_out[s, t])
        b += ld
    return b


@njit(cache=True)
def _live_row_max(
    log_nd: np.ndarray,
    det_offset: np.ndarray,
    rows: np.ndarray,
    weights: np.ndarray,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
) -> None:
    """For each row r in ``rows``: the largest log_nd[r, i] and det_offset[r, i] over the
    particles with weight > 0 (the inputs of :func:`_task_bound`)."""
    for r in rows:
        a = -np.inf
        b = -np.inf
        for i in range(weights.shape[0]):
            if weights[i] > 0.0:
                a = max(a, log_nd[r, i])
                b = max(b, det_offset[r, i])
        max_log_nd[r] = a
        max_det_offset[r] = b


@njit(cache=True)
def _task_bounds(
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
    sp: SensorParams,
    out: np.ndarray,
) -> None:
    for s in range(task_positions.shape[0]):
        out[s] = _task_bound(
            s, task_positions, task_v, task_fa, task_out, max_log_nd, max_det_offset, sp
        )


@njit(cache=True)
def _centred_offsets(source: np.ndarray, center: np.ndarray) -> np.ndarray:
    """(4, N): dx, dy, dz of each source (N, 3) from ``center`` (3,) and dx² + dy² + dz²,
    contiguous per component so that the statistics kernel loads them as vectors."""
    n = source.shape[0]
    out = np.empty((4, n))
    for i in range(n):
        dx = source[i, 0] - center[0]
        dy = source[i, 1] - center[1]
        dz = source[i, 2] - center[2]
        out[0, i] = dx
        out[1, i] = dy
        out[2, i] = dz
        out[3, i] = dx * dx + dy * dy + dz * dz
    return out


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _block_sum(buf: np.ndarray, n: int) -> float:
    """Σ buf[:n] for buf (_BLOCK,) by pairwise halving (buf is overwritten). Every pass is an
    element-wise add that LLVM vectorises, and the order of additions is fixed (it does not
    depend on the vector width, as a reassociated loop's would); pairwise, so also accurate."""
    for q in range(n, _BLOCK):
        buf[np.uint64(q)] = 0.0
    m = _BLOCK
    while m > 1:
        m //= 2
        for q in range(m):
            buf[np.uint64(q)] += buf[np.uint64(q + m)]
    return buf[0]


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _product_sum(a: np.ndarray, b: np.ndarray, i0: int, n: int, buf: np.ndarray) -> float:
    """Σ_q a[q] · b[i0 + q] over q < n (see :func:`_block_sum`; buf (_BLOCK,) scratch)."""
    for q in range(n):
        buf[np.uint64(q)] = a[np.uint64(q)] * b[np.uint64(i0 + q)]
    return _block_sum(buf, n)


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _single_stage_weights(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    i0: int,
    n: int,
    v: float,
    out: float,
    bnd: float,
    sp: SensorParams,
    e: np.ndarray,
    ll: np.ndarray,
) -> None:
    """e[q] = w_i exp(ll_i − bnd) and ll[q] = log p(v | C_i) (less the Jacobian) for particles
    i = i0 + q, q < n, of one position row (1-D rows of :func:`position_rows`) and one
    single-stage reading (transformed reading v, outlier term out).

    Branch-free loops (the detection test is the same for every particle), so LLVM vectorises
    them, ``exp`` and the outlier's log-sum-exp included. A particle of weight 0 gives exactly
    0: its exponent is clamped to ≤ 0 (for positive weights ll ≤ bnd already, ``bnd`` being
    an upper bound over them)."""
    if v < sp.v_threshold:
        for q in range(n):
            i = np.uint64(i0 + q)
            lq = log_nd[i]
            ll[np.uint64(q)] = lq
            e[np.uint64(q)] = weights[i] * exp_scalar(min(lq - bnd, 0.0))
        return
    det_add = sp.log_keep - HALF_LOG_2PI
    if sp.log_outlier > -np.inf:
        for q in range(n):
            i = np.uint64(i0 + q)
            r = (v - loc[i]) * inv_sigma[i]
            lq = vlogaddexp(det_offset[i] + det_add - 0.5 * r * r, out)
            ll[np.uint64(q)] = lq
            e[np.uint64(q)] = weights[i] * exp_scalar(min(lq - bnd, 0.0))
        return
    for q in range(n):
        i = np.uint64(i0 + q)
        r = (v - loc[i]) * inv_sigma[i]
        lq = det_offset[i] + det_add - 0.5 * r * r
        ll[np.uint64(q)] = lq
        e[np.uint64(q)] = weights[i] * exp_scalar(min(lq - bnd, 0.0))


@njit(cache=True, parallel=True, fastmath={"contract"}, error_model="numpy")
def _grouped_stats(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    offsets: np.ndarray,
    weights: np.ndarray,
    group_start: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    bound: np.ndarray,
    sp: SensorParams,
    want_moments: bool,
    want_kl: bool,
    partial: np.ndarray,
) -> None:
    """partial[b, s, :] = the six sums of task s over particle block b.

    Weights are e_i = w_i exp(ll_i − bound_s): one pass, no per-task maximum. One-stage tasks
    (one hypothesised reading each, the one-step planners) run one task at a time over the
    block's particles in branch-free loops that LLVM vectorises (:func:`_single_stage_weights`),
    with the sums formed by pairwise halving in a fixed order (:func:`_block_sum`). Tasks of
    several stages: group_start[g]..group_start[g+1]−1 share one position sequence (equal
    task_positions rows), so a particle's per-position terms are loaded once and the loops over
    the group's hypothesised readings are branch-free arithmetic that LLVM vectorises (the
    outlier component's log-sum-exp included). With false alarms the exact scalar likelihood is
    used instead (slower, not vectorised). Sums a planner does not need (the location moments,
    Σ e·ll for the KL divergence) are left at zero when not wanted; ``offsets`` (4, N) from
    :func:`_centred_offsets` is only read for the moments.
    """
    n = weights.shape[0]
    t_count = task_positions.shape[1]
    n_groups = group_start.shape[0] - 1
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    v_thr = sp.v_threshold
    log_keep = sp.log_keep
    with_false_alarms = sp.false_alarm > 0.0
    with_outliers = sp.log_outlier > -np.inf
    single_stage = t_count == 1 and not with_false_alarms
    for item in prange(n_groups * n_blocks):
        g = item // n_blocks
        b = item % n_blocks
        s0 = group_start[g]
        k = group_start[g + 1] - s0
        i_start = b * _BLOCK
        i_end = min(n, i_start + _BLOCK)
        if single_stage:
            # one task at a time: vectorised over the particles (see _single_stage_weights)
            p = task_positions[s0, 0]
            nb = i_end - i_start
            e = np.empty(_BLOCK)
            ll = np.empty(_BLOCK)
            buf = np.empty(_BLOCK)
            for j in range(k):
                s = s0 + j
                _single_stage_weights(
                    loc[p],
                    log_nd[p],
                    inv_sigma[p],
                    det_offset[p],
                    weights,
                    i_start,
                    nb,
                    task_v[s, 0],
                    task_out[s, 0],
                    bound[s],
                    sp,
                    e,
                    ll,
                )
                for a in range(1, _N_ACC):
                    partial[b, s, a] = 0.0
                if want_moments:
                    for a in range(4):
                        partial[b, s, 1 + a] = _product_sum(e, offsets[a], i_start, nb, buf)
                if want_kl:
                    partial[b, s, 5] = _product_sum(e, ll, 0, nb, buf)
                partial[b, s, 0] = _block_sum(e, nb)
            continue
        z = np.empty((t_count, k))
        fa = np.empty((t_count, k))
        out = np.empty((t_count, k))
        for t in range(t_count):
            for j in range(k):
                z[t, j] = task_v[s0 + j, t]
                fa[t, j] = task_fa[s0 + j, t]
                out[t, j] = task_out[s0 + j, t]
        bnd = bound[s0 : s0 + k].copy()
        ll = np.empty(k)
        a0 = np.zeros(k)
        a1 = np.zeros(k)
        a2 = np.zeros(k)
        a3 = np.zeros(k)
        a4 = np.zeros(k)
        a5 = np.zeros(k)
        for q in range(i_end - i_start):
            i = np.uint64(i_start + q)  # unsigned: no wraparound checks on the loads
            wi = weights[i]
            if wi <= 0.0:
                continue
            dx = dy = dz = d2 = 0.0
            if want_moments:
                dx = offsets[0, i]
                dy = offsets[1, i]
                dz = offsets[2, i]
                d2 = offsets[3, i]
            ll[:] = 0.0
            for t in range(t_count):
                p = task_positions[s0, t]
                m = loc[p, i]
                lnd = log_nd[p, i]
                inv_s = inv_sigma[p, i]
                if with_false_alarms:
                    for j in range(k):
                        ll[j] += _loglik_cached(
                            z[t, j], fa[t, j], out[t, j], m, lnd, inv_s, det_offset[p, i], sp
                        )
                elif with_outliers:
                    det_const = det_offset[p, i] - HALF_LOG_2PI + log_keep
                    for j in range(k):
                        zj = z[t, j]
                        r = (zj - m) * inv_s
                        d = vlogaddexp(det_const - 0.5 * r * r, out[t, j])
                        ll[j] += d if zj >= v_thr else lnd
                else:
                    det_const = det_offset[p, i] - HALF_LOG_2PI
                    for j in range(k):
                        zj = z[t, j]
                        r = (zj - m) * inv_s
                        ll[j] += det_const - 0.5 * r * r if zj >= v_thr else lnd
            for j in range(k):
                e = wi * exp_scalar(ll[j] - bnd[j])
                a0[j] += e
                if want_moments:
                    a1[j] += e * dx
                    a2[j] += e * dy
                    a3[j] += e * dz
                    a4[j] += e * d2
                if want_kl:
                    a5[j] += e * ll[j]
        for j in range(k):
            partial[b, s0 + j, 0] = a0[j]
            partial[b, s0 + j, 1] = a1[j]
            partial[b, s0 + j, 2] = a2[j]
            partial[b, s0 + j, 3] = a3[j]
            partial[b, s0 + j, 4] = a4[j]
            partial[b, s0 + j, 5] = a5[j]


@njit(cache=True, inline="always")
def _task_log_likelihoods(
    s: int,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    sp: SensorParams,
    ll: np.ndarray,
) -> float:
    """ll[i] = Σ_t log p(z_st | C_i(p_st)) (less the Jacobian) for every particle i, sequentially;
    returns the largest over the particles with weight (−inf if none)."""
    mx = -np.inf
    for i in range(weights.shape[0]):
        v = 0.0
        for t in range(task_positions.shape[1]):
            p = task_positions[s, t]
            v += _loglik_cached(
                task_v[s, t],
                task_fa[s, t],
                task_out[s, t],
                loc[p, i],
                log_nd[p, i],
                inv_sigma[p, i],
                det_offset[p, i],
                sp,
            )
        ll[i] = v
        if weights[i] > 0.0 and v > mx:
            mx = v
    return mx


@njit(cache=True, parallel=True)
def _exact_task_stats(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    center: np.ndarray,
    tasks: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    sp: SensorParams,
    sums: np.ndarray,
    log_max: np.ndarray,
) -> None:
    """Two-pass fallback for tasks whose bound was far above every particle's log-likelihood
    (the one-pass weights would underflow): sums relative to the task's true maximum."""
    n = source.shape[0]
    for q in prange(tasks.shape[0]):
        s = tasks[q]
        ll = np.empty(n)
        mx = _task_log_likelihoods(
            s,
            task_positions,
            task_v,
            task_fa,
            task_out,
            loc,
            log_nd,
            inv_sigma,
            det_offset,
            weights,
            sp,
            ll,
        )
        log_max[q] = mx
        for a in range(_N_ACC):
            sums[q, a] = 0.0
        for i in range(n):
            wi = weights[i]
            if wi <= 0.0:
                continue
            e = wi * math.exp(ll[i] - mx)
            dx = source[i, 0] - center[0]
            dy = source[i, 1] - center[1]
            dz = source[i, 2] - center[2]
            sums[q, 0] += e
            sums[q, 1] += e * dx
            sums[q, 2] += e * dy
            sums[q, 3] += e * dz
            sums[q, 4] += e * (dx * dx + dy * dy + dz * dz)
            sums[q, 5] += e * ll[i]


# A task whose best particle lies more than this below its bound is redone exactly: beyond it the
# one-pass weights of particles within e^-60 of the best would leave float64's normal range.
_BOUND_SLACK = 600.0


def predicted_posterior_stats(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    center: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    task_jac: np.ndarray,
    sp: SensorParams,
    log_evidence: np.ndarray,
    mean: np.ndarray,
    trace_cov: np.ndarray,
    kl: np.ndarray,
    want_moments: bool = True,
    want_kl: bool = True,
) -> None:
    """Statistics of the predicted posterior for each task (a hypothesised reading sequence).

    loc, log_nd, inv_sigma, det_offset (P, N): :func:`position_rows`
    of every particle at P distinct positions; source (N, 3): source locations; weights (N,)
    normalised; center (3,): a reference point subtracted before the second moments are formed
    (keeps trace_cov accurate); task_positions (S, T) int indices into the position terms;
    task_v, task_fa, task_out, task_jac (S, T): the hypothesised readings as
    :meth:`~dcee.models.sensor.Sensor.transformed_readings` gives them. Outputs per task s, with
    w'_i ∝ w_i Π_t p(z_st | C_i(p_st)): log_evidence[s] = log Σ_i w_i Π_t p(z_st | ·);
    mean[s] (3,) = Σ w'_i s_i; trace_cov[s] = Σ w'_i ‖s_i − mean‖²; kl[s] = KL(w' ‖ w). mean
    and trace_cov are NaN unless ``want_moments``, kl is NaN unless ``want_kl``.

    Consecutive tasks with the same position row form a group that shares per-particle loads
    (callers list all hypotheses of one candidate sequence together). Memory: O(S · N / 512).
    """
    task_positions = np.ascontiguousarray(task_positions, dtype=np.int64)
    task_v, task_fa, task_out = (
        np.ascontiguousarray(a, dtype=np.float64) for a in (task_v, task_fa, task_out)
    )
    s_count = task_positions.shape[0]
    new_group = np.ones(s_count, dtype=bool)
    new_group[1:] = np.any(task_positions[1:] != task_positions[:-1], axis=1)
    group_start = np.append(np.flatnonzero(new_group), s_count).astype(np.int64)
    used = np.unique(task_positions)  # rows of the position terms the tasks read
    max_log_nd = np.full(log_nd.shape[0], -np.inf)
    max_det_offset = np.full(log_nd.shape[0], -np.inf)
    _live_row_max(log_nd, det_offset, used, weights, max_log_nd, max_det_offset)
    bound = np.empty(s_count)
    _task_bounds(task_positions, task_v, task_fa, task_out, max_log_nd, max_det_offset, sp, bound)
    n_blocks = (source.shape[0] + _BLOCK - 1) // _BLOCK
    partial = np.empty((n_blocks, s_count, _N_ACC))
    common = (loc, log_nd, inv_sigma, det_offset, source, weights, center)
    _grouped_stats(
        loc,
        log_nd,
        inv_sigma,
        det_offset,
        _centred_offsets(source, center) if want_moments else np.zeros((4, 0)),
        weights,
        group_start,
        task_positions,
        task_v,
        task_fa,
        task_out,
        bound,
        sp,
        want_moments,
        want_kl,
        partial,
    )
    sums = partial.sum(axis=0)  # fixed order over blocks: independent of the thread count
    log_ref = bound.copy()
    # Σ e_i ll_i was accumulated with e relative to the bound; a task is redone exactly when its
    # largest weight e^(ll_max − bound) is too small for the one-pass sums to be accurate.
    with np.errstate(divide="ignore"):
        too_small = ~(np.log(sums[:, 0]) > -_BOUND_SLACK)
    if np.any(too_small):
        redo = np.flatnonzero(too_small).astype(np.int64)
        redo_sums = np.empty((len(redo), _N_ACC))
        redo_max = np.empty(len(redo))
        _exact_task_stats(
            *common,
            redo,
            task_positions,
            task_v,
            task_fa,
            task_out,
            sp,
            redo_sums,
            redo_max,
        )
        sums[redo] = redo_sums
        log_ref[redo] = redo_max
    s0 = sums[:, 0]
    offset = sums[:, 1:4] / s0[:, None]
    log_ev = log_ref + np.log(s0)
    kl[:] = sums[:, 5] / s0 - log_ev if want_kl else np.nan
    log_evidence[:] = log_ev + np.asarray(task_jac, dtype=np.float64).sum(axis=1)
    mean[:] = center + offset if want_moments else np.nan
    trace = np.maximum(sums[:, 4] / s0 - np.einsum("ij,ij->i", offset, offset), 0.0)
    trace_cov[:] = trace if want_moments else np.nan


def location_cells(source: np.ndarray, weights: np.ndarray, cell: float) -> tuple[np.ndarray, ...]:
    """The particles grouped by the cube of side ``cell`` (m) that holds their source location.

    source (N, 3), weights (N,). Returns (order (N,) particle indices cell by cell,
    cell_start (C + 1,) where each cell's run begins in ``order``, log_cell_weight (C,) log of the
    cell's total weight, −inf for a cell without weight)."""
    key = np.floor(source / cell).astype(np.int64)
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    order = np.argsort(inverse, kind="stable").astype(np.int64)
    counts = np.bincount(inverse)
    cell_start = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    with np.errstate(divide="ignore"):
        log_cell_weight = np.log(np.bincount(inverse, weights=weights, minlength=len(counts)))
    return order, cell_start, log_cell_weight


@njit(cache=True, parallel=True, error_model="numpy")
def location_kl(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    order: np.ndarray,
    cell_start: np.ndarray,
    log_cell_weight: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    sp: SensorParams,
    kl: np.ndarray,
) -> None:
    """kl[s] = KL(W'_s ‖ W) between the predicted and the current distribution of the source
    *location* over cells (the marginal of the particle belief on the cells of
    :func:`location_cells`): W_c = Σ_{i∈c} w_i, W'_c ∝ Σ_{i∈c} w_i Π_t p(z_st | C_i(p_st)).

    Position terms (P, N) as for :func:`predicted_posterior_stats`; task_* (S, T). Information
    about the other parameters (release rate, wind, diffusion) within a cell does not count: with
    one particle per cell this is the joint KL divergence, with one cell it is 0. Two passes per
    task (its largest log-likelihood, then the cell sums), sequential within a task, so results do
    not depend on the thread count."""
    n = weights.shape[0]
    n_cells = cell_start.shape[0] - 1
    for s in prange(task_positions.shape[0]):
        ll = np.empty(n)
        mx = _task_log_likelihoods(
            s,
            task_positions,
            task_v,
            task_fa,
            task_out,
            loc,
            log_nd,
            inv_sigma,
            det_offset,
            weights,
            sp,
            ll,
        )
        total = 0.0
        acc = 0.0  # Σ_c A_c log(A_c / W_c), A_c the cell's unnormalised predicted weight
        for c in range(n_cells):
            a = 0.0
            for k in range(cell_start[c], cell_start[c + 1]):
                i = order[k]
                wi = weights[i]
                if wi > 0.0:
                    a += wi * math.exp(ll[i] - mx)
            if a > 0.0:
                total += a
                acc += a * (math.log(a) - log_cell_weight[c])
        kl[s] = max(acc / total - math.log(total), 0.0)


# --- NumPy references -------------------------------------------------------------------


def _predicted_weights_reference(
    conc: np.ndarray,
    dist: np.ndarray,
    weights: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    sensor: Sensor,
) -> tuple[np.ndarray, float]:
    """Unnormalised predicted weights (N,) w_i Π_t p(z_t | C_i(p_t)) / e^mx after the readings
    (T,) at position rows (T,), and mx, the largest log-likelihood of a particle with weight."""
    ll = np.zeros(conc.shape[1])
    for p, z in zip(positions, readings, strict=True):
        ll += sensor.log_likelihood(z, conc[p], dist[p])
    mx = ll[weights > 0].max()
    # zero-weight particles may exceed mx; clip them so that 0 · exp(·) stays 0
    return weights * np.exp(np.minimum(ll - mx, 0.0)), float(mx)


def predicted_posterior_stats_reference(
    conc: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    sensor: Sensor,
    dist: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """NumPy reference of :func:`dcee.planning.predicted_kernels.predicted_posterior_stats`
    from concentrations (P, N), source distances (P, N; None: far) and raw readings (S, T).
    Returns (log_evidence, mean, trace_cov, kl)."""
    dist = np.full_like(conc, np.inf) if dist is None else dist
    s_count = task_positions.shape[0]
    log_ev = np.empty(s_count)
    mean = np.empty((s_count, 3))
    trace = np.empty(s_count)
    kl = np.empty(s_count)
    for s in range(s_count):
        e, mx = _predicted_weights_reference(
            conc, dist, weights, task_positions[s], task_readings[s], sensor
        )
        w_post = e / e.sum()
        log_ev[s] = mx + np.log(e.sum())
        mean[s] = w_post @ source
        d = source - mean[s]
        trace[s] = w_post @ np.einsum("ij,ij->i", d, d)
        pos = w_post > 0
        kl[s] = np.sum(w_post[pos] * (np.log(w_post[pos]) - np.log(weights[pos])))
    return log_ev, mean, trace, kl


def location_kl_reference(
    conc: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    sensor: Sensor,
    cell: float,
    dist: np.ndarray | None = None,
) -> np.ndarray:
    """NumPy reference of :func:`dcee.planning.predicted_kernels.location_kl`: (S,) KL
    divergences of the source location's distribution over cubes of side ``cell`` (m), from
    concentrations (P, N), sources (N, 3), weights (N,), positions (S, T) and readings (S, T)."""
    dist = np.full_like(conc, np.inf) if dist is None else dist
    _, cell_of = np.unique(np.floor(source / cell), axis=0, return_inverse=True)
    cell_of = cell_of.reshape(-1)
    prior = np.bincount(cell_of, weights=weights)
    out = np.empty(task_positions.shape[0])
    for s in range(task_positions.shape[0]):
        e, _ = _predicted_weights_reference(
            conc, dist, weights, task_positions[s], task_readings[s], sensor
        )
        post = np.bincount(cell_of, weights=e / e.sum(), minlength=len(prior))
        pos = post > 0
        out[s] = np.sum(post[pos] * np.log(post[pos] / prior[pos]))
    return out
