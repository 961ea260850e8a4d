"""Statistics of hypothesised reading sequences of two or three stages as products of per-stage
factors (numba): the multistage DCEE (``dcee-ms``) and any planner with ``horizon`` 2 or 3.

A task's relative weight of particle i is e_i = exp(Σ_t ll_ti − Σ_t b_t), b_t an upper bound of
stage t's term over the particles (:func:`~dcee.planning.reading_terms.stage_bound`), so
e_i = Π_t F_ti with F_ti = exp(ll_ti − b_t). A factor depends only on its stage's position and
reading, and candidate sequences share both: hypothesis j reads the same z_j1 at the first
position for every continuation, the sequences of a beam meet at the same second positions, and
every non-detection at one position is one factor. So each block of particles computes every
distinct factor once (one ``exp`` per particle, the outlier component added as a constant), and
a task's weights are T − 1 multiplications; the sums are matrix products over chunks of tasks
(:func:`dcee.planning.block_sums.task_sums`). Measured on recorded ``dcee-ms`` decisions
(paper:1, 20,000 particles, one core; docs/performance.md): about 340 tasks of two stages read
about 100 distinct factors per decision.

Every factor is floored at e^(−680 / T), so a product never leaves float64's normal range (it is
at least e^−680; arithmetic on subnormal floats is about 100× slower). A floored particle's
weight is too large by at most e^(−680 / T) (every factor is at most 1), so the sums are exact to
that absolute error, and a task whose sum of weights is below e^(−680 / T + 80)
(:func:`redo_below`) is redone exactly by the caller, as a task of the one-pass kernel is below
e^−600. Tasks with false alarms (a detection's term is then a sum of two particle-dependent
parts, not one factor) or with more than three stages (the floor would be too high) use the
kernel of :mod:`dcee.planning.multi_stage_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from dcee.models.sensor_kernels import SensorParams
from dcee.numeric import HALF_LOG_2PI, exp_scalar, log_scalar
from dcee.planning.block_sums import BLOCK, task_sums
from dcee.planning.multi_stage_kernels import EXP_FLOOR
from dcee.planning.reading_terms import stage_bound

MAX_STAGES = 3
_FLOOR_TOTAL = EXP_FLOOR  # the smallest product: e^-680 times a weight ≥ 1e-12 stays normal
_REDO_MARGIN = 80.0
# tasks per matrix product: measured on a recorded dcee-ms decision, 8-32 alike (10.3-10.8 ms),
# 128 slower (20.7 ms: the weights leave the cache), one product per sequence 12.3 ms (calls)
_CHUNK = 32


def applies(t_count: int, sp: SensorParams) -> bool:
    """Whether tasks of ``t_count`` stages with this sensor take the product kernel."""
    return 2 <= t_count <= MAX_STAGES and sp.false_alarm == 0.0


def redo_below(t_count: int) -> float:
    """A task whose log sum of relative weights is below this is redone exactly."""
    return _FLOOR_TOTAL / t_count + _REDO_MARGIN


def stage_keys(
    task_positions: np.ndarray, task_v: np.ndarray, task_out: np.ndarray, sp: SensorParams
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The distinct stage factors of S tasks of T stages: (key of each task's stage (S, T),
    and per key its position row, transformed reading (−inf: a non-detection, one key per
    position) and outlier term)."""
    detected = task_v >= sp.v_threshold
    rows = np.stack(
        [
            task_positions.astype(np.float64),
            np.where(detected, task_v, -np.inf),
            np.where(detected, task_out, 0.0),
        ],
        axis=-1,
    ).reshape(-1, 3)
    keys, key_of = np.unique(rows, axis=0, return_inverse=True)
    key_of = key_of.reshape(task_positions.shape).astype(np.int64)
    return key_of, keys[:, 0].astype(np.int64), keys[:, 1].copy(), keys[:, 2].copy()


