"""Side by side with Stone Soup on Stone Soup's own source-term-estimation example.

The workload is the one in Stone Soup's gallery example "Autonomous Source Term Estimation"
(stonesoup 1.9.1): truth (30, 40, 1) m, q = 5 g/s, u = 4 m/s, φ = 90°, ζ1 = 1, ζ2 = 8; sensor
threshold 5e-4, Pd = 0.7, σ_min = 1e-4; 10,000 particles from its prior; the platform starts at
(5, 5, 0) and moves on a 2 m grid; each decision scores its candidate moves with a KL-divergence
reward over 4 hypothesised updates (``MultiUpdateExpectedKLDivergence``, brute-force manager).

Both sides run the same number of decisions from their own filters in this process, and each
decision is timed. Our side is ``infotaxis`` (expected KL divergence) with 4 hypothesised
readings over the same 9 candidates (stay, and 2 m along ±x, ±y, 4 m along ±x, ±y) as Stone
Soup's ``NStepDirectionalGridMovable(n_steps=2, step_size=2)``.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from datetime import datetime, timedelta

import numpy as np

from dcee.allocator import tune_allocator
from dcee.blas import one_blas_thread
from dcee.errors import DceeInputError
from dcee.estimation import ParticleFilter
from dcee.estimation.priors import Gamma, SourcePrior, Uniform
from dcee.models import IsotropicPlume, Sensor
from dcee.models.agent import GridAgent, SearchVolume
from dcee.planning import get as get_planner
from dcee.planning.base import Belief
from dcee.planning.particle_terms import ParticleTerms

TRUTH = np.array([30.0, 40.0, 1.0, 5.0, 4.0, np.radians(90.0), 1.0, 8.0])
START = np.array([5.0, 5.0, 0.0])
N_PARTICLES = 10_000
N_HYPOTHESES = 4
STONESOUP_START = datetime(2026, 1, 1)
TARGET_SPEEDUP = 50.0
"""Issue 46's bar: our decision at least this many times faster, both timed in one run."""


def _candidates(position: np.ndarray) -> np.ndarray:
    """Stone Soup's 9 actions: stay, 1 or 2 steps of 2 m along ±x or ±y, inside [0, 50]²."""
    moves = [np.zeros(3)]
    for axis in (0, 1):
        for sign in (-1.0, 1.0):
            for steps in (1, 2):
                d = np.zeros(3)
                d[axis] = sign * 2.0 * steps
                moves.append(d)
    pts = position[None, :] + np.array(moves)
    return pts[np.all((pts[:, :2] >= 0) & (pts[:, :2] <= 50), axis=1)]


def dcee_decisions(n_decisions: int, seed: int = 1990) -> Iterator[float]:
    """Milliseconds of each infotaxis decision on the example's workload (our implementation),
    one per ``next``; the first decision (loading compiled kernels) is run but not yielded."""
    tune_allocator()  # as the command line does in its own processes
    prior = SourcePrior.from_dict(
        {
            "x": Uniform(0, 50),
            "y": Uniform(0, 50),
            "z": Uniform(0, 5),
            "q": Gamma(2, 5),
            "u": Uniform(0, 6),
            "phi": Uniform(0, np.pi),
            "zeta1": Uniform(0, 2),
            "zeta2": Uniform(6, 10),
        }
    )
    # the paper's exact model, as Stone Soup's side has it
    sensor = Sensor.paper_exact(threshold=5e-4, pd=0.7, sigma_min=1e-4, sigma_frac=0.5)
    plume = IsotropicPlume()
    pf = ParticleFilter(prior, sensor, plume, n_particles=N_PARTICLES, seed=seed)
    planner = get_planner("infotaxis", n_hypotheses=N_HYPOTHESES)
    agent = GridAgent(SearchVolume((0.0, 0.0, 0.0), (50.0, 50.0, 5.0)), step=2.0)
    rng = np.random.default_rng(seed)
    position = START.copy()
    cache = ParticleTerms()  # what a Searcher keeps across decisions
    for n in range(n_decisions + 1):
        c = plume.concentration(TRUTH[None], position[None])[0, 0]
        with one_blas_thread():  # as Searcher.tell does
            pf.update(position, float(sensor.simulate(c, rng)))
        cands = _candidates(position)
        t0 = time.perf_counter()
        with one_blas_thread():  # as Searcher.ask does
            costs, _ = planner.costs(
                # the particles as Searcher.belief hands them over
                Belief(pf.planning_particles(), pf.weights, sensor, plume, cache),
                position,
                cands,
                agent,
                rng,
            )
        elapsed = 1e3 * (time.perf_counter() - t0)
        position = cands[int(np.argmin(costs))]
        if n > 0:  # the first call includes loading compiled kernels
            yield elapsed


