"""Compiled (numba) hot kernels. Each one has a plain NumPy reference that the tests compare with:

* plume:            :func:`dcee.models.plume.isotropic_concentration_reference`
* likelihood:       :meth:`dcee.models.sensor.Sensor.log_likelihood`
* history loglik:   :func:`dcee.estimation.particle_filter.history_log_likelihood_reference`
* predicted stats:  :func:`dcee.planning.predicted.predicted_posterior_stats_reference`

Sensor parameters arrive packed as ``sp = [threshold, pd, sigma_min, sigma_frac, false_alarm,
false_alarm_scale, c_lin, L0, L1]`` (see :attr:`dcee.models.sensor.Sensor.params`). All
arithmetic is float64.
Kernels that loop over particles or hypotheses run in parallel (``prange``); every reduction is
sequential within one output element, so results do not depend on the thread count.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

_HALF_LOG_2PI = 0.5 * math.log(2.0 * math.pi)
_INV_SQRT2 = 1.0 / math.sqrt(2.0)
_FOUR_PI = 4.0 * math.pi


@njit(cache=True, inline="always")
def _log_ndtr(x: float) -> float:
    """log Φ(x), accurate also far in the lower tail (asymptotic series below −37)."""
    if x > -37.0:
        return math.log(0.5 * math.erfc(-x * _INV_SQRT2))
    x2 = 1.0 / (x * x)
    series = 1.0 - x2 + 3.0 * x2 * x2 - 15.0 * x2 * x2 * x2 + 105.0 * x2 * x2 * x2 * x2
    return -0.5 * x * x - math.log(-x) - _HALF_LOG_2PI + math.log(series)


@njit(cache=True, inline="always")
def _logaddexp(a: float, b: float) -> float:
    if a == -np.inf:
        return b
    if b == -np.inf:
        return a
    if a > b:
        return a + math.log1p(math.exp(b - a))
    return b + math.log1p(math.exp(a - b))


@njit(cache=True, inline="always")
def _log_missed(c: float, sp: np.ndarray) -> float:
    """log P(no true detection | C) = log((1 − Pd) + Pd Φ((thr − C)/σ)).

    Written as log1p(−Pd Φ(−x)): one erfc and one log1p instead of log Φ, log and logaddexp
    (about 3× cheaper, and exact where Φ(−x) is tiny). With Pd = 1 the log Φ(x) form is kept,
    because 1 − Φ(−x) cancels for x ≪ 0.
    """
    if c < sp[6]:
        return sp[7] + sp[8] * c  # linearised far from the plume (see Sensor.params)
    pd = sp[1]
    sigma = sp[3] * c + sp[2]
    x = (sp[0] - c) / sigma
    if pd < 1.0:
        return math.log1p(-pd * 0.5 * math.erfc(x * _INV_SQRT2))
    return _log_ndtr(x)


@njit(cache=True, inline="always")
def log_likelihood(z: float, c: float, sp: np.ndarray) -> float:
    """log p(z | C) of one reading for one expected concentration (see ``Sensor``)."""
    thr = sp[0]
    pfa = sp[4]
    if z < thr:
        lm = _log_missed(c, sp)
        if pfa > 0.0:
            return lm + math.log1p(-pfa)
        return lm
    sigma = sp[3] * c + sp[2]
    r = (z - c) / sigma
    ld = math.log(sp[1]) - 0.5 * r * r - math.log(sigma) - _HALF_LOG_2PI
    if pfa > 0.0:
        fas = sp[5]
        lfa = math.log(pfa) + _log_missed(c, sp) - (z - thr) / fas - math.log(fas)
        ld = _logaddexp(ld, lfa)
    return ld


@njit(cache=True, inline="always")
def _plume_terms(theta: np.ndarray, i: int):
    """Per-particle constants of the plume: the source location (x, y, z), then
    q/(4π ζ1), 1/λ, u cosφ/(2ζ1) and u sinφ/(2ζ1) — computed once, used at every position."""
    q = theta[i, 3]
    u = theta[i, 4]
    phi = theta[i, 5]
    z1 = theta[i, 6]
    z2 = theta[i, 7]
    lam = math.sqrt(z1 * z2 / (1.0 + u * u * z2 / (4.0 * z1)))
    return (
        theta[i, 0],
        theta[i, 1],
        theta[i, 2],
        q / (_FOUR_PI * z1),
        1.0 / lam,
        u * math.cos(phi) / (2.0 * z1),
        u * math.sin(phi) / (2.0 * z1),
    )


@njit(cache=True, inline="always")
def _plume_at(terms, px: float, py: float, pz: float, rmin: float) -> float:
    """Concentration at (px, py, pz) from one particle's :func:`_plume_terms`."""
    sx, sy, sz, pref, inv_lam, ax, ay = terms
    dx = px - sx
    dy = py - sy
    dz = pz - sz
    r = math.sqrt(dx * dx + dy * dy + dz * dz)
    if r < rmin:
        r = rmin
    return pref / r * math.exp(-r * inv_lam - dx * ax - dy * ay)


