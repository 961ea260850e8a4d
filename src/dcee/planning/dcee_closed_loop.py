"""Closed-loop (Bellman) DCEE: the value of what the next reading lets the agent do.

Theorem-1 DCEE charges ‖p_{k+1} − s̄'‖² as if the agent had to stop at p_{k+1} whatever it
reads there. With hypotheses drawn from the predictive distribution, E[s̄'] = s̄ and
E[‖p − s̄'‖² + tr P'] = ‖p − s̄‖² + tr P (law of total variance): the open-loop cost is the MPC
cost plus a constant, and the planner cannot value information (docs/dual-control.md).

Closed loop with reach R: after the hypothesised reading ẑ the agent may still move anywhere
within R metres (horizontally) of p_{k+1} before the distance to the believed source is charged,

    J(u) = E_ẑ[ dist(s̄'(ẑ), disk(p_{k+1}, R))² + tr P'(ẑ) ],

with dist² = max(0, ‖s̄'_xy − p_xy‖ − R)² + (s̄'_z − p_z)². Far from the mean this is MPC; within R
of it the distance term vanishes and what is left is the expected variance reduction, which
points at the informative move: the dual-control term the open loop cancels. R must exceed one
step (otherwise the reading can never change what the agent does next) and not be so large that
the MPC pull is lost; the default was chosen by measurement (docs/dual-control.md).

The expectation defaults to ``stratified``: at a stall detections are rare (0.1–1 % per
candidate), so sampled hypotheses mostly all read "nothing" and the variance-reduction term
is noise.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.planning.base import Belief, register
from dcee.planning.hypothesis import HypothesisPlanner
from dcee.planning.predicted import SequenceStats

DEFAULT_REACH = 8.0
"""m: four 2 m steps of the paper's agent; chosen by measurement (docs/dual-control.md)."""


@register("dcee-cl")
class ClosedLoopDCEEPlanner(HypothesisPlanner):
    """Closed-loop DCEE with reach R m (``reach``) and the stratified expectation by default."""

    summary = "closed-loop DCEE: free moves within reach R after the next reading"

    needs_kl = False
    default_expectation = "stratified"

    def __init__(self, reach: float = DEFAULT_REACH, **options: Any) -> None:
        super().__init__(**options)
        if isinstance(reach, bool) or not (
            isinstance(reach, int | float) and math.isfinite(reach) and 0 <= reach <= 1e3
        ):
            raise DceeInputError("reach", f"must be a number of m in [0, 1000], got {reach!r}")
        self.reach = float(reach)

    def options(self) -> dict[str, Any]:
        return {"reach": self.reach, **super().options()}

    def loss(self, final_positions: np.ndarray, stats: SequenceStats, belief: Belief) -> np.ndarray:
        d = stats.mean - final_positions[:, None, :]
        horizontal = np.hypot(d[..., 0], d[..., 1])
        beyond = np.maximum(horizontal - self.reach, 0.0)
        return beyond * beyond + d[..., 2] * d[..., 2] + stats.trace_cov
