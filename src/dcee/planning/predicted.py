"""The shared predicted-posterior machinery: hypothesised readings and the posteriors they imply.

Every cost-based planner runs the same steps; only the cost differs (as in the paper):

1. Draw J hypothesised sources Θ_j from the current belief by systematic sampling (O(N + J),
   no sorting) and J sets of standard sensor noise per horizon stage. The *same* draws serve every
   candidate move, so candidates are compared on common random numbers.
2. For a candidate sequence of positions p_1..p_T, the hypothesised readings are
   z_jt = sensor(C(p_t; Θ_j), noise_jt).
3. For each j the predicted posterior has weights w'_i ∝ w_i Π_t p(z_jt | C(p_t; Θ_i)); we reduce
   it to its log evidence, mean source location, trace of the location covariance and its
   KL divergence from the current belief.

Work is shared where the mathematics allows: the concentration of every particle at a position
is computed once per decision, and identical hypothesised reading sequences (in practice: every
all-non-detection hypothesis, which shares one likelihood vector) are evaluated once. Memory is
O(N · positions + J · sequences); no N × J × moves array is formed.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.estimation.particle_filter import systematic_resample
from dcee.models.agent import GridAgent
from dcee.models.plume_kernels import concentration_distance_grid
from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import position_terms
from dcee.planning.base import Belief, Planner
from dcee.planning.predicted_kernels import predicted_posterior_stats


@dataclass(frozen=True)
class SequenceStats:
    """Predicted-posterior statistics for S candidate sequences × J hypotheses.

    readings (S, J, T); log_evidence (S, J); mean (S, J, 3); trace_cov (S, J); kl (S, J).
    """

    readings: np.ndarray
    log_evidence: np.ndarray
    mean: np.ndarray
    trace_cov: np.ndarray
    kl: np.ndarray


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
    s_count, t_count = task_positions.shape
    log_ev = np.empty(s_count)
    mean = np.empty((s_count, 3))
    trace = np.empty(s_count)
    kl = np.empty(s_count)
    for s in range(s_count):
        ll = np.zeros(source.shape[0])
        for t in range(t_count):
            p = task_positions[s, t]
            ll += sensor.log_likelihood(task_readings[s, t], conc[p], dist[p])
        mx = ll[weights > 0].max()
        # zero-weight particles may exceed mx; clip them so that 0 · exp(·) stays 0
        e = weights * np.exp(np.minimum(ll - mx, 0.0))
        w_post = e / e.sum()
        log_ev[s] = mx + np.log(e.sum())
        mean[s] = w_post @ source
        d = source - mean[s]
        trace[s] = w_post @ np.einsum("ij,ij->i", d, d)
        pos = w_post > 0
        kl[s] = np.sum(w_post[pos] * (np.log(w_post[pos]) - np.log(weights[pos])))
    return log_ev, mean, trace, kl


class PredictionContext:
    """One decision's hypotheses and caches; planners ask it for :class:`SequenceStats`."""

    def __init__(
        self, belief: Belief, n_hypotheses: int, horizon: int, rng: np.random.Generator
    ) -> None:
        self.belief = belief
        self.sensor = belief.sensor
        self._sp = belief.sensor.params
        self.indices = systematic_resample(belief.weights, rng, n_hypotheses)
        # Shuffle so that hypothesis j is not tied to a weight stratum at every stage.
        self.indices = rng.permutation(self.indices)
        self.noise = belief.sensor.draw_noise(rng, (n_hypotheses, horizon))
        self._theta = np.ascontiguousarray(belief.theta)
        self._source = np.ascontiguousarray(belief.source)
        self._center = belief.source_mean()
        self._rows: list[tuple[np.ndarray, ...]] = []
        self._index: dict[tuple[float, ...], int] = {}
        self._terms: tuple[np.ndarray, ...] | None = None

    @property
    def n_hypotheses(self) -> int:
        return len(self.indices)

    def position_index(self, positions: np.ndarray) -> np.ndarray:
        """Indices of (K, 3) positions in the concentration cache, computing new ones."""
        out = np.empty(len(positions), dtype=np.int64)
        new: list[np.ndarray] = []
        for k, p in enumerate(positions):
            key = tuple(np.round(p, 9).tolist())
            if key not in self._index:
                self._index[key] = len(self._index)
                new.append(p)
            out[k] = self._index[key]
        if new:
            pts = np.ascontiguousarray(np.array(new, dtype=np.float64))
            shape = (len(pts), self._theta.shape[0])
            conc, dist, loc, log_nd, inv_sigma, det_offset = (np.empty(shape) for _ in range(6))
            plume = self.belief.plume
            concentration_distance_grid(
                self._theta, pts, plume.min_distance, plume.meander, conc, dist
            )
            position_terms(conc, dist, self._sp, loc, log_nd, inv_sigma, det_offset)
            self._rows.append((conc, dist, loc, log_nd, inv_sigma, det_offset))
            self._terms = None
        return out

    @property
    def terms(self) -> tuple[np.ndarray, ...]:
        """(conc, dist, loc, log_nd, inv_sigma, det_offset), each (P, N), at every cached
        position (see :func:`dcee.models.sensor_kernels.position_terms`)."""
        if self._terms is None and len(self._rows) == 1:
            self._terms = self._rows[0]
        elif self._terms is None:
            self._terms = tuple(
                np.ascontiguousarray(np.concatenate([r[k] for r in self._rows], axis=0))
                for k in range(6)
            )
        return self._terms

    @property
    def conc(self) -> np.ndarray:
        """(P, N) concentrations of every particle at every cached position."""
        return self.terms[0]

    def readings(self, pos_idx: np.ndarray) -> np.ndarray:
        """(J, T) hypothesised readings along one sequence of cached positions (T,)."""
        t_count = len(pos_idx)
        c = self.conc[pos_idx][:, self.indices].T  # (J, T)
        r = self.terms[1][pos_idx][:, self.indices].T
        return self.sensor.simulate_from(c, self.noise[:, :t_count], r)

    def stats(self, sequences: np.ndarray, moments: bool = True, kl: bool = True) -> SequenceStats:
        """Statistics for (S, T, 3) candidate position sequences (T ≤ horizon).

        ``moments=False`` leaves mean and trace_cov NaN, ``kl=False`` leaves kl NaN: each
        saves work in the kernel when a planner's cost does not use it.
        """
        s_count, t_count, _ = sequences.shape
        j_count = self.n_hypotheses
        pos_idx = self.position_index(sequences.reshape(-1, 3)).reshape(s_count, t_count)
        readings = np.empty((s_count, j_count, t_count))
        task_pos: list[np.ndarray] = []
        task_z: list[np.ndarray] = []
        inverse = np.empty((s_count, j_count), dtype=np.int64)
        n_tasks = 0
        for s in range(s_count):
            z = self.readings(pos_idx[s])
            readings[s] = z
            uniq, inv = np.unique(z, axis=0, return_inverse=True)
            task_z.append(uniq)
            task_pos.append(np.broadcast_to(pos_idx[s], uniq.shape))
            inverse[s] = n_tasks + inv.ravel()
            n_tasks += len(uniq)
        tz = np.ascontiguousarray(np.concatenate(task_z))
        tp = np.ascontiguousarray(np.concatenate(task_pos))
        log_ev = np.empty(n_tasks)
        mean = np.empty((n_tasks, 3))
        trace = np.empty(n_tasks)
        kl_div = np.empty(n_tasks)
        predicted_posterior_stats(
            *self.terms[2:],
            self._source,
            self.belief.weights,
            self._center,
            tp,
            *self.sensor.transformed_readings(tz),
            self._sp,
            log_ev,
            mean,
            trace,
            kl_div,
            moments,
            kl,
        )
        return SequenceStats(
            readings, log_ev[inverse], mean[inverse], trace[inverse], kl_div[inverse]
        )


