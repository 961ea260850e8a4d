"""One-stage predicted-posterior sums interpolated over the predicted concentration: the
planners' ``precision="interpolated"`` (issue 46).

With the paper's sensor (Gaussian family, constant Pd < 1, no false alarms) every term a
hypothesised reading's likelihood reads at a position — the location C, 1/σ(C), log Pd − log σ(C)
and log P(miss | C) — is a function of the particle's predicted concentration C alone. So is its
relative weight e(v, C) = exp(ll(v | C) − bound) for a reading v. The sums a planner needs,
Σ_i w_i x_i e(v, C_i) for x = 1, dx, dy, dz, |d|², are therefore integrals of e(v, ·) against
the particles' weighted columns, taken over C. Here C is mapped to u = log(C + σ_min/σ_frac)
(so σ = σ_frac e^u: the likelihood changes on a scale of u that does not depend on C), the
columns are spread onto nodes every ``step`` in u by cubic Lagrange weights (each particle on
its four nearest nodes, once per position), and each reading's weight is evaluated at the nodes
only: 8 moves × 41 readings × a few hundred nodes instead of × 18,700 particles.

The error is that of cubic interpolation of e(v, ·) between nodes: of order (step · e'/e)^4, a
few 1e-8 at the default step (measured on recorded decisions, docs/performance.md).
It is not exact: decisions taken with it are compared with the exact computation
(``studies/decision_agreement.py --precision interpolated``). A position whose particles span
more than ``max_nodes`` nodes (an early, wide belief) or with fewer than :data:`MIN_READINGS`
readings is left to the exact kernel, as is every other sensor, several stages, and false
alarms.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import (
    HALF_LOG_2PI,
    exp_scalar,
    log1p_scalar,
    log_scalar,
    vlog1m,
    vndtr_upper,
)

MIN_READINGS = 16
"""Positions with fewer hypothesised readings than this are summed exactly: the spread onto
the nodes costs about as much as a few readings over the particles, so it pays only for many
readings. Measured: Stone Soup's STE workload (10,000 particles, 9 moves × 5 readings) took
3.33 ms per infotaxis decision interpolated against 2.50 ms exact; the paper's 41 readings per
move 3-4× faster interpolated (docs/performance.md)."""

INTERPOLATION_STEP = 0.005
"""Node spacing in u = log(C + σ_min/σ_frac). Measured on five recorded decisions of the demo's
search (20,000 particles, 328 readings each) against the exact kernel: largest error in the log
evidence 2e-8, in the mean 1e-8 of the spread, in the trace 1e-8 relative, in the KL divergence
6e-8 nats (0.002: 5e-10, 0.01: 1e-6, 0.02: 1e-5; it falls as step^4), the kernel 3-7 ms
against 21-22 ms (docs/performance.md)."""


@njit(cache=True, inline="always", fastmath={"contract"}, error_model="numpy")
def gaussian_terms(c: float, sp: SensorParams) -> tuple[float, float, float]:
    """(log P(non-detection | c), 1/σ(c), log Pd − log σ(c)) of the paper's sensor (Gaussian
    family, constant Pd < 1) at concentration c; the transformed location is c itself. The
    formulas of :func:`dcee.planning.position_kernels.position_rows`' vectorised path, in the
    same order (a test holds the two equal bit for bit)."""
    sigma = sp.sigma_frac * c + sp.sigma_min
    inv_s = 1.0 / sigma
    missed = vlog1m(sp.pd * vndtr_upper((sp.v_threshold - c) * inv_s))  # log(1 − Pd Φ(−x))
    lin = sp.lin0 + sp.lin1 * c
    log_nd = (lin if c < sp.c_lin else missed) + (sp.log_not_false_alarm + sp.log_keep)
    return log_nd, inv_s, sp.log_pd - log_scalar(sigma)


def applicable(sp: SensorParams) -> bool:
    """True where the position terms are functions of the concentration alone (the paper's
    Gaussian sensor family with a constant Pd < 1 and no false alarms, :func:`gaussian_terms`)
    and σ grows with C. The plume (meander, decay) only changes C, not these functions."""
    return (
        sp.lognormal == 0.0
        and sp.pd < 1.0
        and sp.near_length == 0.0
        and sp.false_alarm == 0.0
        and sp.sigma_frac > 0.0
        and sp.sigma_min >= 2.0**-60  # σ within the range of the vectorised log
    )


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _spread_columns(
    u: np.ndarray, weights: np.ndarray, weighted: np.ndarray, u0: float, step: float, g: np.ndarray
) -> None:
    """g[m] += Σ_i ℓ_m(u_i) weighted[i] over the live particles: cubic Lagrange weights on the
    four nodes around each u_i (nodes u0 + m · step)."""
    for i in range(u.shape[0]):
        if weights[i] <= 0.0:
            continue
        t = (u[i] - u0) / step
        m = min(max(int(t), 1), g.shape[0] - 3)  # in range whatever the rounding
        f = t - m
        fm1 = f - 1.0
        fm2 = f - 2.0
        fp1 = f + 1.0
        l0 = -f * fm1 * fm2 / 6.0
        l1 = fp1 * fm1 * fm2 / 2.0
        l2 = -fp1 * f * fm2 / 2.0
        l3 = fp1 * f * fm1 / 6.0
        for c in range(5):
            x = weighted[i, c]
            g[m - 1, c] += l0 * x
            g[m, c] += l1 * x
            g[m + 1, c] += l2 * x
            g[m + 2, c] += l3 * x


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _node_log_likelihoods(
    v: float,
    out: float,
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_s: np.ndarray,
    det: np.ndarray,
    sp: SensorParams,
    ll: np.ndarray,
) -> None:
    """ll[m] = log p(v | C_m) less the Jacobian at every node (one branch-free loop per case,
    vectorised)."""
    if v < sp.v_threshold:
        for m in range(ll.shape[0]):
            ll[np.uint64(m)] = log_nd[np.uint64(m)]
        return
    det_add = sp.log_keep - HALF_LOG_2PI
    if sp.log_outlier > -np.inf:
        for m in range(ll.shape[0]):
            q = np.uint64(m)
            r = (v - loc[q]) * inv_s[q]
            a = det[q] + det_add - 0.5 * r * r
            hi = max(a, out)
            ll[q] = hi + log1p_scalar(exp_scalar(min(a, out) - hi))
        return
    for m in range(ll.shape[0]):
        q = np.uint64(m)
        r = (v - loc[q]) * inv_s[q]
        ll[q] = det[q] + det_add - 0.5 * r * r


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _log_shifted(row: np.ndarray, c0: float, u: np.ndarray) -> None:
    """u[i] = log(max(row[i], 0) + c0), vectorised."""
    for i in range(row.shape[0]):
        q = np.uint64(i)
        u[q] = log_scalar(max(row[q], 0.0) + c0)


@njit(cache=True, parallel=True, fastmath={"contract"}, error_model="numpy")
def interpolated_sums(
    conc: np.ndarray,
    weights: np.ndarray,
    weighted: np.ndarray,
    group_start: np.ndarray,
    task_row: np.ndarray,
    task_v: np.ndarray,
    task_out: np.ndarray,
    bound: np.ndarray,
    sp: SensorParams,
    step: float,
    max_nodes: int,
    min_readings: int,
    want_kl: bool,
    sums: np.ndarray,
    log_ref: np.ndarray,
    done: np.ndarray,
) -> None:
    """sums[s] = (Σ w e, Σ w e dx, Σ w e dy, Σ w e dz, Σ w e |d|², Σ w e ll) of one-stage task s
    with e = exp(ll − log_ref[s]), interpolated over the concentration (module docstring).

    conc (P, N): the particles' concentrations at the cached positions; weights (N,), weighted
    (N, 5) as :func:`dcee.planning.block_sums.weighted_columns`; tasks grouped by position
    (group_start, task_row (S,) into conc's rows); task_v, task_out (S,): transformed reading
    and outlier term; bound (S,): an upper bound of ll over the particles. log_ref[s] is set to
    the larger of bound[s] and the largest node value. done[g] is False for a group with fewer
    than ``min_readings`` tasks or whose particles span more than ``max_nodes`` nodes (its
    tasks are left for the exact kernel)."""
    n = weights.shape[0]
    c0 = sp.sigma_min / sp.sigma_frac
    for g in prange(group_start.shape[0] - 1):
        s0 = group_start[g]
        k = group_start[g + 1] - s0
        if k < min_readings:
            done[g] = False
            continue
        u = np.empty(n)
        _log_shifted(conc[task_row[s0]], c0, u)
        u_min = np.inf
        u_max = -np.inf
        for i in range(n):
            if weights[i] > 0.0:
                u_min = min(u_min, u[i])
                u_max = max(u_max, u[i])
        span = (u_max - u_min) / step
        if not span <= max_nodes - 5:  # also False for a NaN span
            done[g] = False
            continue
        nodes = int(span) + 5  # one spare node: rounding may put the last stencil one higher
        done[g] = True
        u0 = u_min - step  # every live particle has a node below it and two above
        g_cols = np.zeros((nodes, 5))
        _spread_columns(u, weights, weighted, u0, step, g_cols)
        loc = np.empty(nodes)
        log_nd = np.empty(nodes)
        inv_s = np.empty(nodes)
        det = np.empty(nodes)
        for m in range(nodes):
            c = math.exp(u0 + m * step) - c0
            loc[m] = c
            log_nd[m], inv_s[m], det[m] = gaussian_terms(c, sp)
        e = np.empty((k, nodes))
        el = np.empty((k, nodes))
        ll = np.empty(nodes)
        for j in range(k):
            s = s0 + j
            _node_log_likelihoods(task_v[s], task_out[s], loc, log_nd, inv_s, det, sp, ll)
            top = max(bound[s], ll.max())
            log_ref[s] = top
            for m in range(nodes):
                q = np.uint64(m)
                x = ll[q] - top
                em = exp_scalar(min(x, 0.0))
                e[j, q] = em
                el[j, q] = em * x
        st = np.dot(g_cols.T, e.T)  # (5, k): every task's five sums in one product
        kl = np.dot(np.ascontiguousarray(g_cols[:, 0]), el.T) if want_kl else np.zeros(k)
        for j in range(k):
            s = s0 + j
            for c in range(5):
                sums[s, c] = st[c, j]
            sums[s, 5] = kl[j] + log_ref[s] * st[0, j] if want_kl else 0.0


def interpolate_groups(
    conc: np.ndarray,
    weights: np.ndarray,
    weighted: np.ndarray,
    group_start: np.ndarray,
    task_positions: np.ndarray,
    task_v: np.ndarray,
    task_out: np.ndarray,
    bound: np.ndarray,
    sp: SensorParams,
    want_kl: bool,
    sums: np.ndarray,
    log_ref: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`interpolated_sums` of every group of one-stage tasks it takes, into sums (S, 6)
    and log_ref (S,); returns the tasks left for the exact kernel (indices into the S tasks)
    and their groups' starts among them. Arguments as :func:`interpolated_sums`;
    task_positions, task_v, task_out (S, 1)."""
    s_count = len(task_positions)
    done = np.zeros(len(group_start) - 1, dtype=np.bool_)
    interpolated_sums(
        conc,
        weights,
        weighted,
        group_start,
        np.ascontiguousarray(task_positions[:, 0]),
        np.ascontiguousarray(task_v[:, 0]),
        np.ascontiguousarray(task_out[:, 0]),
        bound,
        sp,
        INTERPOLATION_STEP,
        max(64, len(weights) // 4),
        MIN_READINGS,
        want_kl,
        sums,
        log_ref,
        done,
    )
    exact = np.flatnonzero(np.repeat(~done, np.diff(group_start)))
    if len(exact) == s_count:
        return exact, group_start
    first = np.zeros(s_count, dtype=bool)
    first[group_start[:-1]] = True  # each group's first task
    starts = np.flatnonzero(first[exact])  # whole groups are left: their firsts start them
    return exact, np.append(starts, len(exact)).astype(np.int64)
