"""Closed-loop (Bellman) DCEE: the value of what the next reading lets the agent do.

Theorem-1 DCEE charges ‖p_{k+1} − s̄'‖² as if the agent had to stop at p_{k+1} whatever it
reads there. With hypotheses drawn from the predictive distribution, E[s̄'] = s̄ and
E[‖p − s̄'‖² + tr P'] = ‖p − s̄‖² + tr P (law of total variance): the open-loop cost is the MPC
cost plus a constant, and the planner cannot value information (docs/dual-control.md).

Closed loop with reach R: after the hypothesised reading ẑ the agent may still move anywhere
within R metres (horizontally) of p_{k+1} before the distance to the believed source is charged,

    J(u) = E_ẑ[ dist(s̄'(ẑ), disk(p_{k+1}, R))² + tr P'(ẑ) ],

with dist² = max(0, ‖s̄'_xy − p_xy‖ − R)² + max(0, |s̄'_z − p_z| − R_z)². Far from the mean this
is MPC; within R of it the distance term vanishes and what is left is the expected variance
reduction, which points at the informative move: the dual-control term the open loop cancels.
R must exceed one step (otherwise the reading can never change what the agent does next) and
not be so large that the MPC pull is lost; the default was chosen by measurement
(docs/dual-control.md). A fixed R cannot suit a belief 20 m wide and one 1 m wide:
R = max(``reach``, ``spread_reach`` · σ_xy) (default 2 σ_xy) keeps a wide belief's every move
free of the distance charge, where a fixed 8 m made the agent pace on the disk's edge
(docs/held-out.md).

The vertical reach R_z: an agent at a fixed altitude (the paper's) cannot act on what a reading
tells about the source height, so R_z = 0 and the height error is charged in full. An agent that
climbs (``agent.climb`` > 0) can: R_z = ``vertical_reach`` · R · climb / step, as many vertical
moves as R allows horizontal ones (default ``vertical_reach`` 1). With R_z = 0 and a climbing
agent, E[(s̄'_z − p_z)²] + E[P'_zz] = (s̄_z − p_z)² + P_zz whatever the reading: the height term
cancels the height information, and the planner never paid for a reading below the believed
source height (docs/turbulent.md: 58 % of its readings at 3 m on the held-out puff study).

The uncertainty term: tr P'(ẑ) counts only what a reading tells about the source *location*.
With the wind and dispersion unknown, readings that resolve them narrow the location later, and
a location-only term does not value them (in the full-unknown study ``dcee-cl`` then reached
1 m no sooner than infotaxis). ``info_share`` a replaces it by
(1 − a) tr P'(ẑ) + a tr P e^{−KL(ẑ)}, the second part being the location variance that the same
information about all parameters would leave (Gaussian small-step approximation); the default
a = 0.5 was chosen by measurement (docs/dual-control.md §6c).

The expectation defaults to ``stratified``: at a stall detections are rare (0.1–1 % per
candidate), so sampled hypotheses mostly all read "nothing" and the variance-reduction term
is noise.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.agent import GridAgent
from dcee.planning.base import Belief, check_count, register
from dcee.planning.hypothesis import HypothesisPlanner, horizontal_distance
from dcee.planning.predicted import PredictionContext, SequenceStats

DEFAULT_REACH = 8.0
"""m: four 2 m steps of the paper's agent; chosen by measurement (docs/dual-control.md)."""

DEFAULT_SPREAD_REACH = 2.0
"""R = max(``reach``, 2 σ_xy) while the belief is wide. With 0 (the default before issue 28) a
belief spread over the area but centred near the agent left no candidate charged by distance and
none informative, and the agent paced on the reach disk's edge: on the 40 tuning configurations
``random:1``-``random:40`` (wind known, 10,000 particles, seed 0) 26/40 acquired, 15 searches
stalled > 60 s. spread_reach 1: 40/40, one 74 s stall, median time to 1 m 97 s; 2: 40/40, no
stall > 42 s, 111 s (infotaxis 40/40, 124 s). 2 kept: no stall (docs/dual-control.md §7)."""