def stonesoup_example(start: np.ndarray, resolution: int, n_steps: int, step_size: int) -> tuple:
    """The parts of Stone Soup's STE examples both comparisons share: (truth, sensor, platform
    at ``start`` with an ``NStepDirectionalGridMovable`` of the given settings, predictor,
    updater with the examples' ESS resampler, MCMC regulariser and constraint), built at a
    fixed timestamp. :class:`DceeInputError` if Stone Soup (the ``bench`` extra) is missing."""
    try:
        from stonesoup.models.measurement.gas import IsotropicPlume as SSPlume
        from stonesoup.models.transition.linear import (
            CombinedGaussianTransitionModel,
            RandomWalk,
        )
        from stonesoup.movable.grid import NStepDirectionalGridMovable
        from stonesoup.platform import FixedPlatform
        from stonesoup.predictor.particle import ParticlePredictor
        from stonesoup.regulariser.particle import MCMCRegulariser
        from stonesoup.resampler.particle import ESSResampler
        from stonesoup.sensor.gas import GasIntensitySensor
        from stonesoup.types.groundtruth import GroundTruthState
        from stonesoup.types.state import State
        from stonesoup.updater.particle import ParticleUpdater
    except ImportError:
        raise DceeInputError(
            "compare-stonesoup",
            "Stone Soup is not installed; install the optional extra: pip install 'dcee[bench]'",
        ) from None

    when = STONESOUP_START
    truth = GroundTruthState(list(TRUTH), timestamp=when)
    sensor = GasIntensitySensor(
        min_noise=1e-4, missed_detection_probability=0.3, sensing_threshold=5e-4
    )
    platform = FixedPlatform(
        movement_controller=NStepDirectionalGridMovable(
            states=[State([[start[0]], [start[1]], [start[2]]], timestamp=when)],
            position_mapping=(0, 1, 2),
            resolution=resolution,
            n_steps=n_steps,
            step_size=step_size,
            action_mapping=(0, 1),
            action_space=np.array([[0, 50], [0, 50]]),
        ),
        sensors=[sensor],
    )

    def constraint(state):
        v = state.state_vector
        return (v[3, :] < 0) | (v[4, :] < 0) | (v[6, :] < 0) | (v[7, :] < 0)

    predictor = ParticlePredictor(CombinedGaussianTransitionModel([RandomWalk(0.0)] * 8))
    updater = ParticleUpdater(
        SSPlume(),
        resampler=ESSResampler(),
        regulariser=MCMCRegulariser(constraint_func=constraint),
        constraint_func=constraint,
    )
    return truth, sensor, platform, predictor, updater


