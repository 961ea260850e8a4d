"""Going where readings become informative when no move within reach is.

The planners look one move ahead (the tree search a few). A belief that is wide and far away
(a release the readings have not yet ruled out, somewhere in the area) predicts the same reading,
"nothing", at every candidate: the costs tie and the robot hovers or paces where it is
(measured: on two releases, ``dcee-cl`` spent 400 s within 15 m once the first release was
localised while a second was still plausible). The stall guard only sees pacing within one step.

The exploration guard asks, before a decision, how much the next reading's outcome, detection
or not, would tell about the hypotheses: the mutual information between the outcome and the
hypothesis under the joint belief (every release's gas; :func:`detection_information`) — the
part of a reading's information that does not depend on its size, zero wherever every
hypothesis predicts the same. It compares the best candidate move with a coarse grid over the
area at the robot's altitude. When the best move's information is below ``share`` of the
grid's best, the robot is offered only the moves that bring it closer to the nearest grid point
with at least ``share`` of the best (:class:`ApproachingAgent`); the planner chooses among them
as usual.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from dcee.estimation.base import Estimator
from dcee.estimation.multi_source_kernels import source_rows
from dcee.models.agent import GridAgent, travel_xy
from dcee.models.plume import IsotropicPlume
from dcee.models.plume_kernels import concentration_distance_grid, plume_from_terms
from dcee.models.sensor import Sensor
from dcee.models.sensor_kernels import SensorParams, log_likelihood, log_missed
from dcee.numeric import exp_scalar, log_scalar, read_only_view, vlog1m, vndtr_upper
from dcee.planning.position_kernels import N_PLUME_CONSTANTS, plume_constants, vectorised_case

DEFAULT_EXPLORE_SHARE = 0.5
"""The guard acts when the best move's information is below this share of the area's best,
and heads for the nearest grid point at or above it."""

THINNED = 1000
"""Particles the information is computed over (a systematic subsample): an outcome probability
to about ±0.02, finer than the guard's comparison (a factor 2) needs, at a tenth of the cost of
10,000."""

GRID_CELLS = 12
"""Grid points per side of the area (a 50 m area: about 4 m apart)."""


def detection_information(
    theta: np.ndarray,
    weights: np.ndarray,
    sensor: Sensor,
    plume: IsotropicPlume,
    points: np.ndarray,
) -> np.ndarray:
    """(M,) mutual information (nats) between "a detection or not" at points (M, 3) and the
    hypothesis, for particles ``theta`` (N, 8 + 4 (K − 1)) with normalised ``weights`` (N,):
    I = H(Σᵢ wᵢ Pᵢ) − Σᵢ wᵢ H(Pᵢ), Pᵢ = 1 − P(miss | Cᵢ(p)) / P(miss | 0) the detection
    probability hypothesis i predicts (Cᵢ the sum of its releases' plumes; false alarms and
    outliers alike in every hypothesis). Zero where every hypothesis predicts the same, however
    noisy the sensor (a bare outcome entropy is not: with Pd = 0.7 a plume's core is a coin).

    The paper's sensor and plume (Gaussian family, constant Pd < 1; no meander, backflow or
    area release; decay 1) take one vectorised kernel (:func:`_information_rows`); every other
    case, and the tests' reference, :func:`detection_information_reference`."""
    theta, weights = _thinned(theta, weights)
    sp = sensor.params
    if not isinstance(plume, IsotropicPlume) or not vectorised_case(sp, *plume.shape):
        return detection_information_reference(theta, weights, sensor, plume, points)
    points = np.ascontiguousarray(points, dtype=np.float64)
    blocks = source_rows(theta)
    constants = np.empty((len(blocks), N_PLUME_CONSTANTS, len(theta)))
    for k, rows in enumerate(blocks):
        plume_constants(np.ascontiguousarray(rows), constants[k])
    p_each = np.empty((len(points), len(theta)))
    h_each = np.empty_like(p_each)
    _information_rows(constants, read_only_view(points), plume.min_distance, sp, p_each, h_each)
    p_mean = np.clip(p_each @ weights, 1e-12, 1.0 - 1e-12)
    return _entropy(p_mean) - h_each @ weights


def detection_information_reference(
    theta: np.ndarray,
    weights: np.ndarray,
    sensor: Sensor,
    plume: IsotropicPlume,
    points: np.ndarray,
) -> np.ndarray:
    """:func:`detection_information` with the general scalar formulas (libm, any sensor or
    plume): each release's plume on the grid, summed, then the relative miss and entropies.
    (Thinning particles already thinned leaves them as they are.)"""
    theta, weights = _thinned(theta, weights)
    points = np.ascontiguousarray(points, dtype=np.float64)
    conc = np.zeros((len(points), len(theta)))  # (M, n): summed over the releases
    near = np.full_like(conc, np.inf)  # the nearest release's clamped distance
    c, r = np.empty_like(conc), np.empty_like(conc)
    for rows in source_rows(theta):
        grid = np.ascontiguousarray(rows)
        if isinstance(plume, IsotropicPlume):
            concentration_distance_grid(
                read_only_view(grid), read_only_view(points), plume.min_distance, *plume.shape, c, r
            )
        else:  # a plume that predicts with its own method (the wall-aware one)
            conc_t, dist_t = plume.concentration_distance(grid, points)
            c[:], r[:] = conc_t.T, dist_t.T
        conc += c
        np.minimum(near, r, out=near)
    miss = np.empty_like(conc)
    _relative_miss(conc, near, sensor.params, miss)
    p_each = np.clip(1.0 - miss, 1e-12, 1.0 - 1e-12)
    p_mean = np.clip(p_each @ weights, 1e-12, 1.0 - 1e-12)
    return _entropy(p_mean) - _entropy(p_each) @ weights


