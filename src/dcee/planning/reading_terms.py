"""Compiled per-reading terms shared by the predicted-posterior kernels
(:mod:`dcee.planning.predicted_kernels`, :mod:`dcee.planning.location_kl`): one hypothesised
reading's log-likelihood from the cached position terms, a task's log-likelihoods over the
particles, the upper bounds that let a kernel skip hopeless particles, and the exact two-pass
statistics of a task whose bound was too loose for the one-pass sums (:func:`exact_task_stats`).

Readings arrive in the sensor's transformed frame (:mod:`dcee.models.sensor_kernels`,
:meth:`dcee.models.sensor.Sensor.transformed_readings`): per task and stage the transformed
reading v, the false-alarm term and the outlier term; the log Jacobian, common to every particle,
is added to the log evidence by the caller.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import HALF_LOG_2PI, log_scalar, logaddexp


@njit(cache=True, inline="always")
def cached_log_likelihood(
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
def stage_bound(
    p: int,
    v: float,
    fa: float,
    out: float,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
    sp: SensorParams,
) -> float:
    """An upper bound of log p(v | C_i(p)) (less the Jacobian) over all particles i, for one
    stage: position row p, transformed reading v, false-alarm and outlier terms fa, out.

    A detection's density term is at most max(log Pd − log σ) − ½ log 2π; a
    false-alarm term at most its density times max P(missed); the outlier term is exact.
    """
    if v < sp.v_threshold:
        return max_log_nd[p]
    ld = max_det_offset[p] - HALF_LOG_2PI
    if sp.false_alarm > 0.0:
        log_missed_max = max_log_nd[p] - sp.log_not_false_alarm - sp.log_keep
        ld = logaddexp(ld, fa + log_missed_max)
    ld += sp.log_keep
    if sp.log_outlier > -np.inf:
        ld = logaddexp(ld, out)
    return ld


@njit(cache=True, inline="always")
def task_bound(
    s: int,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
    sp: SensorParams,
) -> float:
    """An upper bound of Σ_t log p(z_st | C_i) (less the Jacobian) over all particles i: the
    sum of the stages' :func:`stage_bound`."""
    b = 0.0
    for t in range(task_positions.shape[1]):
        b += stage_bound(
            task_positions[s, t], task_v[s, t], task_fa[s, t], task_out[s, t], max_log_nd,
            max_det_offset, sp,
        )  # fmt: skip
    return b


def plain_gaussian(sensor: Sensor) -> bool:
    """A Gaussian-family sensor with a constant Pd and no outliers: its readings and their
    transformed terms have compiled forms (here)."""
    return not sensor.lognormal and sensor.near_length == 0 and sensor.outlier == 0


@njit(cache=True)
def gaussian_sampled_readings(
    conc: np.ndarray,
    indices: np.ndarray,
    pos_idx: np.ndarray,
    noise: np.ndarray,
    sp: SensorParams,
) -> np.ndarray:
    """(S, J, T) hypothesised readings of the J particles ``indices`` (J,) along (S, T)
    sequences of position rows ``pos_idx`` of ``conc`` (R, N), from standard noise (J, T', 4),
    T' ≥ T: :meth:`dcee.models.sensor.Sensor.simulate_from` for a Gaussian-family sensor with
    a constant Pd and no outliers (:func:`plain_gaussian`), the same arithmetic in the same
    order (the same bits, tested), without its dozen NumPy calls and the gathers before them."""
    s_count, t_count = pos_idx.shape
    j_count = indices.shape[0]
    z = np.empty((s_count, j_count, t_count))
    for s in range(s_count):
        for j in range(j_count):
            for t in range(t_count):
                z[s, j, t] = gaussian_reading(conc[pos_idx[s, t], indices[j]], noise[j, t], sp)
    return z


@njit(cache=True, inline="always")
def gaussian_reading(c: float, noise: np.ndarray, sp: SensorParams) -> float:
    """One reading of a Gaussian-family sensor with a constant Pd and no outliers at mean
    concentration c from its standard noise (≥ 4,): :meth:`dcee.models.sensor.Sensor.
    simulate_from`'s arithmetic in its order (no contraction: the same bits). ``sp`` carries
    the sensor's own σ_frac, σ_min, Pd, threshold and false-alarm values."""
    y = c + (sp.sigma_frac * c + sp.sigma_min) * noise[1]
    if noise[0] < sp.pd and y >= sp.threshold:
        return y
    if noise[2] < sp.false_alarm:
        return sp.threshold + sp.false_alarm_scale * noise[3]
    return 0.0


