"""Compiled (numba) predicted-posterior statistics (:func:`predicted_posterior_stats`), tested
against its NumPy reference
(:func:`dcee.planning.predicted_reference.predicted_posterior_stats_reference`).
The per-reading terms it shares with :mod:`dcee.planning.location_kl` are
:mod:`dcee.planning.reading_terms`.

Readings arrive in the sensor's transformed frame (:mod:`dcee.models.sensor_kernels`,
:meth:`dcee.models.sensor.Sensor.transformed_readings`): per task and stage the transformed
reading v, the false-alarm term and the outlier term; the log Jacobian, common to every particle,
is added to the log evidence by the caller. Kernels that loop over particles or hypotheses run in
parallel (``prange``); every reduction is sequential within one output element, so results do
not depend on the thread count.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import HALF_LOG_2PI, exp_scalar, log_scalar
from dcee.planning.block_sums import BLOCK as _BLOCK
from dcee.planning.block_sums import task_sums as _task_sums
from dcee.planning.block_sums import weighted_columns
from dcee.planning.interpolated_kernels import MIN_READINGS, interpolate_groups
from dcee.planning.interpolated_kernels import applicable as interpolation_applies
from dcee.planning.multi_stage_kernels import multi_stage_weights
from dcee.planning.one_stage_sums import finish_one_stage, one_stage_sums, one_stage_task_sums
from dcee.planning.predicted_single import BOUND_SLACK_SINGLE, single_stage_sums
from dcee.planning.reading_terms import (
    cached_log_likelihood,
    exact_task_stats,
    task_setup,
)
from dcee.planning.stage_products import applies as stage_products_apply
from dcee.planning.stage_products import key_bounds, product_stats, redo_below, stage_keys

_EXP_FLOOR = -680.0
"""Weights e^x with x below this are taken as e^-680: w · e^x then stays a normal float for any
weight w ≥ 1e-12 (arithmetic on subnormal floats is about 100× slower on x86: measured, the
paper-exact model without an outlier term ran its one-stage sums 2.6× slower than the default
model). A task is redone exactly when its largest weight is below e^-600 (_BOUND_SLACK), so a
floored particle changes a kept sum by less than N · e^-80 relative."""
_N_ACC = 6  # accumulated sums per task: Σe, Σe·dx, Σe·dy, Σe·dz, Σe·|d|², Σe·ll


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
def _single_stage_weights(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    i0: int,
    n: int,
    v: float,
    out: float,
    bnd: float,
    sp: SensorParams,
    want_kl: bool,
    e: np.ndarray,
    el: np.ndarray,
) -> None:
    """e[q] = exp(ll_i − bnd) and, with ``want_kl``, el[q] = e[q] (ll_i − bnd) for particles
    i = i0 + q, q < n, of one position row (1-D rows of :func:`position_rows`) and one
    single-stage reading (transformed reading v, outlier term out), ll_i = log p(v | C_i) less
    the Jacobian; ``bnd`` is an upper bound of ll over the particles (:func:`task_bound`).

    One branch-free loop per case (a flag tested inside a loop keeps LLVM from vectorising
    it: measured 4.4 against 1.8 ns per particle), ``exp`` included; the KL term's ``log`` in
    a second loop over the stored weights."""
    if v < sp.v_threshold:
        for q in range(n):
            lq = log_nd[np.uint64(i0 + q)] - bnd
            eq = exp_scalar(min(max(lq, _EXP_FLOOR), 0.0))
            e[np.uint64(q)] = eq
            el[np.uint64(q)] = eq * lq
        return
    det_add = sp.log_keep - HALF_LOG_2PI
    if sp.log_outlier > -np.inf:
        # with the outlier component p(z | C) = e^a + e^out (a the detection term), so
        # e^(ll − bnd) = e^(a − bnd) + e^(out − bnd): one exp per particle, and
        # ll − bnd = log e^(ll − bnd), a log, only when the KL divergence reads it
        out_term = exp_scalar(min(out - bnd, 0.0))
        for q in range(n):
            i = np.uint64(i0 + q)
            r = (v - loc[i]) * inv_sigma[i]
            a = max(det_offset[i] + det_add - 0.5 * r * r - bnd, _EXP_FLOOR)
            e[np.uint64(q)] = exp_scalar(min(a, 0.0)) + out_term
        if want_kl:
            for q in range(n):
                eq = e[np.uint64(q)]
                el[np.uint64(q)] = eq * log_scalar(eq)
        return
    for q in range(n):
        i = np.uint64(i0 + q)
        r = (v - loc[i]) * inv_sigma[i]
        lq = det_offset[i] + det_add - 0.5 * r * r - bnd
        eq = exp_scalar(min(max(lq, _EXP_FLOOR), 0.0))
        e[np.uint64(q)] = eq
        el[np.uint64(q)] = eq * lq


@njit(cache=True, parallel=True, fastmath={"contract"}, error_model="numpy")
def _grouped_stats(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    offsets: np.ndarray,
    weights: np.ndarray,
    weighted: np.ndarray,
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
    and the sums of all the group's tasks are two matrix products over ``weighted`` (N, 5)
    (:func:`dcee.planning.block_sums.task_sums`). Tasks of several stages (the tree search,
    ``dcee-ms``) the same way, their weights from
    :func:`dcee.planning.multi_stage_kernels.multi_stage_weights`. With false alarms the exact
    scalar likelihood is used instead, one particle at a time (slower, not vectorised). Sums a
    planner does not need (the location moments, Σ e·ll for the KL divergence) are left at zero
    when not wanted; ``offsets`` (4, N) from
    :func:`_centred_offsets` is only read for the moments.
    """
    n = weights.shape[0]
    t_count = task_positions.shape[1]
    n_groups = group_start.shape[0] - 1
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    vector_path = sp.false_alarm == 0.0
    single_stage = t_count == 1 and vector_path
    for item in prange(n_groups * n_blocks):
        g = item // n_blocks
        b = item % n_blocks
        s0 = group_start[g]
        k = group_start[g + 1] - s0
        i_start = b * _BLOCK
        i_end = min(n, i_start + _BLOCK)
        if vector_path:
            # the group's readings one at a time, vectorised over the block's particles
            # (_single_stage_weights; several stages: dcee.planning.multi_stage_kernels), then
            # every sum of every reading in two matrix products (block_sums.task_sums)
            p = task_positions[s0, 0]
            nb = i_end - i_start
            e = np.empty((k, nb))
            el = np.empty((k, nb))
            ll = np.empty(nb if not single_stage else 0)
            prod = np.empty(nb if not single_stage else 0)
            for j in range(k):
                s = s0 + j
                if single_stage:
                    _single_stage_weights(
                        loc[p], log_nd[p], inv_sigma[p], det_offset[p], i_start, nb,
                        task_v[s, 0], task_out[s, 0], bound[s], sp, want_kl, e[j], el[j],
                    )  # fmt: skip
                else:
                    multi_stage_weights(
                        loc, log_nd, inv_sigma, det_offset, task_positions[s], i_start, nb,
                        task_v[s], task_out[s], bound[s], sp, want_kl, e[j], el[j], ll, prod,
                    )  # fmt: skip
            sums = np.empty((k, _N_ACC))
            _task_sums(e, el, weights, weighted, i_start, want_moments, want_kl, sums)
            for j in range(k):
                for a in range(_N_ACC):
                    partial[b, s0 + j, a] = sums[j, a]
                # Σ w e ll = Σ w e (ll − bound) + bound Σ w e
                if want_kl:
                    partial[b, s0 + j, 5] += bound[s0 + j] * sums[j, 0]
            continue
        # false alarms: the exact scalar likelihood, one particle at a time
        a0 = np.zeros(k)
        a1 = np.zeros(k)
        a2 = np.zeros(k)
        a3 = np.zeros(k)
        a4 = np.zeros(k)
        a5 = np.zeros(k)
        ll = np.empty(k)
        for q in range(i_end - i_start):
            i = np.uint64(i_start + q)  # unsigned: no wraparound checks on the loads
            wi = weights[i]
            if wi <= 0.0:
                continue
            ll[:] = 0.0
            for t in range(t_count):
                p = task_positions[s0, t]
                for j in range(k):
                    s = s0 + j
                    ll[j] += cached_log_likelihood(
                        task_v[s, t], task_fa[s, t], task_out[s, t], loc[p, i], log_nd[p, i],
                        inv_sigma[p, i], det_offset[p, i], sp,
                    )  # fmt: skip
            for j in range(k):
                e = wi * exp_scalar(min(max(ll[j] - bound[s0 + j], _EXP_FLOOR), 0.0))
                a0[j] += e
                if want_moments:
                    a1[j] += e * offsets[0, i]
                    a2[j] += e * offsets[1, i]
                    a3[j] += e * offsets[2, i]
                    a4[j] += e * offsets[3, i]
                if want_kl:
                    a5[j] += e * ll[j]
        for j in range(k):
            partial[b, s0 + j, 0] = a0[j]
            partial[b, s0 + j, 1] = a1[j]
            partial[b, s0 + j, 2] = a2[j]
            partial[b, s0 + j, 3] = a3[j]
            partial[b, s0 + j, 4] = a4[j]
            partial[b, s0 + j, 5] = a5[j]


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
    precision: str = "double",
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
    ``precision="single"``: one-stage tasks without false alarms get their weights in float32
    (:mod:`dcee.planning.predicted_single`); ``precision="interpolated"``: one-stage tasks of the
    paper's sensor family are summed over nodes of the predicted concentration
    (:mod:`dcee.planning.interpolated_kernels`, an approximation within about 1e-8); any
    other task is computed in double precision, tasks of two or three stages as products of
    their distinct stage factors (:mod:`dcee.planning.stage_products`). One-stage tasks without
    the moments (the evidence and KL alone) are summed in one pass
    (:mod:`dcee.planning.one_stage_sums`, equal to about 1e-15).
    """
    task_positions = np.ascontiguousarray(task_positions, dtype=np.int64)
    task_v, task_fa, task_out = (
        np.ascontiguousarray(a, dtype=np.float64) for a in (task_v, task_fa, task_out)
    )
    s_count = task_positions.shape[0]
    one_stage = task_positions.shape[1] == 1 and sp.false_alarm == 0.0
    setup, done = None, False
    if (
        one_stage and not want_moments and precision in ("double", "interpolated") and s_count
    ):  # the evidence and KL alone of one-stage tasks: bounds and one-pass sums in one call
        interpolate_from = (
            MIN_READINGS
            if precision == "interpolated" and interpolation_applies(sp)
            else s_count + 1
        )
        done, setup, sums = one_stage_task_sums(
            loc, log_nd, inv_sigma, det_offset, weights, task_positions, task_v, task_fa,
            task_out, sp, want_kl, interpolate_from,
        )  # fmt: skip
        if done and finish_one_stage(
            sums, setup[1], np.ascontiguousarray(task_jac, dtype=np.float64), _BOUND_SLACK,
            want_kl, log_evidence, kl,
        ):  # fmt: skip
            mean[:] = np.nan  # (no moments on this path)
            trace_cov[:] = np.nan
            return
    single = precision == "single" and one_stage
    products = stage_products_apply(task_positions.shape[1], sp)
    # the model's ceilings as bounds (task_setup) wherever the kernels' slack allows: not
    # float32 weights, not the product kernel's per-stage floors
    ceilings = not products and not single
    group_start, bound, largest_group, max_log_nd, max_det_offset = (
        task_setup(
            task_positions, task_v, task_fa, task_out, log_nd, det_offset, weights, sp, ceilings
        )
        if setup is None
        else setup
    )
    log_ref = bound.copy()
    common = (loc, log_nd, inv_sigma, det_offset, source, weights, center)
    if not done:  # the general kernels
        n_blocks = (source.shape[0] + _BLOCK - 1) // _BLOCK
        vector_path = sp.false_alarm == 0.0
        interpolate = (
            precision == "interpolated"
            and one_stage
            and interpolation_applies(sp)
            and largest_group >= MIN_READINGS  # smaller groups are summed exactly
        )
        # the vectorised kernels' sums read w, w·dx, w·dy, w·dz, w·|d|² per particle (only the
        # moments and the interpolation read more than the weights themselves), the scalar kernel
        # of false alarms the offsets: each only what it reads (memory at 100,000 particles)
        weighted = (
            weighted_columns(weights, source, center, want_moments)
            if vector_path and (want_moments or interpolate)
            else np.zeros((0, 5))
        )
        scalar_moments = want_moments and not vector_path
        offsets = _centred_offsets(source, center) if scalar_moments else np.zeros((4, 0))
        sums = np.empty((s_count, _N_ACC))
        exact_tasks, group_start_exact = np.arange(s_count), group_start
        exact_positions, exact_v, exact_fa, exact_out = task_positions, task_v, task_fa, task_out
        exact_bound = bound
        if interpolate:
            # the groups it takes are summed over nodes (loc is C itself with this sensor)
            exact_tasks, group_start_exact = interpolate_groups(
                loc, weights, weighted, group_start, task_positions, task_v, task_out, bound, sp,
                want_kl, sums, log_ref,
            )  # fmt: skip
            exact_positions = np.ascontiguousarray(task_positions[exact_tasks])
            exact_v, exact_fa, exact_out = (
                np.ascontiguousarray(a[exact_tasks]) for a in (task_v, task_fa, task_out)
            )
            exact_bound = bound[exact_tasks]
        partial = np.empty((n_blocks, len(exact_tasks), _N_ACC))
        if len(exact_tasks) == 0:
            pass  # every task interpolated
        elif products:  # two or three stages: products of the distinct stage factors
            key_of, key_p, key_v, key_out = stage_keys(exact_positions, exact_v, exact_out, sp)
            key_bound = key_bounds(key_p, key_v, key_out, max_log_nd, max_det_offset, sp)
            product_stats(
                loc, log_nd, inv_sigma, det_offset, weights, weighted, key_p, key_v, key_out,
                key_bound, key_of, exact_bound, sp, want_moments, want_kl,
                partial,
            )  # fmt: skip
        elif single:
            single_stage_sums(
                (loc, log_nd, inv_sigma, det_offset),
                weights,
                weighted,
                group_start_exact,
                exact_positions,
                exact_v,
                exact_out,
                exact_bound,
                sp,
                want_moments,
                want_kl,
                partial,
            )
        elif one_stage and not want_moments:  # the evidence and KL alone: sums in one pass
            one_stage_sums(
                loc, log_nd, inv_sigma, det_offset, weights, group_start_exact, exact_positions,
                exact_v, exact_out, exact_bound, sp, want_kl, partial,
            )  # fmt: skip
        else:
            _grouped_stats(
                loc, log_nd, inv_sigma, det_offset, offsets, weights, weighted, group_start_exact,
                exact_positions, exact_v, exact_fa, exact_out, exact_bound, sp, want_moments,
                want_kl, partial,
            )  # fmt: skip
        if len(exact_tasks) == s_count:
            sums = partial.sum(axis=0)  # fixed order over blocks: thread count free
        else:
            sums[exact_tasks] = partial.sum(axis=0)
    # Σ e_i ll_i was accumulated with e relative to the bound; a task is redone exactly when its
    # largest weight e^(ll_max − bound) is too small for the one-pass sums to be accurate.
    slack = _BOUND_SLACK
    if single or products:
        slack = BOUND_SLACK_SINGLE if single else -redo_below(task_positions.shape[1])
    with np.errstate(divide="ignore"):
        too_small = ~(np.log(sums[:, 0]) > -slack)
    if too_small.any():
        redo = np.flatnonzero(too_small).astype(np.int64)
        redo_sums = np.empty((len(redo), _N_ACC))
        redo_max = np.empty(len(redo))
        exact_task_stats(
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
    log_ev = log_ref + np.log(s0)
    kl[:] = sums[:, 5] / s0 - log_ev if want_kl else np.nan
    log_evidence[:] = log_ev + np.asarray(task_jac, dtype=np.float64).sum(axis=1)
    if not want_moments:
        mean[:] = np.nan
        trace_cov[:] = np.nan
        return
    offset = sums[:, 1:4] / s0[:, None]
    mean[:] = center + offset
    trace_cov[:] = np.maximum(sums[:, 4] / s0 - np.einsum("ij,ij->i", offset, offset), 0.0)
