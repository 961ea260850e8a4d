"""Compiled expected information about the source *location*: the KL divergence between the
predicted and the current distribution of the source location over cubes (:func:`location_kl`,
the particles grouped by :func:`location_cells`); its NumPy reference is
:func:`dcee.planning.predicted_reference.location_kl_reference`. Parallel over tasks, sequential
within one, so results do not depend on the thread count."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dcee.models.sensor_kernels import SensorParams
from dcee.planning.reading_terms import task_log_likelihoods


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
