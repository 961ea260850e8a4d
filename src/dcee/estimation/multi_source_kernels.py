"""Compiled (numba) likelihood of readings under K releases; NumPy reference:
:func:`multi_history_log_likelihood_reference`.

A particle of a K-source filter is a row of 8 + 4 (K − 1) numbers: the first release's full
source term (x, y, z, q, u, φ, ζ1, ζ2), then (x, y, z, q) of each further release, which shares
the first one's wind and diffusion (one flow carries every release, as in the truths). The
concentration a particle predicts at a position is the sum of its releases' plumes (the model
is linear in the release rate); the source distance the sensor model reads (near-source
intermittency) is the distance to the nearest release.

Early rejection as in :mod:`dcee.estimation.filter_kernels`: a proposal whose partial
history sum plus the upper bounds of the readings still to come falls below its acceptance
threshold is abandoned (−inf, which the move rejects as it would have).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dcee.estimation.filter_kernels import rejection_bounds
from dcee.models.plume import IsotropicPlume, isotropic_concentration_reference
from dcee.models.plume_kernels import constants_at, plume_at, plume_terms
from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import SensorParams, log_likelihood

_BLOCK = 128  # particles per work item
_CHECK_EVERY = 8  # readings between early-rejection checks
_MARGIN = 1e-9  # as in dcee.estimation.filter_kernels

EXTRA_COLUMNS = 4
"""Columns each release after the first adds to a particle: x, y, z (m) and q (g/s)."""


def source_count(width: int) -> int:
    """K, the releases in a particle row of ``width`` = 8 + 4 (K − 1) columns."""
    k, rest = divmod(width - 8, EXTRA_COLUMNS)
    if width < 8 or rest:
        raise ValueError(f"a K-source particle has 8 + 4 (K − 1) columns, got {width}")
    return k + 1


def source_rows(theta: np.ndarray) -> np.ndarray:
    """(K, N, 8): release j of every particle of ``theta`` (N, 8 + 4 (K − 1)) as an ordinary
    source term (its location and rate, the shared wind and diffusion)."""
    k = source_count(theta.shape[1])
    out = np.repeat(theta[None, :, :8], k, axis=0)
    for j in range(1, k):
        base = 8 + EXTRA_COLUMNS * (j - 1)
        out[j, :, :4] = theta[:, base : base + 4]
    return out


@njit(cache=True, parallel=True)
def _multi_history_kernel(
    rows: np.ndarray,
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
    k_sources = rows.shape[0]
    n = rows.shape[1]
    k_count = readings.shape[0]
    n_blocks = (n + _BLOCK - 1) // _BLOCK
    for b in prange(n_blocks):
        i0 = b * _BLOCK
        nb = min(n, i0 + _BLOCK) - i0
        # release j of particle q at column j * nb + q
        pc = np.empty((10, k_sources * nb))
        for j in range(k_sources):
            for q in range(nb):
                terms = plume_terms(rows[j], i0 + q)
                for c in range(10):
                    pc[c, j * nb + q] = terms[c]
        for q in range(nb):
            i = i0 + q
            if not active[i]:
                out[i] = -np.inf
                continue
            acc = 0.0
            alive = True
            t = threshold[i]
            for k in range(k_count):
                px = positions[k, 0]
                py = positions[k, 1]
                pz = positions[k, 2]
                conc = 0.0
                dist = np.inf
                for j in range(k_sources):
                    c, r = plume_at(
                        constants_at(pc, j * nb + q),
                        px,
                        py,
                        pz,
                        rmin,
                        meander,
                        decay,
                        backflow,
                        radius,
                        vertical,
                        ground,
                        meander_z,
                    )
                    conc += c
                    dist = min(dist, r)
                acc += multiplicity[k] * log_likelihood(readings[k], conc, dist, sp)
                if (k + 1) % _CHECK_EVERY == 0 and k + 1 < k_count:
                    if acc + remaining_bound[k + 1] < t - _MARGIN * (1.0 + abs(t)):
                        alive = False
                        break
            out[i] = acc if alive else -np.inf


def multi_history_log_likelihood(
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
    """out[i] = Σ_k multiplicity[k] · log p(readings[k] | Σ_j C(positions[k]; release j of
    theta[i])), theta (N, 8 + 4 (K − 1)); the arguments as
    :func:`dcee.estimation.filter_kernels.history_log_likelihood` takes them."""
    n = theta.shape[0]
    multiplicity = np.ascontiguousarray(multiplicity, dtype=np.float64)
    threshold, remaining = rejection_bounds(n, multiplicity, threshold, bounds)
    _multi_history_kernel(
        np.ascontiguousarray(source_rows(np.asarray(theta, dtype=np.float64))),
        np.ascontiguousarray(active, dtype=np.bool_),
        np.ascontiguousarray(positions, dtype=np.float64).reshape(-1, 3),
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


def multi_concentration_reference(
    theta: np.ndarray, positions: np.ndarray, plume: IsotropicPlume
) -> tuple[np.ndarray, np.ndarray]:
    """NumPy reference: ((N, M) summed concentrations, (N, M) distance to the nearest release,
    clamped at the plume's least distance) of particles (N, 8 + 4 (K − 1)) at (M, 3)."""
    rows = source_rows(np.asarray(theta, dtype=np.float64))
    conc = sum(
        isotropic_concentration_reference(r, positions, plume.min_distance, *plume.shape)
        for r in rows
    )
    dist = np.min(
        [np.linalg.norm(positions[None, :, :] - r[:, None, :3], axis=2) for r in rows], axis=0
    )
    return conc, np.maximum(dist, plume.min_distance)


def multi_history_log_likelihood_reference(
    theta: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    sensor: Sensor,
    plume: IsotropicPlume,
) -> np.ndarray:
    """NumPy reference of the compiled K-source history likelihood: (N,) Σ_k m_k log p(z_k |
    Θ_i)."""
    conc, dist = multi_concentration_reference(theta, positions, plume)
    ll = sensor.log_likelihood(readings[None, :], conc, dist)
    return (ll * multiplicity[None, :]).sum(axis=1)
