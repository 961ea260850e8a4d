"""Multistage DCEE (the paper's multistage cost) with a receding horizon.

J(U) = E[‖p_{k+H|k} − s̄_{k+H|k}‖² + tr P_{k+H|k}] over hypothesised readings at every stage of the
sequence U = (u_k, …, u_{k+H−1}); the first move of the best sequence is applied.

Tractability (the approximation, documented): the 8^H sequences are searched by a beam. At
depth d the partial sequences are ranked by their own d-stage DCEE cost and only the best
``beam_width`` are expanded by every admissible move, so H = 2 evaluates 8 + 8·K sequences and
H = 3 evaluates 8 + 2·8·K (K = beam_width) instead of 64 or 512. Hypothesis j uses the same
hypothesised source Θ_j and the same standard noise at every stage and for every sequence
(common random numbers), and identical reading sequences (e.g. all non-detections) are evaluated
once. Candidates whose first move was pruned get cost +inf.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.agent import GridAgent
from dcee.planning.base import Belief, Planner, register
from dcee.planning.predicted import PredictionContext, dcee_cost


@register("dcee-ms")
class MultistageDCEEPlanner(Planner):
    uses_hypotheses = True

    def __init__(self, horizon: int = 2, beam_width: int = 3, n_hypotheses: int = 40) -> None:
        if horizon not in (1, 2, 3):
            raise DceeInputError("horizon", f"must be 1, 2 or 3, got {horizon}")
        if beam_width < 1:
            raise DceeInputError("beam_width", f"must be >= 1, got {beam_width}")
        if n_hypotheses < 1:
            raise DceeInputError("hypotheses", f"must be >= 1, got {n_hypotheses}")
        self.horizon = int(horizon)
        self.beam_width = int(beam_width)
        self.n_hypotheses = int(n_hypotheses)

    def options(self) -> dict[str, Any]:
        return {
            "horizon": self.horizon,
            "beam_width": self.beam_width,
            "n_hypotheses": self.n_hypotheses,
        }

    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        ctx = PredictionContext(belief, self.n_hypotheses, self.horizon, rng)
        seqs = candidates[:, None, :]
        first = np.arange(len(candidates))
        cost = dcee_cost(seqs[:, -1], ctx.stats(seqs, kl=False))
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
            cost = dcee_cost(seqs[:, -1], ctx.stats(seqs, kl=False))
            evaluated += len(seqs)
        best = np.full(len(candidates), np.inf)
        np.minimum.at(best, first, cost)
        return best, {"sequences_evaluated": evaluated}