DEFAULT_VERTICAL_REACH = 1.0
"""R_z = 1 · R · climb / step: the same number of moves vertically as horizontally. Chosen on the
turbulent tuning range random:13-40 against 0 (docs/turbulent.md); no effect at a fixed
altitude."""

DEFAULT_INFO_SHARE = 0.5
"""Share of the uncertainty term measured by information about every parameter rather than by
the location variance (:meth:`ClosedLoopDCEEPlanner.uncertainty`). 0.5 and 1 were measured on
21 paired full-unknown searches (median time to RMSE < 1 m 131 s and 143 s against 163 s with
0); 0.5 kept (docs/dual-control.md §6c)."""


@register("dcee-cl")
class ClosedLoopDCEEPlanner(HypothesisPlanner):
    """Closed-loop DCEE with reach R m (``reach``), an uncertainty term that values every
    parameter (``info_share``) and the stratified expectation by default."""

    summary = "closed-loop DCEE: free moves within reach R after the next reading"

    needs_kl = False
    default_expectation = "stratified"
    # three moves in a turbulent plume (search.lookahead, chosen on filament and puffs)
    follows_lookahead = True

    def __init__(
        self,
        reach: float = DEFAULT_REACH,
        spread_reach: float = DEFAULT_SPREAD_REACH,
        info_share: float = DEFAULT_INFO_SHARE,
        vertical_reach: float = DEFAULT_VERTICAL_REACH,
        **options: Any,
    ) -> None:
        super().__init__(**options)
        for name, value, high in (
            ("reach", reach, 1e3),
            ("spread_reach", spread_reach, 10.0),
            ("info_share", info_share, 1.0),
            ("vertical_reach", vertical_reach, 10.0),
        ):
            if isinstance(value, bool) or not (
                isinstance(value, int | float) and math.isfinite(value) and 0 <= value <= high
            ):
                raise DceeInputError(name, f"must be a number in [0, {high:g}], got {value!r}")
        self.reach = float(reach)
        self.spread_reach = float(spread_reach)
        self.info_share = float(info_share)
        self.vertical_reach = float(vertical_reach)
        # climb / step of the agent the current decision is for (set by bind_agent)
        self._climb_per_step = 0.0
        # the KL divergence costs one more accumulation in the kernel: only when it is used
        self.needs_kl = self.info_share > 0.0

    def options(self) -> dict[str, Any]:
        return {
            "reach": self.reach,
            "spread_reach": self.spread_reach,
            "info_share": self.info_share,
            "vertical_reach": self.vertical_reach,
            **super().options(),
        }

    def effective_reach(self, belief: Belief) -> float:
        """R = max(``reach``, ``spread_reach`` · σ_xy) m, σ_xy the belief's horizontal spread
        √(var x + var y): with ``spread_reach`` > 0 a wide belief makes every move within its
        spread free of the distance charge (pure variance reduction), and the MPC pull returns
        as the belief narrows (an option under study, docs/dual-control.md)."""
        if self.spread_reach == 0.0:
            return self.reach
        spread = math.sqrt(belief.location_variance(2))
        return max(self.reach, self.spread_reach * spread)

    def bind_agent(self, agent: GridAgent) -> None:
        self._climb_per_step = agent.climb / agent.step

    def effective_vertical_reach(self, reach: float) -> float:
        """R_z = ``vertical_reach`` · R · climb / step m for the horizontal reach R = ``reach``
        (:meth:`effective_reach`; 0 at a fixed altitude)."""
        return self.vertical_reach * reach * self._climb_per_step

    def uncertainty(self, stats: SequenceStats, belief: Belief) -> np.ndarray:
        """(S, J) the uncertainty left after each hypothesised reading, in m²:
        (1 − a) tr P'_j + a tr P e^{−KL_j}, a = ``info_share``.

        tr P'_j counts only what the reading tells about the source location. tr P e^{−KL_j}
        is the location variance that the same amount of information, KL_j nats about all the
        parameters (wind and dispersion included), would leave if it were information about
        the 2-D location of a Gaussian belief (its variance shrinks by e^{−I} per I nats). It
        values readings that resolve the environment, which later narrow the location."""
        if self.info_share == 0.0:
            return stats.trace_cov
        a = self.info_share
        return (1.0 - a) * stats.trace_cov + a * belief.location_variance() * np.exp(-stats.kl)

    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        d = stats.mean - final_positions[:, None, :]
        horizontal = horizontal_distance(final_positions, stats.mean, belief.site)
        reach = self.effective_reach(belief)
        beyond = np.maximum(horizontal - reach, 0.0)
        above = np.maximum(np.abs(d[..., 2]) - self.effective_vertical_reach(reach), 0.0)
        return beyond * beyond + above * above + self.uncertainty(stats, belief)


