"""NumPy references of the compiled predicted-posterior kernels
(:func:`dcee.planning.predicted_kernels.predicted_posterior_stats`,
:func:`dcee.planning.location_kl.location_kl`): plain loops over the tasks from concentrations
and raw readings, what the kernels are tested against (tests/test_kernels.py)."""

from __future__ import annotations

import numpy as np

from dcee.models.sensor import Sensor


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
    """NumPy reference of :func:`dcee.planning.location_kl.location_kl`: (S,) KL
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


def unique_per_sequence_reference(
    readings: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The distinct reading sequences of each candidate: readings (S, J, T) →
    (task readings (Q, T), the candidate of each task (Q,), inverse (S, J) task of each
    hypothesis). Tasks are ordered by candidate, then lexicographically by reading (the order
    ``np.unique(readings[s], axis=0)`` gives), so identical hypotheses of one candidate
    (in practice every non-detection) are evaluated once. The NumPy reference of the compiled
    :func:`~dcee.planning.reading_terms.unique_tasks` the planners call."""
    s_count, j_count, t_count = readings.shape
    flat = readings.reshape(s_count * j_count, t_count)
    seq = np.repeat(np.arange(s_count), j_count)
    order = np.lexsort((*flat.T[::-1], seq))  # the last key is the primary one
    fs, ss = flat[order], seq[order]
    new = np.ones(len(order), dtype=bool)
    new[1:] = (ss[1:] != ss[:-1]) | np.any(fs[1:] != fs[:-1], axis=1)
    task = np.cumsum(new) - 1
    inverse = np.empty(len(order), dtype=np.int64)
    inverse[order] = task
    return np.ascontiguousarray(fs[new]), ss[new], inverse.reshape(s_count, j_count)