def dcee_cost(final_positions: np.ndarray, stats: SequenceStats) -> np.ndarray:
    """(S,) DCEE cost (the paper's theorem 1): mean over hypotheses of
    ‖p − s̄_{k+T|k}‖² + tr P_{k+T|k}, for (S, 3) final positions."""
    d = final_positions[:, None, :] - stats.mean
    return np.mean(np.einsum("sjk,sjk->sj", d, d) + stats.trace_cov, axis=1)


class OneStepPlanner(Planner):
    """A planner whose cost is a function of one-step predicted-posterior statistics."""

    uses_hypotheses = True
    #: which optional statistics :meth:`cost_from_stats` reads (see PredictionContext.stats)
    needs_moments = True
    needs_kl = True

    def __init__(self, n_hypotheses: int = 40) -> None:
        if int(n_hypotheses) != n_hypotheses or n_hypotheses < 1:
            raise DceeInputError("hypotheses", f"must be an integer >= 1, got {n_hypotheses}")
        self.n_hypotheses = int(n_hypotheses)

    def options(self) -> dict[str, Any]:
        return {"n_hypotheses": self.n_hypotheses}

    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        ctx = PredictionContext(belief, self.n_hypotheses, 1, rng)
        stats = ctx.stats(candidates[:, None, :], moments=self.needs_moments, kl=self.needs_kl)
        return self.cost_from_stats(candidates, stats, belief), {}

    @abstractmethod
    def cost_from_stats(
        self, candidates: np.ndarray, stats: SequenceStats, belief: Belief
    ) -> np.ndarray:
        """(M,) cost from (M, 3) candidates and their one-step statistics."""