@register("dcee-cl-tree")
class ScenarioTreeDCEEPlanner(ClosedLoopDCEEPlanner):
    """Closed-loop DCEE over a two-stage scenario tree: the second move is chosen after the
    first hypothesised reading, then the reach-R cost is charged,

        J(u1) = E_ẑ1[ min_{u2} E_ẑ2|ẑ1[ dist(s̄″, disk(p2, R))² + tr P″ ] ].

    Each distinct first reading (J + 1 stratified) opens a branch whose belief is the predicted
    posterior after it; ``branch_hypotheses`` readings per second move are drawn from that
    branch's own predictive distribution (stratified, common random numbers across branches).
    Cost: 8 × (J + 1) branches × 8 moves × (J2 + 1) readings: far dearer than ``dcee-cl``
    (docs/dual-control.md measures whether the exact second step adds anything)."""

    summary = "closed-loop DCEE over a two-move scenario tree (second move after the reading)"
    follows_lookahead = False  # its own two stages

    def __init__(self, branch_hypotheses: int = 10, **options: Any) -> None:
        super().__init__(**options)
        if self.horizon != 1:
            raise DceeInputError("horizon", "the scenario tree has its own two stages: use 1")
        self.branch_hypotheses = check_count("branch_hypotheses", branch_hypotheses)

    def options(self) -> dict[str, Any]:
        return {**super().options(), "branch_hypotheses": self.branch_hypotheses}

    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        self.bind_agent(agent)
        ctx = PredictionContext(
            belief,
            self.n_hypotheses,
            1,
            rng,
            self.expectation,
            self.noise,
            self.readings,
            self.precision,
        )
        first = ctx.stats(candidates[:, None, :], moments=False, kl=False)
        seconds = [agent.candidates(p)[0] for p in candidates]
        first_idx = ctx.position_index(candidates)
        ctx.position_index(np.concatenate(seconds))  # every position cached before branching
        conc, dist = ctx.terms.conc, ctx.terms.dist
        branch_seed = int(rng.integers(2**63))
        with np.errstate(divide="ignore"):
            log_w = np.log(ctx.belief.weights)  # over the context's (merged) particles
        cost = np.zeros(len(candidates))
        branches = 0
        for m, p_idx in enumerate(first_idx):
            readings, inverse = np.unique(first.readings[m, :, 0], return_inverse=True)
            prob = np.bincount(inverse.ravel(), weights=first.probability[m])
            for z1, pz in zip(readings, prob, strict=True):
                if pz <= 0.0:
                    continue
                lw = log_w + belief.sensor.log_likelihood(z1, conc[p_idx], dist[p_idx])
                w = np.exp(lw - lw.max())
                w /= w.sum()
                branch = ctx.branch(w, self.branch_hypotheses, np.random.default_rng(branch_seed))
                seqs = seconds[m][:, None, :]
                cost[m] += pz * self.sequence_costs(seqs, branch, branch.belief).min()
                branches += 1
        return cost, {"branches": branches}