@njit(cache=True, fastmath={"contract"}, error_model="numpy")
def _information_rows(
    constants: np.ndarray,
    points: np.ndarray,
    rmin: float,
    sp: SensorParams,
    p_each: np.ndarray,
    h_each: np.ndarray,
) -> None:
    """p_each[m, i] = hypothesis i's detection probability at points[m] relative to none
    (clipped to [1e-12, 1 − 1e-12]) and h_each[m, i] its outcome entropy (nats), for the
    paper's sensor and plume: constants (K, 10, n) the :func:`plume_constants` of each
    release. Loops without branches (selects only) over particles, so that LLVM vectorises
    them with the ``exp``, ``log`` and ``erfc`` of :mod:`dcee.numeric` (the scalar libm form,
    :func:`detection_information_reference`, took two thirds of a count-unknown decision)."""
    n = constants.shape[2]
    conc = np.empty(n)
    base = log_missed(0.0, np.inf, sp)
    for m in range(points.shape[0]):
        px, py, pz = points[m, 0], points[m, 1], points[m, 2]
        conc[:] = 0.0
        for k in range(constants.shape[0]):
            for j in range(n):
                i = np.uint64(j)  # unsigned: no wraparound check to keep LLVM from vectorising
                c, _ = plume_from_terms(
                    constants[k, 0, i],
                    constants[k, 1, i],
                    constants[k, 2, i],
                    constants[k, 3, i],
                    constants[k, 4, i],
                    constants[k, 5, i],
                    constants[k, 6, i],
                    px,
                    py,
                    pz,
                    rmin,
                )
                conc[i] += c
        for j in range(n):
            i = np.uint64(j)
            c = conc[i]
            missed = vlog1m(
                sp.pd * vndtr_upper((sp.v_threshold - c) / (sp.sigma_frac * c + sp.sigma_min))
            )
            log_miss = (sp.lin0 + sp.lin1 * c if c < sp.c_lin else missed) - base
            p = min(max(1.0 - exp_scalar(min(log_miss, 0.0)), 1e-12), 1.0 - 1e-12)
            p_each[m, i] = p
            h_each[m, i] = -(p * log_scalar(p) + (1.0 - p) * vlog1m(p))


@njit(cache=True)
def _relative_miss(conc: np.ndarray, dist: np.ndarray, sp: SensorParams, out: np.ndarray) -> None:
    """out = min(1, P(no detection | C, r) / P(no detection | 0)) elementwise (compiled: the
    NumPy form took most of a decision with several releases)."""
    base = log_likelihood(0.0, 0.0, np.inf, sp)
    for i in range(conc.shape[0]):
        for j in range(conc.shape[1]):
            out[i, j] = math.exp(min(log_likelihood(0.0, conc[i, j], dist[i, j], sp) - base, 0.0))


def _entropy(p: np.ndarray) -> np.ndarray:
    return -(p * np.log(p) + (1.0 - p) * np.log1p(-p))


def _thinned(
    theta: np.ndarray, weights: np.ndarray, n: int = THINNED
) -> tuple[np.ndarray, np.ndarray]:
    """At most ``n`` particles with their weights: systematic resampling at the fixed offset
    1/2 (no random draw, so the guard moves no generator), weights equal."""
    if len(weights) <= n:
        return theta, weights
    edges = np.cumsum(weights)
    idx = np.searchsorted(edges, (np.arange(n) + 0.5) / n * edges[-1])
    idx = np.minimum(idx, len(edges) - 1)
    return theta[idx], np.full(n, 1.0 / n)


def reachable_points(agent: GridAgent, position: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The rows of ``points`` (K, 3) m a robot at ``position`` (3,) m can go to: on a site, free
    cells (not blocked, not unknown) at a finite travel distance round the walls; all of them
    without a site. A point inside a building counts as reachable to the travel distance (a
    hypothesised source there is reached at its nearest face), but a goal there is not: the
    way back from it is blocked, so a guard steering towards it measured every move as
    infinitely far and steered nowhere (``site:block``, mpc, seed 0: 155 s in one region)."""
    site = agent.site
    if site is None or len(points) == 0:
        return points
    points = points[~site.is_blocked(points)]
    return points[site.reachable(position, points)] if len(points) else points


def area_grid(agent: GridAgent, altitude: float, cells: int = GRID_CELLS) -> np.ndarray:
    """(cells², 3) grid points over the agent's area (cell centres) at ``altitude`` m."""
    lo, hi = np.asarray(agent.volume.low), np.asarray(agent.volume.high)
    xs = lo[0] + (np.arange(cells) + 0.5) * (hi[0] - lo[0]) / cells
    ys = lo[1] + (np.arange(cells) + 0.5) * (hi[1] - lo[1]) / cells
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, altitude)])


