"""One simulated search: truth → sensor noise → reading → Searcher.tell → Searcher.ask → move.

Random streams: ``SeedSequence(seed)`` is split into a *truth* stream (sensor noise of the real
readings), an *agent* stream (split again into filter and planner) and a *figures* stream
(particle subsamples for plots only); child 3 of the seed drives a stochastic truth such as the
filament plume (:func:`dcee.simulation.truth.plume_stream`). The truth stream draws the same
numbers at every step whatever the agent does, so two strategies run with the same seed see
identical truth noise (common random numbers).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcee.allocator import tune_allocator
from dcee.analysis.metrics import summarise
from dcee.estimation.particle_filter import ParticleFilter
from dcee.models.sensor import Sensor
from dcee.planning import get as get_planner
from dcee.planning.base import planner_class
from dcee.scenarios.config import Scenario
from dcee.searcher import Searcher
from dcee.simulation.truth import TruthModel, make_truth


@dataclass
class EpisodeResult:
    """Per-step records (list of dicts, one per reading), the summary, the final particles
    (N, 8) with every parameter (known ones included) and their weights (N,), and optional
    snapshots of the particles' source locations for figures: list of (time, (n, 3) array)."""

    records: list[dict[str, Any]]
    summary: dict[str, Any]
    final_theta: np.ndarray
    final_weights: np.ndarray
    snapshots: list[tuple[float, np.ndarray]] = field(default_factory=list)


def streams(seed: int) -> tuple[np.random.Generator, ...]:
    """(truth, filter, planner, figures) generators derived from one seed. The figures stream
    only subsamples particles for plots, so plotting never changes a search."""
    truth_ss, agent_ss, figure_ss = np.random.SeedSequence(seed).spawn(3)
    filter_ss, planner_ss = agent_ss.spawn(2)
    return tuple(np.random.default_rng(s) for s in (truth_ss, filter_ss, planner_ss, figure_ss))


def run_episode(
    scenario: Scenario,
    strategy: str,
    seed: int,
    planner_options: dict[str, Any] | None = None,
    truth: TruthModel | None = None,
    progress: Callable[[float, dict[str, Any]], None] | None = None,
    snapshot_every: float | None = None,
    snapshot_particles: int = 2000,
) -> EpisodeResult:
    """Fly one search until the budget is spent (or the posterior spread < ``stop_spread``)."""
    tune_allocator()
    search = scenario.search
    planner = get_planner(strategy, **_planner_defaults(strategy, scenario, planner_options))
    truth_rng, filter_rng, planner_rng, figure_rng = streams(seed)
    sensor: Sensor = scenario.make_sensor()  # the instrument: makes the real readings
    agent = scenario.make_agent()
    truth = truth or make_truth(scenario, seed)
    true_location = scenario.truth_theta()[:3]
    pf = ParticleFilter(
        scenario.make_prior(),
        scenario.make_estimator_sensor(),  # the reading model of the filter and the planners
        scenario.make_plume(),
        n_particles=search.particles,
        seed=filter_rng,
        resample_threshold=search.resample_threshold,
        mcmc_steps=search.mcmc_steps,
        global_share=search.global_share,
        diversify=search.diversify,
        max_sweeps=search.max_sweeps,
    )
    searcher = Searcher(pf, planner, agent, planner_rng)
    position = np.array(scenario.agent.start, dtype=np.float64)
    t = agent.dwell  # the first reading is taken at the start after one dwell
    average = scenario.average
    records: list[dict[str, Any]] = []
    snapshots: list[tuple[float, np.ndarray]] = []
    next_snapshot = 0.0
    path_length = 0.0
    while True:
        noise = sensor.draw_noise(truth_rng, ())  # the same count per step, whatever the position
        conc = truth.sensed(position, t, average, scenario.sensor.response_time)
        reading = float(sensor.simulate_from(conc, noise))
        info = searcher.tell(position, reading, t)
        est = searcher.estimate()
        rec: dict[str, Any] = {
            "step": len(records),
            "time": t,
            "x": position[0],
            "y": position[1],
            "z": position[2],
            "true_concentration": conc,
            "reading": reading,
            "detection": bool(sensor.is_detection(reading)),
            "mean_x": est.mean[0],
            "mean_y": est.mean[1],
            "mean_z": est.mean[2],
            **{
                f"cov_{a}{b}": est.cov[i, j]
                for i, a in enumerate("xyz")
                for j, b in enumerate("xyz")
                if j >= i
            },
            "spread": est.spread,
            "rmse": pf.rmse(true_location),
            "mean_error": float(np.linalg.norm(est.mean - true_location)),
            "ess": info.ess,
            "resampled": info.resampled,
            "tempering_stages": info.tempering_stages,
            "acceptance": info.acceptance,
            "move_sweeps": info.move_sweeps,
            "distinct": info.distinct,
            "rejected": info.rejected,
            "update_seconds": searcher.last_update_seconds,
        }
        if snapshot_every is not None and t >= next_snapshot:
            snapshots.append((t, _subsample(pf, snapshot_particles, figure_rng)))
            next_snapshot += snapshot_every
        stop = t + agent.step_time > search.budget + 1e-9 or (
            search.stop_spread > 0 and est.spread < search.stop_spread
        )
        waypoint = None if stop else searcher.ask()
        rec["decision_seconds"] = 0.0 if stop else searcher.last_decision_seconds
        records.append(rec)
        if progress:
            progress(t, rec)
        if waypoint is None:
            break
        path_length += float(np.linalg.norm(waypoint - position))
        position = waypoint
        t += agent.step_time
    summary = summarise(records, scenario, strategy, seed, path_length)
    summary["planner_options"] = planner.options()
    summary["recoveries"] = len(pf.recoveries)
    summary["tempering_events"] = sum(r["kind"] == "tempering" for r in pf.recoveries)
    summary["rejected_readings"] = sum(r["kind"] == "rejected" for r in pf.recoveries)
    summary["truth_in_95"] = pf.in_credible_region(true_location, 0.95)
    summary.update(scenario.resolved_settings())
    summary["resamples"] = pf.n_resamples
    if snapshot_every is not None and snapshots[-1][0] != records[-1]["time"]:
        snapshots.append((records[-1]["time"], _subsample(pf, snapshot_particles, figure_rng)))
    return EpisodeResult(records, summary, pf.theta.copy(), pf.weights.copy(), snapshots)


def _subsample(pf: ParticleFilter, n: int, rng: np.random.Generator) -> np.ndarray:
    idx = rng.choice(pf.n, size=min(n, pf.n), replace=True, p=pf.weights)
    return pf.source_locations[idx].copy()


def _planner_defaults(
    strategy: str, scenario: Scenario, options: dict[str, Any] | None
) -> dict[str, Any]:
    """Constructor defaults: the scenario's hypothesis count (a spec's own, ``dcee:hypotheses=25``,
    overrides it in :func:`dcee.planning.get`)."""
    opts = dict(options or {})
    if planner_class(strategy).uses_hypotheses:
        opts.setdefault("n_hypotheses", scenario.search.hypotheses)
    return opts


__all__ = ["EpisodeResult", "run_episode", "streams"]