@njit(cache=True, parallel=True)
def concentration_grid(theta: np.ndarray, positions: np.ndarray, rmin: float, out: np.ndarray):
    """out[m, i] = C(positions[m]; theta[i]). theta (N, 8), positions (M, 3), out (M, N)."""
    n = theta.shape[0]
    m_count = positions.shape[0]
    for i in prange(n):
        terms = _plume_terms(theta, i)
        for m in range(m_count):
            out[m, i] = _plume_at(terms, positions[m, 0], positions[m, 1], positions[m, 2], rmin)


def concentration_matrix(theta: np.ndarray, positions: np.ndarray, rmin: float, out: np.ndarray):
    """out[i, m] = C(positions[m]; theta[i]); out (N, M) C-contiguous."""
    tmp = np.empty((positions.shape[0], theta.shape[0]))
    concentration_grid(theta, positions, rmin, tmp)
    out[...] = tmp.T


@njit(cache=True, parallel=True)
def history_log_likelihood(
    theta: np.ndarray,
    active: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    rmin: float,
    sp: np.ndarray,
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
        terms = _plume_terms(theta, i)
        acc = 0.0
        for k in range(k_count):
            c = _plume_at(terms, positions[k, 0], positions[k, 1], positions[k, 2], rmin)
            acc += multiplicity[k] * log_likelihood(readings[k], c, sp)
        out[i] = acc


@njit(cache=True, parallel=True)
def position_terms(
    conc: np.ndarray,
    sp: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    log_sigma: np.ndarray,
):
    """Per (position, particle) terms of the likelihood that do not depend on the reading.

    conc (P, N) → log p(non-detection | C), 1/σ(C) and log σ(C), each (P, N). With them a
    hypothesised reading costs a lookup (non-detection) or a few flops (detection).
    """
    p_count, n = conc.shape
    for i in prange(n):
        for p in range(p_count):
            c = conc[p, i]
            sigma = sp[3] * c + sp[2]
            log_nd[p, i] = log_likelihood(0.0, c, sp)
            inv_sigma[p, i] = 1.0 / sigma
            log_sigma[p, i] = math.log(sigma)


@njit(cache=True, inline="always")
def _loglik_cached(z: float, c: float, lnd: float, inv_s: float, log_s: float, sp: np.ndarray):
    """log p(z | C) from :func:`position_terms`; equals :func:`log_likelihood`."""
    thr = sp[0]
    if z < thr:
        return lnd
    r = (z - c) * inv_s
    ld = math.log(sp[1]) - 0.5 * r * r - log_s - _HALF_LOG_2PI
    pfa = sp[4]
    if pfa > 0.0:
        fas = sp[5]
        log_missed = lnd - math.log1p(-pfa)
        ld = _logaddexp(ld, math.log(pfa) + log_missed - (z - thr) / fas - math.log(fas))
    return ld


# --- exp that the compiler can vectorise ---------------------------------------------------
# numba's math.exp is a scalar libm call (about 3-4 ns here; this llvmlite wheel has no SVML), and
# the exponentials were the largest cost of a decision. _vexp is branch-free arithmetic (no table
# lookups), so LLVM turns the hypothesis loops into SIMD code (about 2.7x faster per term here):
# exp(x) = 2^(−m) · e^r with m = round(−x / ln 2), r = x + m ln 2 (Cody-Waite split of ln 2) and
# |r| ≤ ln 2 / 2, a degree-12 Taylor polynomial for e^r, and 2^(−m) assembled from the bits of m.
# Relative error < 1e-15 for −700 ≤ x ≤ 0 (tested against math.exp); x < −700 is treated as −700
# (e^-700 ≈ 1e-304, negligible next to the terms that matter), so only call it with x ≤ 0.
_LN2_HI = 6.93145751953125e-1  # ln 2 with its low bits cleared: m · _LN2_HI is exact
_LN2_LO = 1.42860682030941723212e-6
_INV_LN2 = 1.0 / math.log(2.0)


@njit(cache=True, inline="always")
def _vexp(x: float) -> float:
    """exp(x) for x ≤ 0, vectorisable (see above)."""
    x = max(x, -700.0)
    m = math.floor(-x * _INV_LN2 + 0.5)
    r = (x + m * _LN2_HI) + m * _LN2_LO
    p = 1.0 + r * (
        1.0
        + r
        * (
            1.0 / 2.0
            + r
            * (
                1.0 / 6.0
                + r
                * (
                    1.0 / 24.0
                    + r
                    * (
                        1.0 / 120.0
                        + r
                        * (
                            1.0 / 720.0
                            + r
                            * (
                                1.0 / 5040.0
                                + r
                                * (
                                    1.0 / 40320.0
                                    + r
                                    * (
                                        1.0 / 362880.0
                                        + r
                                        * (
                                            1.0 / 3628800.0
                                            + r * (1.0 / 39916800.0 + r / 479001600.0)
                                        )
                                    )
                                )
                            )
                        )
                    )
                )
            )
        )
    )
    mi = np.int64(m)
    scale = 1.0
    scale *= 0.5 if mi & 1 else 1.0
    scale *= 0.25 if mi & 2 else 1.0
    scale *= 0.0625 if mi & 4 else 1.0
    scale *= 3.90625e-3 if mi & 8 else 1.0  # 2^-8
    scale *= 1.52587890625e-05 if mi & 16 else 1.0  # 2^-16
    scale *= 2.3283064365386963e-10 if mi & 32 else 1.0  # 2^-32
    scale *= 5.421010862427522e-20 if mi & 64 else 1.0  # 2^-64
    scale *= 2.938735877055719e-39 if mi & 128 else 1.0  # 2^-128
    scale *= 8.636168555094445e-78 if mi & 256 else 1.0  # 2^-256
    scale *= 7.458340731200207e-155 if mi & 512 else 1.0  # 2^-512
    return p * scale


@njit(cache=True)
def vexp(x: np.ndarray, out: np.ndarray) -> None:
    """out[i] = exp(x[i]) for x ≤ 0 with :func:`_vexp` (exposed for tests)."""
    for i in range(x.shape[0]):
        out[i] = _vexp(x[i])


# --- predicted-posterior statistics ------------------------------------------------------------
_BLOCK = 512  # particles per work item; fixed, so the summation order never depends on threads
_N_ACC = 6  # accumulated sums per task: Σe, Σe·dx, Σe·dy, Σe·dz, Σe·|d|², Σe·ll


@njit(cache=True, inline="always")
def _task_bound(
    s: int,
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    max_log_nd: np.ndarray,
    min_log_sigma: np.ndarray,
    sp: np.ndarray,
) -> float:
    """An upper bound of Σ_t log p(z_st | C_i) over all particles i.

    A detection's Gaussian term is at most log Pd − log σ − ½ log 2π with σ ≥ min σ; a
    false-alarm term at most log pfa + log P(missed) − (z − thr)/scale − log scale.
    """
    thr = sp[0]
    pfa = sp[4]
    b = 0.0
    for t in range(task_positions.shape[1]):
        p = task_positions[s, t]
        z = task_readings[s, t]
        if z < thr:
            b += max_log_nd[p]
            continue
        ld = math.log(sp[1]) - min_log_sigma[p] - _HALF_LOG_2PI
        if pfa > 0.0:
            fas = sp[5]
            log_missed_max = max_log_nd[p] - math.log1p(-pfa)
            ld = _logaddexp(ld, math.log(pfa) + log_missed_max - (z - thr) / fas - math.log(fas))
        b += ld
    return b


@njit(cache=True, parallel=True, fastmath={"contract"})
def _grouped_stats(
    conc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    log_sigma: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    center: np.ndarray,
    group_start: np.ndarray,
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    bound: np.ndarray,
    sp: np.ndarray,
    want_moments: bool,
    want_kl: bool,
    partial: np.ndarray,
) -> None:
    """partial[b, s, :] = the six sums of task s over particle block b.

    Tasks group_start[g]..group_start[g+1]−1 share one position sequence (equal task_positions
    rows), so a particle's per-position terms are loaded once and the loops over the group's
    hypothesised readings are branch-free arithmetic that LLVM vectorises. Weights are
    e_i = w_i exp(ll_i − bound_s): one pass, no per-task maximum. With false alarms the exact
    scalar likelihood is used instead (slower, not vectorised). Sums a planner does not need
    (the location moments, Σ e·ll for the KL divergence) are left at zero when not wanted.
    """
    n = source.shape[0]
    t_count = task_positions.shape[1]
    n_groups = group_start.shape[0] - 1
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    thr = sp[0]
    log_pd_const = math.log(sp[1]) - _HALF_LOG_2PI
    with_false_alarms = sp[4] > 0.0
    for item in prange(n_groups * n_blocks):
        g = item // n_blocks
        b = item % n_blocks
        s0 = group_start[g]
        k = group_start[g + 1] - s0
        z = np.empty((t_count, k))
        for t in range(t_count):
            for j in range(k):
                z[t, j] = task_readings[s0 + j, t]
        bnd = bound[s0 : s0 + k].copy()
        ll = np.empty(k)
        a0 = np.zeros(k)
        a1 = np.zeros(k)
        a2 = np.zeros(k)
        a3 = np.zeros(k)
        a4 = np.zeros(k)
        a5 = np.zeros(k)
        for i in range(b * _BLOCK, min(n, (b + 1) * _BLOCK)):
            wi = weights[i]
            if wi <= 0.0:
                continue
            dx = source[i, 0] - center[0]
            dy = source[i, 1] - center[1]
            dz = source[i, 2] - center[2]
            d2 = dx * dx + dy * dy + dz * dz
            if t_count == 1 and not with_false_alarms:
                # The common case (one-step planners), fused into one vectorised loop.
                p = task_positions[s0, 0]
                c = conc[p, i]
                lnd = log_nd[p, i]
                inv_s = inv_sigma[p, i]
                det_const = log_pd_const - log_sigma[p, i]
                for j in range(k):
                    zj = z[0, j]
                    r = (zj - c) * inv_s
                    lj = det_const - 0.5 * r * r if zj >= thr else lnd
                    e = wi * _vexp(lj - bnd[j])
                    a0[j] += e
                    if want_moments:
                        a1[j] += e * dx
                        a2[j] += e * dy
                        a3[j] += e * dz
                        a4[j] += e * d2
                    if want_kl:
                        a5[j] += e * lj
                continue
            ll[:] = 0.0
            for t in range(t_count):
                p = task_positions[s0, t]
                c = conc[p, i]
                lnd = log_nd[p, i]
                inv_s = inv_sigma[p, i]
                if with_false_alarms:
                    for j in range(k):
                        ll[j] += _loglik_cached(z[t, j], c, lnd, inv_s, log_sigma[p, i], sp)
                else:
                    det_const = log_pd_const - log_sigma[p, i]
                    for j in range(k):
                        zj = z[t, j]
                        r = (zj - c) * inv_s
                        ll[j] += det_const - 0.5 * r * r if zj >= thr else lnd
            for j in range(k):
                e = wi * _vexp(ll[j] - bnd[j])
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


@njit(cache=True)
def _task_bounds(
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    max_log_nd: np.ndarray,
    min_log_sigma: np.ndarray,
    sp: np.ndarray,
    out: np.ndarray,
) -> None:
    for s in range(task_positions.shape[0]):
        out[s] = _task_bound(s, task_positions, task_readings, max_log_nd, min_log_sigma, sp)


@njit(cache=True, parallel=True)
def _exact_task_stats(
    conc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    log_sigma: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    center: np.ndarray,
    tasks: np.ndarray,
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    sp: np.ndarray,
    sums: np.ndarray,
    log_max: np.ndarray,
) -> None:
    """Two-pass fallback for tasks whose bound was far above every particle's log-likelihood
    (the one-pass weights would underflow): sums relative to the task's true maximum."""
    n = source.shape[0]
    for q in prange(tasks.shape[0]):
        s = tasks[q]
        ll = np.empty(n)
        mx = -np.inf
        for i in range(n):
            v = 0.0
            for t in range(task_positions.shape[1]):
                p = task_positions[s, t]
                v += _loglik_cached(
                    task_readings[s, t],
                    conc[p, i],
                    log_nd[p, i],
                    inv_sigma[p, i],
                    log_sigma[p, i],
                    sp,
                )
            ll[i] = v
            if weights[i] > 0.0 and v > mx:
                mx = v
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
    conc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    log_sigma: np.ndarray,
    source: np.ndarray,
    weights: np.ndarray,
    center: np.ndarray,
    task_positions: np.ndarray,
    task_readings: np.ndarray,
    sp: np.ndarray,
    log_evidence: np.ndarray,
    mean: np.ndarray,
    trace_cov: np.ndarray,
    kl: np.ndarray,
    want_moments: bool = True,
    want_kl: bool = True,
) -> None:
    """Statistics of the predicted posterior for each task (a hypothesised reading sequence).

    conc (P, N): concentration of every particle at P distinct positions, with log_nd,
    inv_sigma, log_sigma from :func:`position_terms`; source (N, 3): source locations; weights
    (N,) normalised; center (3,): a reference point subtracted before the second moments are
    formed (keeps trace_cov accurate); task_positions (S, T) int indices into conc;
    task_readings (S, T). Outputs per task s, with w'_i ∝ w_i Π_t p(z_st | C_i(p_st)):
    log_evidence[s] = log Σ_i w_i Π_t p(z_st | ·); mean[s] (3,) = Σ w'_i s_i;
    trace_cov[s] = Σ w'_i ‖s_i − mean‖²; kl[s] = KL(w' ‖ w). mean and trace_cov are NaN
    unless ``want_moments``, kl is NaN unless ``want_kl`` (each costs about 20% more time).

    Consecutive tasks with the same position row form a group that shares per-particle loads
    (callers list all hypotheses of one candidate sequence together). Memory: O(S · N / 512).
    """
    task_positions = np.ascontiguousarray(task_positions, dtype=np.int64)
    task_readings = np.ascontiguousarray(task_readings, dtype=np.float64)
    s_count = task_positions.shape[0]
    new_group = np.ones(s_count, dtype=bool)
    new_group[1:] = np.any(task_positions[1:] != task_positions[:-1], axis=1)
    group_start = np.append(np.flatnonzero(new_group), s_count).astype(np.int64)
    live = weights > 0.0
    max_log_nd = np.where(live, log_nd, -np.inf).max(axis=1)
    min_log_sigma = np.where(live, log_sigma, np.inf).min(axis=1)
    bound = np.empty(s_count)
    _task_bounds(task_positions, task_readings, max_log_nd, min_log_sigma, sp, bound)
    n_blocks = (source.shape[0] + _BLOCK - 1) // _BLOCK
    partial = np.empty((n_blocks, s_count, _N_ACC))
    _grouped_stats(
        conc,
        log_nd,
        inv_sigma,
        log_sigma,
        source,
        weights,
        center,
        group_start,
        task_positions,
        task_readings,
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
            conc,
            log_nd,
            inv_sigma,
            log_sigma,
            source,
            weights,
            center,
            redo,
            task_positions,
            task_readings,
            sp,
            redo_sums,
            redo_max,
        )
        sums[redo] = redo_sums
        log_ref[redo] = redo_max
    s0 = sums[:, 0]
    offset = sums[:, 1:4] / s0[:, None]
    log_evidence[:] = log_ref + np.log(s0)
    mean[:] = center + offset if want_moments else np.nan
    trace = np.maximum(sums[:, 4] / s0 - np.einsum("ij,ij->i", offset, offset), 0.0)
    trace_cov[:] = trace if want_moments else np.nan
    kl[:] = sums[:, 5] / s0 - log_evidence if want_kl else np.nan
