"""Compiled (numba) hot kernels. Each one has a plain NumPy reference that the tests compare with:

* plume:            :func:`dcee.models.plume.isotropic_concentration_reference`
* likelihood:       :meth:`dcee.models.sensor.Sensor.log_likelihood`
* history loglik:   :func:`dcee.estimation.particle_filter.history_log_likelihood_reference`
* predicted stats:  :func:`dcee.planning.predicted.predicted_posterior_stats_reference`

Sensor parameters arrive packed as ``sp = [threshold, pd, sigma_min, sigma_frac, false_alarm,
false_alarm_scale]`` (see :attr:`dcee.models.sensor.Sensor.params`). All arithmetic is float64.
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
    """log P(no true detection | C) = log((1 − Pd) + Pd Φ((thr − C)/σ))."""
    pd = sp[1]
    sigma = sp[3] * c + sp[2]
    lb = _log_ndtr((sp[0] - c) / sigma)
    if pd < 1.0:
        return _logaddexp(math.log1p(-pd), math.log(pd) + lb)
    return lb


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


@njit(cache=True, parallel=True)
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
):
    """Statistics of the predicted posterior for each task (a hypothesised reading sequence).

    conc (P, N): concentration of every particle at P distinct positions, with log_nd,
    inv_sigma, log_sigma from :func:`position_terms`; source (N, 3): source locations; weights
    (N,) normalised; center (3,): a reference point subtracted before the second moments are
    formed (keeps trace_cov accurate); task_positions (S, T) int indices into conc;
    task_readings (S, T). Outputs per task s, with w'_i ∝ w_i Π_t p(z_st | C_i(p_st)):
    log_evidence[s] = log Σ_i w_i Π_t p(z_st | ·); mean[s] (3,) = Σ w'_i s_i;
    trace_cov[s] = Σ w'_i ‖s_i − mean‖²; kl[s] = KL(w' ‖ w). Terms with w'_i/max < e^-60 are
    skipped (relative effect < 1e-22).
    """
    n = source.shape[0]
    s_count = task_positions.shape[0]
    t_count = task_positions.shape[1]
    for s in prange(s_count):
        ll = np.empty(n)
        mx = -np.inf
        for i in range(n):
            v = 0.0
            for t in range(t_count):
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
        s0 = 0.0
        s1x = 0.0
        s1y = 0.0
        s1z = 0.0
        s2 = 0.0
        sll = 0.0
        for i in range(n):
            wi = weights[i]
            d = ll[i] - mx
            if wi <= 0.0 or d < -60.0:
                continue
            e = wi * math.exp(d)
            dx = source[i, 0] - center[0]
            dy = source[i, 1] - center[1]
            dz = source[i, 2] - center[2]
            s0 += e
            s1x += e * dx
            s1y += e * dy
            s1z += e * dz
            s2 += e * (dx * dx + dy * dy + dz * dz)
            sll += e * ll[i]
        mxs = s1x / s0
        mys = s1y / s0
        mzs = s1z / s0
        log_evidence[s] = mx + math.log(s0)
        mean[s, 0] = center[0] + mxs
        mean[s, 1] = center[1] + mys
        mean[s, 2] = center[2] + mzs
        tc = s2 / s0 - (mxs * mxs + mys * mys + mzs * mzs)
        trace_cov[s] = tc if tc > 0.0 else 0.0
        kl[s] = sll / s0 - log_evidence[s]