@njit(cache=True)
def gaussian_transformed(tz: np.ndarray, threshold: float) -> np.ndarray:
    """v of :meth:`dcee.models.sensor.Sensor.transformed_readings` for a Gaussian-family sensor:
    the reading where it is a detection (≥ threshold), else half the threshold; tz (Q, T)."""
    v = np.empty_like(tz)
    half = 0.5 * threshold
    for q in range(tz.shape[0]):
        for t in range(tz.shape[1]):
            z = tz[q, t]
            v[q, t] = z if z >= threshold else half
    return v


@njit(cache=True, inline="always")
def _row_less(flat: np.ndarray, a: int, b: int) -> bool:
    """Row a of flat (Q, T) lexicographically before row b."""
    for t in range(flat.shape[1]):
        if flat[a, t] != flat[b, t]:
            return flat[a, t] < flat[b, t]
    return False


INSERTION_SORT_MAX = 64
"""Hypothesised readings per candidate up to which :func:`unique_tasks` orders them by insertion
sort (fastest for the paper's 40); more are ordered by merge sorts."""


@njit(cache=True)
def unique_tasks(readings: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compiled :func:`~dcee.planning.predicted_reference.unique_per_sequence_reference`, the same
    output: readings (S, J, T) → (task readings (Q, T), the candidate of each task (Q,),
    inverse (S, J)); each candidate's J rows sorted by a stable insertion sort (J is 4-40),
    equal rows one task. Its dozen NumPy calls took 70 µs of a 1.3 ms infotaxis decision.
    Beyond :data:`INSERTION_SORT_MAX` rows per candidate the rows are ordered by stable merge
    sorts, one per reading from the last (the same order: both are stable): the insertion
    sort's J² steps took 9 s of a decision with 20,000 hypothesised readings."""
    s_count, j_count, t_count = readings.shape
    flat = readings.reshape(s_count * j_count, t_count)
    order = np.empty(j_count, dtype=np.int64)
    tz = np.empty((s_count * j_count, t_count))
    seq = np.empty(s_count * j_count, dtype=np.int64)
    inverse = np.empty((s_count, j_count), dtype=np.int64)
    q = 0
    for s in range(s_count):
        base = s * j_count
        if j_count > INSERTION_SORT_MAX:
            order[:] = np.arange(j_count)
            for t in range(t_count - 1, -1, -1):
                keys = np.empty(j_count)
                for j in range(j_count):
                    keys[j] = flat[base + order[j], t]
                order[:] = order[np.argsort(keys, kind="mergesort")]
        else:
            for j in range(j_count):
                k = j
                while k > 0 and _row_less(flat, base + j, base + order[k - 1]):
                    order[k] = order[k - 1]
                    k -= 1
                order[k] = j
        for k in range(j_count):
            row = base + order[k]
            if k == 0 or _row_less(flat, base + order[k - 1], row):
                for t in range(t_count):
                    tz[q, t] = flat[row, t]
                seq[q] = s
                q += 1
            inverse[s, order[k]] = q - 1
    return tz[:q].copy(), seq[:q].copy(), inverse


@njit(cache=True)
def task_layout(task_positions: np.ndarray, n_rows: int) -> tuple[np.ndarray, np.ndarray]:
    """(group_start (G + 1,), used rows (U,)) of tasks with position rows task_positions (S, T)
    into n_rows position rows: a group is a run of consecutive tasks with the same rows (its
    start indices, then S), ``used`` the distinct rows any task reads, increasing (what
    ``np.unique(task_positions)`` gives)."""
    s_count, t_count = task_positions.shape
    starts = np.empty(s_count + 1, dtype=np.int64)
    g = 0
    for s in range(s_count):
        new = s == 0
        if not new:
            for t in range(t_count):
                if task_positions[s, t] != task_positions[s - 1, t]:
                    new = True
                    break
        if new:
            starts[g] = s
            g += 1
    starts[g] = s_count
    seen = np.zeros(n_rows, dtype=np.bool_)
    for s in range(s_count):
        for t in range(t_count):
            seen[task_positions[s, t]] = True
    return starts[: g + 1].copy(), np.flatnonzero(seen).astype(np.int64)


@njit(cache=True, parallel=True)
def live_row_max(
    log_nd: np.ndarray,
    det_offset: np.ndarray,
    rows: np.ndarray,
    weights: np.ndarray,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
) -> None:
    """For each row r in ``rows``: the largest log_nd[r, i] and det_offset[r, i] over the
    particles with weight > 0 (the inputs of :func:`task_bound`). Rows in parallel (a maximum
    does not depend on the order)."""
    for k in prange(rows.shape[0]):
        r = rows[k]
        a = -np.inf
        b = -np.inf
        for i in range(weights.shape[0]):
            if weights[i] > 0.0:
                a = max(a, log_nd[r, i])
                b = max(b, det_offset[r, i])
        max_log_nd[r] = a
        max_det_offset[r] = b


@njit(cache=True)
def task_bounds(
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
        out[s] = task_bound(
            s, task_positions, task_v, task_fa, task_out, max_log_nd, max_det_offset, sp
        )


@njit(cache=True, inline="always")
def task_log_likelihoods(
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
            v += cached_log_likelihood(
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
def exact_task_stats(
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
        mx = task_log_likelihoods(
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
        for a in range(sums.shape[1]):
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


@njit(cache=True)
def model_ceilings(sp: SensorParams) -> tuple[float, float]:
    """Upper bounds of every particle's log P(non-detection) and log Pd − log σ at any position,
    for the Gaussian family, from the model alone: log P(missed) ≤ 0, so log_nd ≤ log(1 − fa)
    + log(1 − outlier); σ = σ_frac C + σ_min ≥ σ_min for C ≥ 0 (every estimator plume's: the
    isotropic formula, and the wall and room plumes' receptor fields, triangular solves of an
    M-matrix's factors with a nonnegative right-hand side) and Pd(r) ≤ Pd. A bound only has to lie
    above the terms (the sums are relative to it; a task whose weights all fall more than the
    kernel's slack below it is redone exactly): these lie at most log(σ(C)/σ_min) + a few nats
    per stage above the largest live terms. The margin keeps the vectorised log's last-bit
    wobble below them."""
    margin = 1e-9
    return (
        sp.log_not_false_alarm + sp.log_keep + margin,
        sp.log_pd - log_scalar(sp.sigma_min) + margin,
    )


@njit(cache=True)
def task_setup(
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_fa: np.ndarray,
    task_out: np.ndarray,
    log_nd: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    sp: SensorParams,
    ceilings: bool = False,
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray]:
    """What the statistics kernels need of a task list, in one call: (group_start
    (:func:`task_layout`), each task's bound (S,) (:func:`task_bound` from the largest terms of
    the rows the tasks read), the largest group's size, and those largest terms per row (R,)
    (−inf for rows no task reads)).

    The largest terms are those of the particles with weight (:func:`live_row_max`, a pass
    over two terms of every row read), or, where the caller's slack allows ``ceilings`` and
    the sensor is of the Gaussian family (other families have no such bounds), the model's own
    (:func:`model_ceilings`): no pass over the particles, bounds a few
    nats looser (measured on Stone Soup's STE workload: 45 of the one-stage sums' 140 µs per
    decision, hot; lab, 2026-12-05)."""
    group_start, used = task_layout(task_positions, log_nd.shape[0])
    max_log_nd = np.full(log_nd.shape[0], -np.inf)
    max_det_offset = np.full(log_nd.shape[0], -np.inf)
    if ceilings and sp.lognormal == 0.0:
        ceiling_nd, ceiling_det = model_ceilings(sp)
        for r in used:
            max_log_nd[r] = ceiling_nd
            max_det_offset[r] = ceiling_det
    else:
        live_row_max(log_nd, det_offset, used, weights, max_log_nd, max_det_offset)
    bound = np.empty(task_positions.shape[0])
    task_bounds(task_positions, task_v, task_fa, task_out, max_log_nd, max_det_offset, sp, bound)
    largest = 0
    for g in range(group_start.shape[0] - 1):
        largest = max(largest, group_start[g + 1] - group_start[g])
    return group_start, bound, largest, max_log_nd, max_det_offset