@njit(cache=True)
def key_bounds(
    key_p: np.ndarray,
    key_v: np.ndarray,
    key_out: np.ndarray,
    max_log_nd: np.ndarray,
    max_det_offset: np.ndarray,
    sp: SensorParams,
) -> np.ndarray:
    """Each key's stage bound (the terms whose sum is each task's bound)."""
    out = np.empty(key_p.shape[0])
    for k in range(key_p.shape[0]):
        out[k] = stage_bound(key_p[k], key_v[k], 0.0, key_out[k], max_log_nd, max_det_offset, sp)
    return out


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _stage_factor(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    i0: int,
    n: int,
    v: float,
    out: float,
    bnd: float,
    floor: float,
    sp: SensorParams,
    f: np.ndarray,
) -> None:
    """f[q] = max(exp(ll_i − bnd), e^floor) for particles i = i0 + q, q < n, of one position
    row and one stage's reading (with the outlier component: its constant e^(out − bnd) added
    to the floored detection term). Branch-free loops, vectorised."""
    if v < sp.v_threshold:
        for q in range(n):
            x = log_nd[np.uint64(i0 + q)] - bnd
            f[np.uint64(q)] = exp_scalar(min(max(x, floor), 0.0))
        return
    det_add = sp.log_keep - HALF_LOG_2PI - bnd
    out_term = exp_scalar(min(out - bnd, 0.0)) if sp.log_outlier > -np.inf else 0.0
    for q in range(n):
        i = np.uint64(i0 + q)
        r = (v - loc[i]) * inv_sigma[i]
        x = det_offset[i] + det_add - 0.5 * r * r
        f[np.uint64(q)] = exp_scalar(min(max(x, floor), 0.0)) + out_term


@njit(cache=True, parallel=True, fastmath={"contract"}, error_model="numpy")
def product_stats(
    loc: np.ndarray,
    log_nd: np.ndarray,
    inv_sigma: np.ndarray,
    det_offset: np.ndarray,
    weights: np.ndarray,
    weighted: np.ndarray,
    key_p: np.ndarray,
    key_v: np.ndarray,
    key_out: np.ndarray,
    key_bound: np.ndarray,
    key_of: np.ndarray,
    bound: np.ndarray,
    sp: SensorParams,
    want_moments: bool,
    want_kl: bool,
    partial: np.ndarray,
) -> None:
    """partial[b, s, :] = the six sums of task s over particle block b (as
    :func:`dcee.planning.predicted_kernels._grouped_stats` writes them): position terms
    (P, N); weights (N,); weighted (N, 5) :func:`~dcee.planning.block_sums.weighted_columns`;
    the keys of :func:`stage_keys` with their :func:`key_bounds`; bound (S,) each task's
    bound (the sum of its keys')."""
    n = weights.shape[0]
    n_blocks = (n + BLOCK - 1) // BLOCK
    n_keys = key_p.shape[0]
    s_count, t_count = key_of.shape
    floor = _FLOOR_TOTAL / t_count
    for b in prange(n_blocks):
        i0 = b * BLOCK
        nb = min(n, i0 + BLOCK) - i0
        f = np.empty((n_keys, nb))
        for k in range(n_keys):
            p = key_p[k]
            _stage_factor(
                loc[p], log_nd[p], inv_sigma[p], det_offset[p], i0, nb, key_v[k], key_out[k],
                key_bound[k], floor, sp, f[k],
            )  # fmt: skip
        # the tasks in chunks of _CHUNK, one matrix product each
        for s0 in range(0, s_count, _CHUNK):
            k_count = min(s_count, s0 + _CHUNK) - s0
            e = np.empty((k_count, nb))
            el = np.empty((k_count, nb))
            for j in range(k_count):
                ej = e[j]
                first = f[key_of[s0 + j, 0]]
                second = f[key_of[s0 + j, 1]]
                for q in range(nb):
                    ej[q] = first[q] * second[q]
                for t in range(2, t_count):
                    ft = f[key_of[s0 + j, t]]
                    for q in range(nb):
                        ej[q] *= ft[q]
                if want_kl:
                    elj = el[j]
                    for q in range(nb):
                        elj[q] = ej[q] * log_scalar(ej[q])
            sums = np.empty((k_count, partial.shape[2]))
            task_sums(e, el, weights, weighted, i0, want_moments, want_kl, sums)
            for j in range(k_count):
                for a in range(partial.shape[2]):
                    partial[b, s0 + j, a] = sums[j, a]
                # Σ w e ll = Σ w e log e + bound Σ w e (log e = ll − bound)
                if want_kl:
                    partial[b, s0 + j, 5] += bound[s0 + j] * sums[j, 0]
