"""Fly one simulated search with a planner until its budget is spent: :func:`run_episode`."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from dcee.estimation.base import Estimator
from dcee.planning import get as get_planner
from dcee.planning.team import check_team_planner
from dcee.provenance import code_version, platform_record
from dcee.runs.assemble import planner_defaults
from dcee.runs.result import EpisodeResult
from dcee.runs.simulation import SearchSimulation
from dcee.scenarios import Scenario
from dcee.simulation.truth import TruthModel


def run_episode(
    scenario: Scenario,
    strategy: str,
    seed: int,
    planner_options: dict[str, Any] | None = None,
    truth: TruthModel | None = None,
    progress: Callable[[float, dict[str, Any]], None] | None = None,
    snapshot_at: Sequence[float] | None = None,
    snapshot_particles: int = 2000,
) -> EpisodeResult:
    """Fly one search until the budget is spent (or the posterior spread < ``stop_spread``).

    ``snapshot_at``: times (s) at which to keep a weighted subsample of ``snapshot_particles``
    source locations (at the first reading at or after each time; the last reading always, when
    any are asked for), e.g. :func:`snapshot_times` of the budget, or a dense grid for an
    animation. The subsamples come from their own random stream: they never change the search.
    """
    planner = get_planner(strategy, **planner_defaults(strategy, scenario, planner_options))
    sim = SearchSimulation(scenario, seed, planner, truth)
    pf, searcher = sim.filter, sim.searcher
    snapshots: list[tuple[float, np.ndarray]] = []
    pending = sorted(snapshot_at) if snapshot_at is not None else []
    team = scenario.agent.count > 1
    if team:
        check_team_planner(planner)
    while True:
        rec = sim.sense()[-1]
        t = sim.time
        if pending and t >= pending[0] - 1e-9:
            snapshots.append((t, _subsample(pf, snapshot_particles, sim.figure_rng)))
            while pending and t >= pending[0] - 1e-9:
                pending.pop(0)
        if sim.finished:
            waypoint = None
        else:
            waypoint = searcher.ask_team(sim.positions) if team else searcher.ask()
        if waypoint is not None:
            rec["decision_seconds"] = searcher.last_decision_seconds
        if progress:
            progress(t, rec)
        if waypoint is None:
            break
        sim.move(waypoint)
        if sim.over_budget:
            break
    records = sim.records
    summary = sim.summary(strategy)
    if snapshot_at is not None and (not snapshots or snapshots[-1][0] != records[-1]["time"]):
        snapshots.append((records[-1]["time"], _subsample(pf, snapshot_particles, sim.figure_rng)))
    config = {
        "scenario": scenario.model_dump(mode="json"),
        "strategy": strategy,
        "seed": seed,
        "planner_options": summary["planner_options"],
        "code": code_version(),
    }
    summary["code"] = config["code"]
    summary["platform"] = platform_record()
    summary["version"] = config["code"]["version"]
    # a count bank's most probable count, every release (figures colour each); else the filter's
    final = getattr(pf, "estimate_particles", None)
    theta, weights = final() if final is not None else (pf.theta, pf.weights)
    return EpisodeResult(records, summary, theta.copy(), weights.copy(), snapshots, config)


def _subsample(pf: Estimator, n: int, rng: np.random.Generator) -> np.ndarray:
    idx = rng.choice(pf.n, size=min(n, pf.n), replace=True, p=pf.weights)
    return pf.source_locations[idx].copy()