def stonesoup_decisions(n_decisions: int, seed: int = 1990) -> Iterator[float]:
    """Milliseconds of each ``choose_actions`` call in Stone Soup's own example set-up, one per
    ``next``."""
    truth, sensor, platform, predictor, updater = stonesoup_example(START, 1, 2, 2)
    from stonesoup.sensormanager import BruteForceSensorManager
    from stonesoup.sensormanager.reward import MultiUpdateExpectedKLDivergence
    from stonesoup.types.hypothesis import SingleHypothesis
    from stonesoup.types.state import ParticleState, StateVectors
    from stonesoup.types.track import Track
    from stonesoup.updater.particle import ParticleUpdater

    np.random.seed(seed)  # noqa: NPY002 - Stone Soup draws from the global generator
    start = STONESOUP_START
    reward = MultiUpdateExpectedKLDivergence(
        updater=ParticleUpdater(measurement_model=None), updates_per_track=N_HYPOTHESES
    )
    manager = BruteForceSensorManager(
        sensors={sensor}, platforms={platform}, reward_function=reward
    )
    n = N_PARTICLES
    rng = np.random.default_rng(seed)
    prior = ParticleState(
        StateVectors(
            [
                rng.uniform(0, 50, n),
                rng.uniform(0, 50, n),
                rng.uniform(0, 5, n),
                rng.gamma(2, 5, n),
                rng.uniform(0, 6, n),
                rng.uniform(0, np.pi, n),
                rng.uniform(0, 2, n),
                rng.uniform(6, 10, n),
            ]
        ),
        weight=np.array([1 / n] * n),
        timestamp=start,
    )
    prior.parent = prior
    track = Track(prior)

    def assimilate(now: datetime) -> ParticleState:
        prediction = predictor.predict(track[-1], timestamp=now)
        truth.timestamp = now
        detection = sensor.measure({truth}, noise=True).pop()
        track.append(updater.update(SingleHypothesis(prediction, detection)))
        return track[-1]

    assimilate(start + timedelta(seconds=1))
    for k in range(1, n_decisions + 1):
        now = start + timedelta(seconds=k + 1)
        t0 = time.perf_counter()
        chosen = manager.choose_actions({track}, now, n_steps=2, step_size=2, action_mapping=(0, 1))
        elapsed = 1e3 * (time.perf_counter() - t0)
        for s, actions in chosen[0].items():
            s.add_actions(actions)
            s.act(now)
        assimilate(now)
        yield elapsed


def _alternate(n_decisions: int) -> tuple[float, float]:
    """One run: fresh filters on both sides, one Stone Soup decision then one of ours, n times;
    the medians (ms) of Stone Soup's and of ours."""
    ss: list[float] = []
    ours: list[float] = []
    stone_soup = stonesoup_decisions(n_decisions)
    dcee = dcee_decisions(n_decisions)
    for _ in range(n_decisions):
        ss.append(next(stone_soup))
        ours.append(next(dcee))
    return float(np.median(ss)), float(np.median(ours))


def compare(n_decisions: int = 10, repeats: int = 1) -> dict:
    """Median ms per decision for both, measured in this process in alternation (one Stone
    Soup decision, then one of ours, and so on: both see the same machine load), and the
    ratio. With ``repeats`` > 1 the whole run is repeated (fresh filters each time) and the
    summary is the median over the runs (the ratio: the median of the runs' ratios), each run
    kept under ``runs``: one run's median of 20 decisions has moved by up to ±15 % between
    runs on this 2-vCPU machine, and once by a third (2026-11-29)."""
    from threadpoolctl import threadpool_limits

    runs = []
    # One BLAS thread for both sides: OpenBLAS threads spinning after Stone Soup's calls would
    # otherwise take the cores from our numba threads in the decision that follows (dcee.blas);
    # Stone Soup itself is no slower with one (measured 39.3 ms against 37.8 ms, noise level).
    with threadpool_limits(limits=1, user_api="blas"):
        for _ in range(repeats):
            ss_med, our_med = _alternate(n_decisions)
            runs.append(
                {"stonesoup_median_ms": ss_med, "dcee_infotaxis_median_ms": our_med,
                 "speedup": ss_med / our_med}
            )  # fmt: skip
    ss_med = float(np.median([r["stonesoup_median_ms"] for r in runs]))
    our_med = float(np.median([r["dcee_infotaxis_median_ms"] for r in runs]))
    speedups = [r["speedup"] for r in runs]
    return {
        "workload": "Stone Soup STE example: 10,000 particles, 9 moves × 4 updates, KL reward",
        "decisions": n_decisions,
        "repeats": repeats,
        "stonesoup_median_ms": ss_med,
        "dcee_infotaxis_median_ms": our_med,
        "speedup": float(np.median(speedups)),
        "speedup_range": [min(speedups), max(speedups)],
        "ratio_to": {"stonesoup": our_med / ss_med},
        "target_speedup": TARGET_SPEEDUP,
        "runs": runs,
    }