def joint_belief(estimator: Estimator) -> tuple[np.ndarray, np.ndarray]:
    """The particles and weights the guards' information is about: the estimator's joint belief
    (a count bank's target count, every release's gas) or its particles."""
    joint = getattr(estimator, "joint_particles", None)
    return joint() if joint is not None else (estimator.theta, estimator.weights)


def exploration_goal(
    estimator: Estimator,
    position: np.ndarray,
    agent: GridAgent,
    share: float = DEFAULT_EXPLORE_SHARE,
) -> np.ndarray | None:
    """The grid point (3,) m to head for, or None when a move within reach is informative
    enough (see the module doc). The information is the estimator's joint belief's
    (:func:`detection_information`; a count bank's target count, every release's gas)."""
    cands, _ = agent.candidates(position)
    if len(cands) == 0:
        return None
    theta, weights = joint_belief(estimator)

    def info(points: np.ndarray) -> np.ndarray:
        return detection_information(theta, weights, estimator.sensor, estimator.plume, points)

    local = float(info(cands).max())
    if local >= share * math.log(2.0):  # no grid point can beat ln 2: the move is informative
        return None
    grid = reachable_points(agent, position, area_grid(agent, float(position[2])))
    if len(grid) == 0:
        return None
    h_grid = info(grid)
    best = float(h_grid.max())
    if best <= 0.0 or local >= share * best:
        return None
    good = grid[h_grid >= share * best]
    d = travel_xy(agent.site, position, good)
    return good[int(np.argmin(d))]


class RestrictedAgent:
    """An agent whose next move from ``start`` (3,) m is restricted to those :meth:`allowed`
    keeps (every move where it keeps none); later moves of a look-ahead are not restricted.
    Every other attribute is the wrapped agent's. What the searcher's guards hand a planner."""

    def __init__(self, agent: GridAgent, target: np.ndarray, start: np.ndarray) -> None:
        self.agent = agent
        self.target = np.asarray(target, dtype=np.float64)
        self.start = np.asarray(start, dtype=np.float64)

    def allowed(self, cands: np.ndarray) -> np.ndarray:
        """(M,) bool: which of the candidate next positions (M, 3) m are offered."""
        raise NotImplementedError

    def candidates(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        cands, headings = self.agent.candidates(position)
        if not np.allclose(position, self.start):  # later moves of a look-ahead: unrestricted
            return cands, headings
        keep = self.allowed(cands)
        return (cands[keep], headings[keep]) if keep.any() else (cands, headings)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.agent, name)


class ApproachingAgent(RestrictedAgent):
    """The moves that bring the agent closer to ``target`` (3,) m by at least half a step, by
    travel distance round the site's obstacles (straight without a site): what the exploration
    guard hands a planner. Where none does (a path round a corner that no whole step follows),
    the moves that bring it closer at all: offered every move there, a planner stepped back
    and forth between two cells for 150 s (``site:block``, entrotaxis, seed 6)."""

    def allowed(self, cands: np.ndarray) -> np.ndarray:
        site = self.agent.site
        now = float(travel_xy(site, self.target, self.start[None])[0])
        after = travel_xy(site, self.target, cands)
        closer = after < now - 0.5 * self.agent.step
        return closer if closer.any() else after < now - 1e-9


def wander_goal(
    estimator: Estimator,
    anchor: np.ndarray,
    agent: GridAgent,
    radius: float,
    position: np.ndarray,
) -> np.ndarray | None:
    """Where to go when the robot (at ``position`` (3,) m) has kept to one region (within
    ``radius`` m of ``anchor`` (3,) m) while the belief stays wider than it: the grid point
    outside the region (beyond ``radius`` + one step of the anchor, reachable from the robot,
    :func:`reachable_points`) whose next reading tells the most
    (:func:`detection_information`), or None when no such point tells anything."""
    theta, weights = joint_belief(estimator)
    grid = area_grid(agent, float(anchor[2]))
    outside = np.hypot(*(grid[:, :2] - anchor[:2]).T) > radius + agent.step
    grid = reachable_points(agent, position, grid[outside])
    if len(grid) == 0:
        return None
    info = detection_information(theta, weights, estimator.sensor, estimator.plume, grid)
    best = int(np.argmax(info))
    return grid[best] if info[best] > WANDER_LEAST_INFORMATION else None


WANDER_LEAST_INFORMATION = 1e-3
"""nats: a grid point telling less than this is no reason to leave a region."""
