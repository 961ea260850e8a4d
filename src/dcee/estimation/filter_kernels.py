"""Compiled (numba) filter kernel; NumPy reference:
:func:`history_log_likelihood_reference`.

The history likelihood Σ_k m_k log p(z_k | Θ_i) is the cost of the filter's MCMC move (every
proposal against every reading so far) and of each update (one reading). Particles are taken
in blocks; for each reading the plume is evaluated for the whole block in a branch-free loop
that LLVM vectorises (:func:`dcee.numeric.exp_scalar`), then the likelihood: far from a
hypothesised source the concentration is below the sensor's linearisation point and a
non-detection costs a multiply-add; the other non-detections are gathered and evaluated in one
vectorised pass (the paper's sensor; libm otherwise), detections in a scalar loop. Each
particle's sum runs over the readings in their order, as in a plain loop.

**Early rejection (exact).** The MCMC move accepts proposal i only if its history
log-likelihood exceeds a threshold T_i fixed by its uniform draw, the prior and the current
particle. Every reading's log-likelihood has an upper bound over all source terms
(:func:`reading_upper_bounds`), so once the partial sum plus the bounds of the readings still
to come falls below T_i, the proposal cannot be accepted and its sum is abandoned (returned as
−inf, which the move rejects as it would have). Accepted proposals are summed in full, in the
same order, so the filter's particles and cached likelihoods are what the full sums give.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.plume import IsotropicPlume, isotropic_concentration_reference
from dcee.models.plume_kernels import constants_at, plume_at, plume_from_terms, plume_terms
from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import SensorParams, log_likelihood
from dcee.numeric import (
    HALF_LOG_2PI,
    exp_scalar,
    log1p_scalar,
    log_scalar,
    read_only_view,
    vlog1m,
    vndtr_upper,
)

_BLOCK = 256  # particles per work item
_CHECK_EVERY = 8  # readings between early-rejection checks
# Early rejection needs the partial sum to lie this far below the threshold (nats, relative
# to 1 + |T|): the final comparison is made in another order of floating-point operations.
_MARGIN = 1e-9


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _plume_block(
    pc: np.ndarray,
    nb: int,
    px: float,
    py: float,
    pz: float,
    rmin: float,
    conc: np.ndarray,
    dist: np.ndarray,
) -> None:
    """conc[q], dist[q] for the block's particles q < nb from their plume constants pc (10, nb),
    without meander; vectorised (:func:`~dcee.models.plume_kernels.plume_from_terms`)."""
    for j in range(nb):
        q = np.uint64(j)  # unsigned: no wraparound checks, which would block vectorising
        conc[q], dist[q] = plume_from_terms(
            pc[0, q], pc[1, q], pc[2, q], pc[3, q], pc[4, q], pc[5, q], pc[6, q], px, py, pz, rmin
        )


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _log_missed_gaussian(conc: np.ndarray, count: int, sp: SensorParams, out: np.ndarray) -> None:
    """out[j] = log P(no detection | conc[j]) − log(1 − false alarm) − log(1 − outlier) for
    j < count: log(1 − Pd Φ(−x)), x = (threshold − C)/σ(C), for the Gaussian family with a
    constant Pd < 1; branch-free, vectorised (erfc and log of :mod:`dcee.numeric`)."""
    for j in range(count):
        c = conc[j]
        x = (sp.v_threshold - c) / (sp.sigma_frac * c + sp.sigma_min)
        out[j] = vlog1m(sp.pd * vndtr_upper(x))


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _log_detected_gaussian(
    conc: np.ndarray, count: int, z: float, sp: SensorParams, out: np.ndarray
) -> None:
    """out[j] = log p(z | conc[j]) of a detection z ≥ threshold for j < count, the Gaussian
    family with a constant Pd and no false alarms (what
    :func:`~dcee.models.sensor_kernels.log_likelihood` gives): log Pd − ½ x² − log σ − ½ log 2π
    + log(1 − outlier), x = (z − C)/σ(C), and with the outlier component its log-sum-exp with
    log(outlier / ln(max/thr)) − log z as max + log1p(exp(−|difference|)). Branch-free with the
    ``exp``, ``log`` and ``log1p`` of :mod:`dcee.numeric`, so LLVM vectorises it (the scalar libm
    form took most of an MCMC sweep: a detection is never merged with another reading)."""
    base = sp.log_pd - HALF_LOG_2PI + sp.log_keep
    with_outlier = sp.log_outlier > -np.inf
    out_term = sp.log_outlier - math.log(z) if with_outlier else 0.0
    for j in range(count):
        c = conc[j]
        sigma = sp.sigma_frac * c + sp.sigma_min
        x = (z - c) / sigma
        ld = base - 0.5 * x * x - log_scalar(sigma)
        if with_outlier:
            hi = max(ld, out_term)
            ld = hi + log1p_scalar(exp_scalar(min(ld, out_term) - hi))
        out[j] = ld


@njit(cache=True, parallel=True)
def _history_kernel(
    theta: np.ndarray,
    active: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    rmin: float,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
    sp: SensorParams,
    threshold: np.ndarray,
    remaining_bound: np.ndarray,
    out: np.ndarray,
) -> None:
    n = theta.shape[0]
    k_count = readings.shape[0]
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    # log P(miss) vectorised for the paper's sensor (Gaussian, constant Pd < 1; with Pd = 1 the
    # log Φ form needs relative accuracy far in the tail, and Pd(r) needs expm1)
    vector_missed = sp.lognormal == 0.0 and sp.pd < 1.0 and sp.near_length == 0.0
    # detections of that sensor too, where a detection's term is one Gaussian density (with
    # the outlier component's log-sum-exp); σ_min within the range of the vectorised log
    vector_detected = (
        sp.lognormal == 0.0
        and sp.near_length == 0.0
        and sp.magnitude != 0.0
        and sp.false_alarm == 0.0
        and sp.sigma_min >= 2.0**-60
    )
    missed_offset = sp.log_not_false_alarm + sp.log_keep
    for b in prange(n_blocks):
        i0 = b * _BLOCK
        nb = min(n, i0 + _BLOCK) - i0
        pc = np.empty((10, nb))
        for q in range(nb):
            terms = plume_terms(theta, i0 + q)
            for c in range(10):
                pc[c, q] = terms[c]
        acc = np.zeros(nb)
        alive = np.empty(nb, dtype=np.bool_)
        n_alive = 0
        for q in range(nb):
            alive[q] = active[i0 + q]
            n_alive += alive[q]
        conc = np.empty(nb)
        dist = np.empty(nb)
        gathered = np.empty(nb)
        missed = np.empty(nb)
        which = np.empty(nb, dtype=np.int64)
        for k in range(k_count):
            if n_alive == 0:
                break
            px = positions[k, 0]
            py = positions[k, 1]
            pz = positions[k, 2]
            if (
                meander > 0.0
                or decay != 1.0
                or backflow > 0.0
                or radius > 0.0
                or vertical != 1.0
                or ground > 0.0
                or meander_z > 0.0
            ):
                for q in range(nb):
                    conc[q], dist[q] = plume_at(
                        constants_at(pc, q), px, py, pz, rmin, meander, decay, backflow, radius,
                        vertical, ground, meander_z,
                    )  # fmt: skip
            else:
                _plume_block(pc, nb, px, py, pz, rmin, conc, dist)
            zk = readings[k]
            mk = multiplicity[k]
            if zk < sp.threshold and vector_missed:
                # a non-detection: linear below c_lin; the others gathered and evaluated in
                # one vectorised pass
                count = 0
                for q in range(nb):
                    if alive[q]:
                        cq = conc[q]
                        if cq < sp.c_lin:
                            acc[q] += mk * (sp.lin0 + sp.lin1 * cq + missed_offset)
                        else:
                            gathered[count] = cq
                            which[count] = q
                            count += 1
                if count > 0:
                    _log_missed_gaussian(gathered, count, sp, missed)
                    for j in range(count):
                        acc[which[j]] += mk * (missed[j] + missed_offset)
            elif zk >= sp.threshold and vector_detected:
                _log_detected_gaussian(conc, nb, zk, sp, missed)
                for q in range(nb):
                    if alive[q]:
                        acc[q] += mk * missed[q]
            else:
                for q in range(nb):
                    if alive[q]:
                        acc[q] += mk * log_likelihood(zk, conc[q], dist[q], sp)
            if (k + 1) % _CHECK_EVERY == 0 and k + 1 < k_count:
                rest = remaining_bound[k + 1]
                for q in range(nb):
                    t = threshold[i0 + q]
                    if alive[q] and acc[q] + rest < t - _MARGIN * (1.0 + abs(t)):
                        alive[q] = False
                        n_alive -= 1
        for q in range(nb):
            out[i0 + q] = acc[q] if alive[q] else -np.inf


def reading_upper_bounds(readings: np.ndarray, sensor: Sensor) -> np.ndarray:
    """(K,) an upper bound of log p(z_k | C, r) over every concentration C ≥ 0 and source
    distance r, for readings (K,) g/m³ (below the threshold: a non-detection).

    Non-detection: log P(miss) ≤ 0, so log(1 − false alarm) + log(1 − outlier). Detection:
    Pd(r) ≤ Pd, σ(C) ≥ σ_min (Gaussian) or = s (log-normal), the squared residual ≥ 0; a false
    alarm's density is at most its exponential's at P(miss) = 1; the outlier term is exact.
    """
    sp = sensor.params
    z = np.asarray(readings, dtype=np.float64)
    det = z >= sensor.threshold
    zd = np.where(det, z, sensor.threshold)
    if not sensor.magnitude:  # detection only: P(detection) ≤ Pd, times g(z)
        density = sp.log_pd + sp.log_flat - np.log(zd)
    elif sensor.lognormal:
        density = sp.log_pd - math.log(sensor.log_sd) - HALF_LOG_2PI - np.log(zd)
    else:
        density = np.full(z.shape, sp.log_pd - math.log(sensor.sigma_min) - HALF_LOG_2PI)
    if sensor.false_alarm > 0:
        fas = sensor.false_alarm_scale
        fa = sp.log_false_alarm - (zd - sensor.threshold) / fas - math.log(fas)
        density = np.logaddexp(density, fa)
    density = density + sp.log_keep
    if sp.log_outlier > -np.inf:
        density = np.logaddexp(density, sp.log_outlier - np.log(zd))
    return np.where(det, density, sp.log_not_false_alarm + sp.log_keep)


def rejection_bounds(
    n: int, multiplicity: np.ndarray, threshold: np.ndarray | None, bounds: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """The early-rejection inputs of the history kernels: ((N,) thresholds, (K + 1,)
    remaining[k] = Σ_{k' ≥ k} m_k' · bound_k'); without a threshold or bounds none is
    rejected (−inf thresholds, zero bounds)."""
    if threshold is None or bounds is None:
        return np.full(n, -np.inf), np.zeros(len(multiplicity) + 1)
    weighted = np.asarray(bounds, dtype=np.float64) * multiplicity
    return threshold, np.append(np.cumsum(weighted[::-1])[::-1], 0.0)


def history_log_likelihood(
    theta: np.ndarray,
    active: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    rmin: float,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
    sp: SensorParams,
    out: np.ndarray,
    threshold: np.ndarray | None = None,
    bounds: np.ndarray | None = None,
) -> None:
    """out[i] = Σ_k multiplicity[k] · log p(readings[k] | C(positions[k]; theta[i])).

    Particles with ``active[i]`` False get −inf (used for proposals outside the prior's support).
    theta (N, 8); positions (K, 3); readings, multiplicity (K,); out (N,). With ``threshold``
    (N,) and ``bounds`` (K,) (:func:`reading_upper_bounds`), a particle whose sum provably ends
    at or below threshold[i] gets −inf instead (exact early rejection, see the module doc).
    """
    n = theta.shape[0]
    multiplicity = np.ascontiguousarray(multiplicity, dtype=np.float64)
    threshold, remaining = rejection_bounds(n, multiplicity, threshold, bounds)
    _history_kernel(
        read_only_view(np.ascontiguousarray(theta, dtype=np.float64)),
        np.ascontiguousarray(active, dtype=np.bool_),
        np.ascontiguousarray(positions, dtype=np.float64),
        np.ascontiguousarray(readings, dtype=np.float64),
        multiplicity,
        rmin,
        meander,
        decay,
        backflow,
        radius,
        vertical,
        ground,
        meander_z,
        sp,
        np.ascontiguousarray(threshold, dtype=np.float64),
        remaining,
        out,
    )


def history_log_likelihood_reference(
    theta: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    sensor: Sensor,
    plume: IsotropicPlume,
) -> np.ndarray:
    """NumPy reference of the compiled history likelihood: (N,) Σ_k m_k log p(z_k | Θ_i)."""
    conc = isotropic_concentration_reference(theta, positions, plume.min_distance, *plume.shape)
    d = positions[None, :, :] - theta[:, None, :3]
    dist = np.maximum(np.sqrt(np.einsum("nki,nki->nk", d, d)), plume.min_distance)
    ll = sensor.log_likelihood(readings[None, :], conc, dist)
    return (ll * multiplicity[None, :]).sum(axis=1)


@njit(cache=True, parallel=True)
def _history_from_concentration_kernel(
    conc: np.ndarray,
    dist: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    sp: SensorParams,
    out: np.ndarray,
) -> None:
    """out[i] += Σ_k multiplicity[k] · log p(readings[k] | conc[i, k], dist[i, k])."""
    for i in prange(conc.shape[0]):
        total = 0.0
        for k in range(conc.shape[1]):
            total += multiplicity[k] * log_likelihood(readings[k], conc[i, k], dist[i, k], sp)
        out[i] += total


HISTORY_CHUNK = 64
"""Positions per call of a plume without compiled constants (bounds the (N, chunk) arrays)."""


def history_log_likelihood_generic(
    plume: object,
    theta: np.ndarray,
    active: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    sp: SensorParams,
    out: np.ndarray,
) -> None:
    """:func:`history_log_likelihood` for a plume that predicts with its own method,
    ``plume.concentration_distance(theta, positions)`` → ((N, K) g/m³, (N, K) m) (the
    wall-aware plume, :class:`~dcee.models.site_plume.SitePlume`): the same sum of the same
    scalar log-likelihood, without the early rejection (an exact value in its place)."""
    live = np.flatnonzero(np.asarray(active, dtype=np.bool_))
    theta = np.ascontiguousarray(np.asarray(theta, dtype=np.float64)[live])
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    readings = np.ascontiguousarray(readings, dtype=np.float64)
    multiplicity = np.ascontiguousarray(multiplicity, dtype=np.float64)
    total = np.zeros(len(live))
    for start in range(0, len(positions), HISTORY_CHUNK):
        rows = slice(start, start + HISTORY_CHUNK)
        conc, dist = plume.concentration_distance(theta, positions[rows])  # type: ignore[attr-defined]
        _history_from_concentration_kernel(
            np.ascontiguousarray(conc),
            np.ascontiguousarray(dist),
            readings[rows],
            multiplicity[rows],
            sp,
            total,
        )
    out[:] = -np.inf
    out[live] = total
