"""Going where readings become informative when no move within reach is.

The planners look one move ahead (the tree search a few). A belief that is wide and far away
(a release the readings have not yet ruled out, somewhere in the area) predicts the same reading,
"nothing", at every candidate: the costs tie and the robot hovers or paces where it is
(measured: on two releases, ``dcee-cl`` spent 400 s within 15 m once the first release was
localised while a second was still plausible). The stall guard only sees pacing within one step.

The exploration guard asks, before a decision, how uncertain the next reading's outcome is,
detection or not, under the belief: the binary entropy H(P_det(p)) with P_det(p) = Σᵢ wᵢ
P(detection | Cᵢ(p)) — the part of a reading's information that does not depend on its size,
and the one that is zero wherever every hypothesis agrees. It compares the best candidate move
with a coarse grid over the area at the robot's altitude. When the best move's entropy is below
``share`` of the grid's best, the robot is offered only the moves that bring it closer to the
nearest grid point whose entropy is at least ``share`` of the best (:class:`ApproachingAgent`);
the planner chooses among them as usual.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from dcee.models.agent import GridAgent, travel_xy
from dcee.planning.base import Belief

DEFAULT_EXPLORE_SHARE = 0.5
"""The guard acts when the best move's outcome entropy is below this share of the area's best,
and heads for the nearest grid point at or above it."""

THINNED = 1000
"""Particles the entropies are computed over (a systematic subsample): an outcome probability
to about ±0.02, finer than the guard's comparison (a factor 2) needs, at a tenth of the cost."""

GRID_CELLS = 12
"""Grid points per side of the area (a 50 m area: about 4 m apart)."""


def detection_entropy(belief: Belief, points: np.ndarray) -> np.ndarray:
    """(M,) binary entropy (nats) of "a detection or not" at points (M, 3) under the belief:
    P_det(p) = 1 − Σᵢ wᵢ P(miss | Cᵢ(p)) / P(miss | 0) (the miss probability relative to
    no gas: false alarms and outliers alike in every hypothesis)."""
    theta, weights = _thinned(belief)
    conc = belief.plume.concentration(theta, points)  # (n, M)
    sensor = belief.sensor
    base = float(sensor.log_likelihood(0.0, 0.0, np.inf))
    far = np.linalg.norm(points[None, :, :] - theta[:, None, :3], axis=2)
    miss = np.exp(np.minimum(sensor.log_likelihood(0.0, conc, far) - base, 0.0))
    p = np.clip(1.0 - weights @ miss, 1e-12, 1.0 - 1e-12)
    return -(p * np.log(p) + (1.0 - p) * np.log1p(-p))


def _thinned(belief: Belief, n: int = THINNED) -> tuple[np.ndarray, np.ndarray]:
    """At most ``n`` particles of the belief with their weights: systematic resampling at the
    fixed offset 1/2 (no random draw, so the guard moves no generator), weights equal."""
    if len(belief.weights) <= n:
        return belief.theta, belief.weights
    edges = np.cumsum(belief.weights)
    idx = np.searchsorted(edges, (np.arange(n) + 0.5) / n * edges[-1])
    idx = np.minimum(idx, len(edges) - 1)
    return belief.theta[idx], np.full(n, 1.0 / n)


def area_grid(agent: GridAgent, altitude: float, cells: int = GRID_CELLS) -> np.ndarray:
    """(cells², 3) grid points over the agent's area (cell centres) at ``altitude`` m."""
    lo, hi = np.asarray(agent.volume.low), np.asarray(agent.volume.high)
    xs = lo[0] + (np.arange(cells) + 0.5) * (hi[0] - lo[0]) / cells
    ys = lo[1] + (np.arange(cells) + 0.5) * (hi[1] - lo[1]) / cells
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, altitude)])


def exploration_goal(
    belief: Belief,
    position: np.ndarray,
    agent: GridAgent,
    share: float = DEFAULT_EXPLORE_SHARE,
) -> np.ndarray | None:
    """The grid point (3,) m to head for, or None when a move within reach is informative
    enough (see the module doc)."""
    cands, _ = agent.candidates(position)
    if len(cands) == 0:
        return None
    local = float(detection_entropy(belief, cands).max())
    if local >= share * math.log(2.0):  # no grid point can beat ln 2: the move is informative
        return None
    grid = area_grid(agent, float(position[2]))
    if agent.site is not None:  # points the robot can reach, by travel distance round walls
        grid = grid[agent.site.reachable(position, grid)]
        if len(grid) == 0:
            return None
    h_grid = detection_entropy(belief, grid)
    best = float(h_grid.max())
    if best <= 0.0 or local >= share * best:
        return None
    good = grid[h_grid >= share * best]
    d = travel_xy(agent.site, position, good)
    return good[int(np.argmin(d))]


class ApproachingAgent:
    """An agent's move set without the moves that fail to bring it closer (horizontally) to
    ``goal`` (3,) m by at least half a step; every other attribute is the wrapped agent's.
    Where no move does, every move (the planner decides)."""

    def __init__(self, agent: GridAgent, goal: np.ndarray, start: np.ndarray) -> None:
        self.agent = agent
        self.goal = np.asarray(goal, dtype=np.float64)
        self.start = np.asarray(start, dtype=np.float64)

    def candidates(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        cands, headings = self.agent.candidates(position)
        if not np.allclose(position, self.start):  # later moves of a look-ahead: unrestricted
            return cands, headings
        now = math.hypot(*(self.start[:2] - self.goal[:2]))
        closer = np.hypot(*(cands[:, :2] - self.goal[:2]).T) < now - 0.5 * self.agent.step
        return (cands[closer], headings[closer]) if closer.any() else (cands, headings)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.agent, name)
