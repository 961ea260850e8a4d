"""Compiled (numba) per-position likelihood terms of a particle set: the plume constants of each
particle (:func:`plume_constants`), the terms at a batch of positions (:func:`position_rows`,
cached across decisions by :class:`~dcee.planning.particle_terms.ParticleTerms`) and the content
hash that detects a changed particle set. Tested against the NumPy plume and sensor models."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.plume_kernels import (
    constants_at,
    plume_at,
    plume_from_terms,
    plume_terms,
)
from dcee.models.sensor_kernels import (
    SensorParams,
    log_detection_probability,
    log_likelihood,
    transform,
)
from dcee.numeric import (
    log_scalar,
    vlog1m,
    vndtr_upper,
)

_HASH_MUL1 = np.uint64(0x9E3779B97F4A7C15)
_HASH_MUL2 = np.uint64(0xBF58476D1CE4E5B9)
_HASH_MUL3 = np.uint64(0x94D049BB133111EB)


@njit(cache=True, parallel=True)
def content_hash(bits: np.ndarray) -> tuple[int, int]:
    """(Σ bits[k]·h(k), Σ bits[k]·h'(k)) modulo 2^64 for bits (n,) uint64 (a float array's
    IEEE-754 bits, viewed): a fingerprint of an array's contents. h(k) is an odd 64-bit mix of
    k (splitmix64's), h'(k) = h(k)·another odd constant; so a change of any one element always
    changes both sums (an odd factor is invertible modulo 2^64), and integer sums do not depend
    on their order. Computed from the index, not read from a stored probe: no megabyte of
    random numbers to fetch at every decision (measured, 80,000 values: 18 µs against 47 µs
    for two dot products with a stored probe, hot, 11 µs on two threads; the probe came from
    memory in a decision)."""
    a = np.uint64(0)
    b = np.uint64(0)
    one = np.uint64(1)
    for k in prange(bits.shape[0]):  # integer sums: the same for any split over threads
        h = (np.uint64(k) + one) * _HASH_MUL1
        h = (h ^ (h >> np.uint64(29))) * _HASH_MUL2
        h = (h ^ (h >> np.uint64(32))) | one
        a += bits[k] * h
        b += bits[k] * (h * _HASH_MUL3)
    return a, b


N_PLUME_CONSTANTS = 10
"""Per-particle plume constants (:func:`~dcee.models.plume_kernels.plume_terms`)."""


@njit(cache=True, parallel=True)
def plume_constants(theta: np.ndarray, out: np.ndarray) -> None:
    """out[:, i] = :func:`~dcee.models.plume_kernels.plume_terms` of particle i (the source
    location, q/(4π ζ1), 1/λ, u cosφ/(2ζ1), u sinφ/(2ζ1), cos φ, sin φ, u/(2ζ1)): the square
    root, cosine and sine of a particle, computed once per particle set instead of at every
    new position. theta (N, 8); out (10, N)."""
    for i in prange(theta.shape[0]):
        terms = plume_terms(theta, i)
        for k in range(N_PLUME_CONSTANTS):
            out[k, i] = terms[k]


@njit(cache=True)
def vectorised_case(
    sp: SensorParams,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
) -> bool:
    """True for the paper's sensor and plume (Gaussian family, constant Pd < 1; no meander,
    backflow or area release; decay 1), which the branch-free loops with the vectorisable
    ``exp``, ``log`` and ``erfc`` of :mod:`dcee.numeric` handle (:func:`position_rows`, the
    exploration guard's information); every other case takes the scalar libm formulas."""
    return (
        sp.lognormal == 0.0
        and sp.pd < 1.0
        and sp.near_length == 0.0
        and meander == 0.0
        and decay == 1.0
        and backflow == 0.0
        and radius == 0.0
        and vertical == 1.0
        and ground == 0.0
        and meander_z == 0.0
        and sp.sigma_min >= 2.0**-60  # σ within the range of the vectorised log
    )


_ROW_BLOCK = 512  # particles per work item of position_rows (4 KB per row: within L1)


# The common case in four loops over a block of particles, not one. Each particle's arithmetic
# is the same, in the same order (bit for bit the one fused loop it replaces), but a fused loop
# body of ~200 vector instructions holds three long dependency chains (the plume's exp, the
# erfc's 25-term Clenshaw recurrence, two logs), longer than the out-of-order window: the core
# waited on each chain's latency. In short loops the next iterations' chains overlap:
# 557 → 345 µs on one thread for 6 positions × 7,703 particles (lab measurement, 2026-11-29,
# Stone Soup's workload; docs/performance.md "Issue 46 (2026-11-29, later)").


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _rows_plume(
    plume: np.ndarray,
    i0: int,
    i1: int,
    px: float,
    py: float,
    pz: float,
    rmin: float,
    conc: np.ndarray,
    dist: np.ndarray,
) -> None:
    """Phase 1 of the common case: C and the clamped distance r of particles i0..i1−1 at one
    position (the transformed location of the Gaussian family is C itself: copied by the
    caller where it has rows of its own)."""
    for j in range(i1 - i0):
        # an unsigned index: numba then emits no negative-index wraparound, which would keep
        # LLVM from vectorising the loop
        i = np.uint64(i0 + j)
        c, r = plume_from_terms(
            plume[0, i],
            plume[1, i],
            plume[2, i],
            plume[3, i],
            plume[4, i],
            plume[5, i],
            plume[6, i],
            px,
            py,
            pz,
            rmin,
        )
        conc[i] = c
        dist[i] = r


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _rows_sigma(
    i0: int,
    i1: int,
    sp: SensorParams,
    conc: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
) -> None:
    """Phase 2: 1/σ and log Pd − log σ, σ = σ_frac C + σ_min."""
    for j in range(i1 - i0):
        i = np.uint64(i0 + j)
        sigma = sp.sigma_frac * conc[i] + sp.sigma_min
        inv_sigma[i] = 1.0 / sigma
        det_offset[i] = sp.log_pd - log_scalar(sigma)


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _rows_detect(
    i0: int, i1: int, sp: SensorParams, conc: np.ndarray, inv_sigma: np.ndarray, log_nd: np.ndarray
) -> None:
    """Phase 3: Pd Φ(−(threshold − C)/σ), the probability of a detection, into log_nd."""
    for j in range(i1 - i0):
        i = np.uint64(i0 + j)
        log_nd[i] = sp.pd * vndtr_upper((sp.v_threshold - conc[i]) * inv_sigma[i])


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _rows_missed(i0: int, i1: int, sp: SensorParams, conc: np.ndarray, log_nd: np.ndarray) -> None:
    """Phase 4: log_nd = log(1 − Pd Φ(·)) (linearised below c_lin) + the false-alarm and
    keep terms: log p(non-detection | C)."""
    missed_offset = sp.log_not_false_alarm + sp.log_keep
    for j in range(i1 - i0):
        i = np.uint64(i0 + j)
        c = conc[i]
        missed = vlog1m(log_nd[i])
        lin = sp.lin0 + sp.lin1 * c
        log_nd[i] = (lin if c < sp.c_lin else missed) + missed_offset


@njit(cache=True, inline="always")
def _store_terms(
    c: float,
    r: float,
    sp: SensorParams,
    row: int,
    i: int,
    conc: np.ndarray,
    dist: np.ndarray,
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
) -> None:
    """The terms of one particle at one position from its concentration ``c`` and clamped
    source distance ``r``, by the scalar formulas of :mod:`dcee.models.sensor_kernels`, into
    row ``row``, column ``i`` of each output (:func:`position_rows`' general path and
    :func:`rows_from_concentration`)."""
    m, sigma = transform(c, r, sp)
    conc[row, i] = c
    dist[row, i] = r
    loc[row, i] = m
    inv_sigma[row, i] = 1.0 / sigma
    log_nd[row, i] = log_likelihood(0.0, c, r, sp)
    det_offset[row, i] = log_detection_probability(r, sp) - math.log(sigma)


@njit(cache=True, parallel=True)
def position_rows(
    plume: np.ndarray,
    positions: np.ndarray,
    rows: np.ndarray,
    rmin: float,
    meander: float,
    decay: float,
    backflow: float,
    radius: float,
    vertical: float,
    ground: float,
    meander_z: float,
    sp: SensorParams,
    conc: np.ndarray,
    dist: np.ndarray,
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
) -> None:
    """Row rows[k] of each (R, N) output = the terms of every particle at positions[k] that do
    not depend on the reading: the concentration C and the clamped source distance r (as
    :func:`~dcee.models.plume_kernels.concentration_distance_grid`), the transformed location,
    log p(non-detection | C, r), 1/σ and log Pd(r) − log σ (see
    :mod:`dcee.models.sensor_kernels`). With them a hypothesised reading costs a lookup
    (non-detection) or a few flops (detection). plume (10, N) from :func:`plume_constants`;
    positions (K, 3); rows (K,) distinct. NumPy references:
    :func:`~dcee.models.plume.isotropic_concentration_reference`,
    :meth:`~dcee.models.sensor.Sensor.log_likelihood`.

    Blocks of particles run in parallel. The paper's sensor (Gaussian family, constant Pd < 1)
    without meander or backflow and with decay 1 takes four short loops (:func:`_rows_plume`
    to :func:`_rows_missed`), vectorised with
    the ``exp``, ``log`` and ``erfc`` of :mod:`dcee.numeric`; every other case the scalar
    formulas with libm
    (with Pd = 1, log Φ needs relative accuracy far in the tail).
    """
    n = plume.shape[1]
    n_blocks = (n + _ROW_BLOCK - 1) // _ROW_BLOCK
    fast = vectorised_case(sp, meander, decay, backflow, radius, vertical, ground, meander_z)
    # the location is C itself in the common case; its rows may share C's memory
    # (ParticleTerms' LOC_IS_CONC_SLOTS), and are then not written twice
    loc_own_rows = loc.ctypes.data != conc.ctypes.data
    for b in prange(n_blocks):
        i0 = b * _ROW_BLOCK
        i1 = min(n, i0 + _ROW_BLOCK)
        for k in range(positions.shape[0]):
            px = positions[k, 0]
            py = positions[k, 1]
            pz = positions[k, 2]
            row = rows[k]
            if fast:
                _rows_plume(plume, i0, i1, px, py, pz, rmin, conc[row], dist[row])
                if loc_own_rows:
                    loc[row, i0:i1] = conc[row, i0:i1]
                _rows_sigma(i0, i1, sp, conc[row], inv_sigma[row], det_offset[row])
                _rows_detect(i0, i1, sp, conc[row], inv_sigma[row], log_nd[row])
                _rows_missed(i0, i1, sp, conc[row], log_nd[row])
                continue
            for i in range(i0, i1):
                c, r = plume_at(
                    constants_at(plume, i), px, py, pz, rmin, meander, decay, backflow, radius,
                    vertical, ground, meander_z,
                )  # fmt: skip
                _store_terms(c, r, sp, row, i, conc, dist, loc, log_nd, inv_sigma, det_offset)


@njit(cache=True, parallel=True)
def rows_from_concentration(
    conc_in: np.ndarray,
    dist_in: np.ndarray,
    rows: np.ndarray,
    sp: SensorParams,
    conc: np.ndarray,
    dist: np.ndarray,
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
) -> None:
    """:func:`position_rows` for a plume that predicts with its own method (the wall-aware
    one): conc_in, dist_in (K, N) its concentrations and clamped source distances at K
    positions; row rows[k] of each output gets the terms of position k (the scalar formulas of
    :func:`position_rows`' general path)."""
    for k in range(conc_in.shape[0]):
        row = rows[k]
        for i in prange(conc_in.shape[1]):
            _store_terms(
                conc_in[k, i], dist_in[k, i], sp, row, i,
                conc, dist, loc, log_nd, inv_sigma, det_offset,
            )  # fmt: skip
