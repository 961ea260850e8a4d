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

import copy
from dataclasses import dataclass

import numpy as np

from dcee.errors import DceeInputError
from dcee.estimation.resampling import systematic_resample
from dcee.planning.base import Belief
from dcee.planning.location_kl import location_cells, location_kl
from dcee.planning.particle_terms import ParticleTerms, PositionTerms
from dcee.planning.predicted_kernels import predicted_posterior_stats
from dcee.planning.reading_terms import (
    gaussian_sampled_readings,
    gaussian_transformed,
    plain_gaussian,
    unique_tasks,
)
from dcee.planning.stratified_kernels import stratified_hypotheses


@dataclass(frozen=True)
class SequenceStats:
    """Predicted-posterior statistics for S candidate sequences × J hypotheses.

    readings (S, J, T); probability (S, J): the share of the expectation each hypothesis stands
    for (rows sum to 1); log_evidence (S, J); mean (S, J, 3); trace_cov (S, J); kl (S, J).
    """

    readings: np.ndarray
    probability: np.ndarray
    log_evidence: np.ndarray
    mean: np.ndarray
    trace_cov: np.ndarray
    kl: np.ndarray
    location_kl: np.ndarray

    def expect(self, values: np.ndarray) -> np.ndarray:
        """(S,) expectation over the next readings of per-hypothesis ``values`` (S, J)."""
        return np.einsum("sj,sj->s", self.probability, values)


_NO_CENTER = np.zeros(3)  # passed where no statistic reads the reference point


EXPECTATIONS = ("sampled", "stratified")
"""How a planner estimates an expectation over the next readings:

* ``sampled`` (the paper): J hypothesised sources drawn from the belief, each with its own
  reading; every hypothesis weighs 1/J.
* ``stratified``: the outcome "no detection at any stage" is one hypothesis weighted by its exact
  probability Σ_i w_i Π_t P(nd | C_i(p_t)); J detection hypotheses are drawn from the predictive
  distribution conditioned on at least one detection (source i ∝ w_i (1 − Π_t P(nd | C_i(p_t))),
  the first detecting stage by its probability, that stage's reading from
  :meth:`~dcee.models.sensor.Sensor.simulate_detection`, later stages unconditioned), each
  weighing P(detection)/J. Unbiased for the same expectation, and far less variable when
  detections are rare: at a stall P(detection) is 0.1–1 % per candidate, so J sampled
  hypotheses mostly contain none and the cost differences between candidates are noise.
"""


NOISE_SHARING = ("shared", "fresh")
"""``shared``: one set of hypotheses for every candidate (common random numbers, our default);
``fresh``: new hypotheses and noise for every candidate sequence (the authors' example code)."""

HYPOTHESIS_READINGS = ("model", "noise-free", "miss-free")
"""How sampled hypothetical readings are made (ablation): from the full reading model; without
measurement noise (the reading is C wherever it is detected); or without random misses."""


def check_hypothesis_options(expectation: str, noise: str, readings: str) -> None:
    """:class:`~dcee.errors.DceeInputError` naming the option unless the three are allowed
    together (see :data:`EXPECTATIONS`, :data:`NOISE_SHARING`, :data:`HYPOTHESIS_READINGS`)."""
    for name, value, allowed in (
        ("expectation", expectation, EXPECTATIONS),
        ("noise", noise, NOISE_SHARING),
        ("readings", readings, HYPOTHESIS_READINGS),
    ):
        if value not in allowed:
            raise DceeInputError(name, f"must be one of {', '.join(allowed)}, got {value!r}")
    if expectation == "stratified" and readings != "model":
        raise DceeInputError(
            "readings", "simplified hypothetical readings need expectation=sampled"
        )


PRECISIONS = ("double", "single", "interpolated")
"""Arithmetic of the hypothesised readings' weights: ``double`` (float64 throughout),
``single`` (float32 exp and log for one-stage tasks, float64 sums; about 1e-6 relative, see
:mod:`dcee.planning.predicted_single`) or ``interpolated`` (one-stage tasks of the paper's
sensor family summed over nodes of the predicted concentration instead of over the particles;
about 1e-8 relative, see :mod:`dcee.planning.interpolated_kernels`). Tasks of several readings
are computed in double precision under every option."""


def check_precision(precision: object) -> None:
    """:class:`~dcee.errors.DceeInputError` unless ``precision`` is one of :data:`PRECISIONS`."""
    if precision not in PRECISIONS:
        raise DceeInputError(
            "precision", f"must be one of {', '.join(PRECISIONS)}, got {precision!r}"
        )


