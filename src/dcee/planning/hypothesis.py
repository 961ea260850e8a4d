"""Planners that score candidate moves by hypothesised readings: cost separate from search.

A :class:`HypothesisPlanner` defines only its *loss*, a function of one hypothesis's predicted
posterior (S, J). The expectation over the next readings (sampled | stratified, see
:data:`dcee.planning.predicted.EXPECTATIONS`) and the search over move sequences (one step, or a
receding-horizon beam) are shared, so every loss gets every expectation and every horizon:
``infotaxis:horizon=2`` is multistage infotaxis with no code of its own.

Beam search (horizon H > 1), the documented approximation: at depth d the partial sequences are
ranked by their own d-stage cost and only the best ``beam_width`` are expanded by every
admissible move, so H = 2 evaluates 8 + 8·K sequences and H = 3 evaluates 8 + 2·8·K (K =
beam_width) instead of 64 or 512. Hypothesis j uses the same random numbers at every stage and
for every sequence (common random numbers), and identical reading sequences (e.g. all
non-detections) are evaluated once. First moves whose every continuation was pruned get cost
+inf.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import Any, ClassVar

import numpy as np

from dcee.errors import DceeInputError
from dcee.estimation.resampling import systematic_resample
from dcee.models.agent import GridAgent, travel_xy
from dcee.models.site import SiteMap
from dcee.planning.base import Belief, Planner, check_count
from dcee.planning.predicted import (
    PredictionContext,
    SequenceStats,
    check_hypothesis_options,
    check_precision,
)


class HypothesisPlanner(Planner):
    """Cost(U) = E_ẑ[loss(U, predicted posterior after ẑ)] over hypothesised readings.

    Options (all planners of this kind): ``n_hypotheses`` J per candidate sequence,
    ``expectation`` sampled | stratified, ``horizon`` H moves (1–3) and ``beam_width``; for
    ablations, ``noise`` shared | fresh (:data:`~dcee.planning.predicted.NOISE_SHARING`),
    ``readings`` model | noise-free | miss-free and ``subsample`` (predict with a systematic
    resample of that share of the particles, equally weighted; the authors' example uses 0.2);
    ``precision`` interpolated | double | single, how the one-reading predictions are summed
    (:data:`~dcee.planning.predicted.PRECISIONS`; the default is ``interpolated``, which only
    concerns predictions of one reading, a beam's first stage included: sequences of several
    readings are computed in double precision whatever the option; decisions measured against
    double's in docs/performance.md).
    """

    uses_hypotheses = True
    #: which optional statistics :meth:`loss` reads (see PredictionContext.stats)
    needs_moments: ClassVar[bool] = True
    needs_kl: ClassVar[bool] = True
    default_horizon: ClassVar[int] = 1
    default_expectation: ClassVar[str] = "sampled"
    #: side (m) of the location cubes of ``SequenceStats.location_kl``; None: not computed
    location_cell: float | None = None

    def __init__(
        self,
        n_hypotheses: int = 40,
        expectation: str | None = None,
        horizon: int | None = None,
        beam_width: int = 3,
        noise: str = "shared",
        readings: str = "model",
        subsample: float = 1.0,
        precision: str | None = None,
    ) -> None:
        expectation = self.default_expectation if expectation is None else expectation
        horizon = self.default_horizon if horizon is None else horizon
        if precision is None:
            # one-reading predictions (one-step planners, a beam's first stage) are interpolated
            # over the concentration where the sensor allows it (1e-8 of the exact sums,
            # decisions measured: docs/performance.md); sequences of several readings are
            # always computed exactly
            precision = "interpolated"
        n_hypotheses = check_count("hypotheses", n_hypotheses)
        beam_width = check_count("beam_width", beam_width)
        if horizon not in (1, 2, 3):
            raise DceeInputError("horizon", f"must be 1, 2 or 3, got {horizon}")
        check_hypothesis_options(expectation, noise, readings)
        check_precision(precision)
        self.precision = str(precision)
        if isinstance(subsample, bool) or not (
            isinstance(subsample, int | float) and 0 < subsample <= 1
        ):
            raise DceeInputError("subsample", f"must be a share in (0, 1], got {subsample!r}")
        self.noise = str(noise)
        self.readings = str(readings)
        self.subsample = float(subsample)
        self.n_hypotheses = int(n_hypotheses)
        self.expectation = str(expectation)
        self.horizon = int(horizon)
        self.beam_width = int(beam_width)

    def options(self) -> dict[str, Any]:
        return {
            "n_hypotheses": self.n_hypotheses,
            "expectation": self.expectation,
            "horizon": self.horizon,
            "beam_width": self.beam_width,
            "noise": self.noise,
            "readings": self.readings,
            "subsample": self.subsample,
            "precision": self.precision,
        }

    def bind_agent(self, agent: GridAgent) -> None:
        """Called with the agent before each decision's costs (a cost that depends on which
        moves the agent has, as ``dcee-cl``'s vertical reach does, reads it here)."""

    @abstractmethod
    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        """(S, J) loss of each hypothesis for (S, 3) final positions of S sequences."""

    def sequence_costs(
        self, sequences: np.ndarray, ctx: PredictionContext, belief: Belief
    ) -> np.ndarray:
        """(S,) expected loss of (S, T, 3) position sequences."""
        stats = ctx.stats(
            sequences,
            moments=self.needs_moments,
            kl=self.needs_kl,
            location_cell=self.location_cell,
        )
        return stats.expect(self.loss(sequences[:, -1], stats, belief))

    def context(
        self, belief: Belief, rng: np.random.Generator, stages: int
    ) -> tuple[Belief, PredictionContext]:
        """The belief the predictions use (its identical particles merged; a systematic
        resample of it with ``subsample`` < 1) and one decision's :class:`PredictionContext`
        for sequences of up to ``stages`` readings, drawing every random number from ``rng``."""
        if self.subsample < 1.0:
            n = max(1, round(self.subsample * len(belief.weights)))
            idx = systematic_resample(belief.weights, rng, n)
            belief = Belief(
                belief.theta[idx],
                np.full(n, 1.0 / n),
                belief.sensor,
                belief.plume,
                # a new particle set: no row carries over, the buffers do
                None if belief.cache is None else belief.cache.derived(),
                site=belief.site,
            )
        ctx = PredictionContext(
            belief,
            self.n_hypotheses,
            stages,
            rng,
            self.expectation,
            self.noise,
            self.readings,
            self.precision,
        )
        return ctx.belief, ctx

    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        self.bind_agent(agent)
        belief, ctx = self.context(belief, rng, self.horizon)
        seqs = candidates[:, None, :]
        cost = self.sequence_costs(seqs, ctx, belief)
        if self.horizon == 1:
            return cost, {}
        first = np.arange(len(candidates))
        evaluated = len(seqs)
        for _ in range(1, self.horizon):
            keep = np.argsort(cost, kind="stable")[: self.beam_width]
            new_seqs: list[np.ndarray] = []
            new_first: list[int] = []
            for s in keep:
                nxt, _ = agent.candidates(seqs[s, -1])
                for p in nxt:
                    new_seqs.append(np.vstack([seqs[s], p[None, :]]))
                    new_first.append(first[s])
            seqs = np.array(new_seqs)
            first = np.array(new_first)
            cost = self.sequence_costs(seqs, ctx, belief)
            evaluated += len(seqs)
        best = np.full(len(candidates), np.inf)
        np.minimum.at(best, first, cost)
        return best, {"sequences_evaluated": evaluated}


def squared_distance(
    final_positions: np.ndarray, stats: SequenceStats, site: SiteMap | None = None
) -> np.ndarray:
    """(S, J) ‖p − s̄'_j‖² for (S, 3) final positions; with a ``site``, the horizontal part is
    the travel distance around its obstacles and no-go zones (:func:`travel_xy`)."""
    d = final_positions[:, None, :] - stats.mean
    if site is None or not site.blocked.any():
        return np.einsum("sjk,sjk->sj", d, d)
    return horizontal_distance(final_positions, stats.mean, site) ** 2 + d[..., 2] ** 2


def horizontal_distance(
    final_positions: np.ndarray, points: np.ndarray, site: SiteMap | None
) -> np.ndarray:
    """(S, J) horizontal travel distance from each of (S, 3) positions to its (S, J, 3)
    points: straight without a site, around its blocked cells with one."""
    if site is None or not site.blocked.any():
        d = points - final_positions[:, None, :]
        return np.hypot(d[..., 0], d[..., 1])
    return np.stack([travel_xy(site, p, q) for p, q in zip(final_positions, points, strict=True)])