class PredictionContext:
    """One decision's hypotheses and caches; planners ask it for :class:`SequenceStats`.

    Every random number is drawn here, once per decision, and shared by every candidate
    sequence (common random numbers): the J hypothesised sources and J × horizon standard noise
    (sampled), or one systematic-sampling offset and per-hypothesis uniforms (stratified).
    ``noise="fresh"`` redraws them for every sequence instead.
    """

    def __init__(
        self,
        belief: Belief,
        n_hypotheses: int,
        horizon: int,
        rng: np.random.Generator,
        expectation: str = "sampled",
        noise: str = "shared",
        readings: str = "model",
        precision: str = "double",
    ) -> None:
        check_hypothesis_options(expectation, noise, readings)
        check_precision(precision)
        self.precision = precision
        self._pt = belief.cache if belief.cache is not None else ParticleTerms()
        self._pt.sync(belief.theta, belief.sensor, belief.plume)
        self._pt.begin()
        # the merged particles (see dcee.planning.particle_terms): same statistics, less work
        belief = Belief(
            self._pt.theta,
            self._pt.weights(belief.weights),
            belief.sensor,
            belief.plume,
            site=belief.site,
        )
        self.belief = belief
        self.sensor = belief.sensor
        self.expectation = expectation
        self._sp = belief.sensor.params
        self._n = int(n_hypotheses)
        self._horizon = int(horizon)
        self._rng = rng
        self._fresh = noise == "fresh"
        self._simplify = readings
        self._draw()
        self._source = self._pt.source  # belief.source, kept contiguous across decisions
        self._center_value: np.ndarray | None = None
        self._cell_cache: dict[float, tuple[np.ndarray, ...]] = {}

    @property
    def _center(self) -> np.ndarray:
        """(3,) the belief's mean source location: the reference the second moments are taken
        about (computed once, when a statistic first needs it)."""
        if self._center_value is None:
            self._center_value = self.belief.source_mean()
        return self._center_value

    def _draw(self) -> None:
        """Every random number one set of hypotheses needs (see the class docstring)."""
        rng, n = self._rng, self._n
        if self.expectation == "sampled":
            self.indices = systematic_resample(self.belief.weights, rng, n)
            # Shuffle so that hypothesis j is not tied to a weight stratum at every stage.
            self.indices = rng.permutation(self.indices)
        else:
            self._offset = rng.random()
            self._first_u = rng.random(n)  # picks the first detecting stage
            self._detect_u = rng.random((n, 2))  # that stage's reading
        self.noise = self.sensor.draw_noise(rng, (n, self._horizon))
        if self._simplify == "noise-free":
            self.noise[..., 1] = 0.0
        elif self._simplify == "miss-free":
            self.noise[..., 0] = 0.0  # below any Pd: every reading above the threshold is seen

    def branch(
        self, weights: np.ndarray, n_hypotheses: int, rng: np.random.Generator
    ) -> PredictionContext:
        """A one-stage context for the belief reweighted to ``weights`` (M,) (over this
        context's particles, :attr:`belief`) — the predicted posterior after a hypothesised
        reading — that reuses this context's per-position terms (they depend on Θ, not on the
        weights) and draws its own hypotheses from ``rng``.

        Particles below 1e-12 of the largest weight are dropped (their total share is below
        N · 1e-12): after a detection the branch keeps only the few particles that explain it.
        """
        keep = weights > 1e-12 * weights.max()
        other = copy.copy(self)
        theta = self.belief.theta
        if keep.mean() < 0.9:
            theta, weights = theta[keep], weights[keep] / weights[keep].sum()
            other._pt = self._pt.subset(keep)
            other._source = other._pt.source
        other.belief = Belief(theta, weights, self.sensor, self.belief.plume, site=self.belief.site)
        other._n, other._horizon, other._rng = int(n_hypotheses), 1, rng
        other._center_value = None
        other._cell_cache = {}
        other._draw()
        return other

    @property
    def n_hypotheses(self) -> int:
        """Hypotheses per sequence: J sampled, or J + 1 stratified (the first is "no
        detection")."""
        return self._n if self.expectation == "sampled" else self._n + 1

    def position_index(self, positions: np.ndarray) -> np.ndarray:
        """Rows of (K, 3) positions in :attr:`terms`, computing new ones."""
        return self._pt.rows(positions)

    @property
    def terms(self) -> PositionTerms:
        """(conc, dist, loc, log_nd, inv_sigma, det_offset), each (R, M) over this context's
        particles, rows as :meth:`position_index` gives them (see
        :func:`~dcee.planning.position_kernels.position_rows`). Read it after the last
        :meth:`position_index` call: new rows may move the buffers."""
        return self._pt.terms

    @property
    def conc(self) -> np.ndarray:
        """(R, M) concentrations of every particle at every cached position."""
        return self.terms.conc

    def readings(self, pos_idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Hypothesised readings (J', T) along one sequence of cached positions (T,) and the
        probability (J',) each stands for (summing to 1)."""
        if self._fresh:
            self._draw()
        if self.expectation == "stratified":
            z, prob = self._stratified_batch(np.asarray(pos_idx)[None])
            return z[0], prob[0]
        t_count = len(pos_idx)
        c = self.conc[pos_idx][:, self.indices].T  # (J, T)
        r = self.terms.dist[pos_idx][:, self.indices].T
        z = self.sensor.simulate_from(c, self.noise[:, :t_count], r)
        return z, np.full(self._n, 1.0 / self._n)

    def _sampled_readings(self, pos_idx: np.ndarray) -> np.ndarray:
        """(S, J, T) sampled hypothesised readings along (S, T) sequences of cached positions;
        the same as :meth:`readings` for each sequence (shared noise), in one NumPy pass."""
        t_count = pos_idx.shape[1]
        sensor = self.sensor
        if plain_gaussian(sensor):
            return gaussian_sampled_readings(self.conc, self.indices, pos_idx, self.noise, self._sp)
        c = self.conc[:, self.indices][pos_idx].transpose(0, 2, 1)  # (S, J, T)
        r = self.terms.dist[:, self.indices][pos_idx].transpose(0, 2, 1)
        return self.sensor.simulate_from(c, self.noise[None, :, :t_count], r)

    def _stratified_batch(self, pos_idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The stratified hypotheses of (S, T) sequences of cached positions at once: ((S, J', T)
        readings, (S, J') probabilities), those of a loop over the sequences bit for bit
        (:func:`~dcee.planning.stratified_kernels.stratified_hypotheses`)."""
        terms = self.terms
        return stratified_hypotheses(
            terms.log_nd, terms.conc, terms.dist, self.belief.weights, pos_idx, self.sensor,
            self.noise, self._offset, self._first_u, self._detect_u,
        )  # fmt: skip

    def stats(
        self,
        sequences: np.ndarray,
        moments: bool = True,
        kl: bool = True,
        location_cell: float | None = None,
    ) -> SequenceStats:
        """Statistics for (S, T, 3) candidate position sequences (T ≤ horizon).

        ``moments=False`` leaves mean and trace_cov NaN, ``kl=False`` leaves kl NaN: each
        saves work in the kernel when a planner's cost does not use it. ``location_cell`` (m)
        asks for location_kl over cubes of that side (NaN otherwise).
        """
        s_count, t_count, _ = sequences.shape
        j_count = self.n_hypotheses
        pos_idx = self.position_index(sequences.reshape(-1, 3)).reshape(s_count, t_count)
        if self.expectation == "sampled" and not self._fresh:
            readings = self._sampled_readings(pos_idx)  # every sequence at once
            probability = np.full((s_count, j_count), 1.0 / j_count)
        elif not self._fresh:
            readings, probability = self._stratified_batch(pos_idx)  # every sequence at once
        else:
            readings = np.empty((s_count, j_count, t_count))
            probability = np.empty((s_count, j_count))
            for s in range(s_count):
                readings[s], probability[s] = self.readings(pos_idx[s])
        tz, seq_of_task, inverse = unique_tasks(np.ascontiguousarray(readings))
        n_tasks = len(tz)
        tp = np.ascontiguousarray(pos_idx[seq_of_task])
        log_ev = np.empty(n_tasks)
        mean = np.empty((n_tasks, 3))
        trace = np.empty(n_tasks)
        kl_div = np.empty(n_tasks)
        predicted_posterior_stats(
            *self.terms[2:],
            self._source,
            self.belief.weights,
            # the moments' reference point; the other statistics do not read it
            self._center if moments else _NO_CENTER,
            tp,
            *self._transformed(tz),
            self._sp,
            log_ev,
            mean,
            trace,
            kl_div,
            moments,
            kl,
            self.precision,
        )
        loc_kl = np.full(n_tasks, np.nan)
        if location_cell is not None:
            tv, tfa, tout, _ = self._transformed(tz)
            location_kl(
                *self.terms[2:],
                self.belief.weights,
                *self._cells(location_cell),
                tp,
                np.ascontiguousarray(tv, dtype=np.float64),
                np.ascontiguousarray(tfa, dtype=np.float64),
                np.ascontiguousarray(tout, dtype=np.float64),
                self._sp,
                loc_kl,
            )
        return SequenceStats(
            readings,
            probability,
            log_ev[inverse],
            mean[inverse],
            trace[inverse],
            kl_div[inverse],
            loc_kl[inverse],
        )

    def _transformed(self, tz: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`~dcee.models.sensor.Sensor.transformed_readings` of task readings tz (Q, T);
        for a Gaussian sensor without false alarms or outliers compiled (the same values: v the
        reading or half the threshold, the other terms −inf and 0), without its dozen NumPy
        calls."""
        sensor = self.sensor
        if plain_gaussian(sensor) and sensor.false_alarm == 0:
            never = np.full_like(tz, -np.inf)
            return gaussian_transformed(tz, sensor.threshold), never, never, np.zeros_like(tz)
        return sensor.transformed_readings(tz)

    def _cells(self, cell: float) -> tuple[np.ndarray, ...]:
        """:func:`~dcee.planning.location_kl.location_cells` of this context's belief,
        computed once per cell size."""
        key = float(cell)
        if key not in self._cell_cache:
            self._cell_cache[key] = location_cells(self._source, self.belief.weights, key)
        return self._cell_cache[key]
