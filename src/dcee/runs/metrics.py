"""Score a search: its summary metrics (the paper's definitions), the longest stall, and the
whole summary a saved search carries (:func:`search_summary`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from dcee.estimation.source_count import SourceCountBank
from dcee.searcher import WANDER_RADIUS

if TYPE_CHECKING:
    from dcee.scenarios import Scenario
    from dcee.searcher import Searcher


def first_time_below(times: np.ndarray, values: np.ndarray, level: float) -> float | None:
    """First time at which ``values`` < ``level`` (None if never)."""
    hit = np.flatnonzero(values < level)
    return float(times[hit[0]]) if len(hit) else None


def longest_stall(
    times: np.ndarray,
    positions: np.ndarray,
    acquired: np.ndarray,
    step: float,
) -> float:
    """Longest time, s, the agent stayed within one step of one position while the source was
    not yet acquired: the longest window [t_i, t_j] of consecutive readings whose positions all
    lie within ``step`` m (horizontally) of the window's first position p_i and none of which
    had the source acquired (``acquired`` False: RMSE ≥ ``search.acquired_rmse``).

    times: (n,) s, non-decreasing; positions: (n, 2 or 3) m; acquired: (n,) bool. A robot that
    paces between two cells one step apart, or hovers on one spot, makes a long window; one that
    moves on makes windows of one move (the reading before it and the one after). Holding
    where the source is already acquired is not a stall.
    """
    n = len(times)
    xy = np.asarray(positions, float)[:, :2]
    reach = step * (1.0 + 1e-9) + 1e-9
    best = 0.0
    i = 0
    while i < n:
        if acquired[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and not acquired[j + 1] and math.hypot(*(xy[j + 1] - xy[i])) <= reach:
            j += 1
        best = max(best, float(times[j] - times[i]))
        i += 1
    return best


WANDER_SECONDS = 120.0
"""s: a wander longer than this is counted in a campaign's report (issue 44's bar)."""


def search_wander(records: list[dict[str, Any]], acquired_rmse: float) -> float:
    """The longest time, s, a robot of the search stayed within :data:`WANDER_RADIUS` m (the
    wander guard's region, :mod:`dcee.searcher`: a 15 m region, the scale issue 44 measured) of
    one position while the source was not acquired and its belief was wider than that region
    (the spread √tr P above the radius: readings in the region could not resolve it): what
    the wander guard (:meth:`dcee.searcher.Searcher.wander_goal`) acts on. A robot closing in
    on a source with a belief narrower than the region is not wandering, nor is one stuck on a
    narrow, wrong belief (a failure the final error counts)."""
    return search_stall(records, WANDER_RADIUS, acquired_rmse, wider_than=WANDER_RADIUS)


def search_stall(
    records: list[dict[str, Any]],
    step: float,
    acquired_rmse: float,
    wider_than: float | None = None,
) -> float:
    """:func:`longest_stall` of a search's records, s: the longest over its robots; with
    ``wider_than`` (m), a reading whose belief spread is at most that counts as settled too."""
    robots = np.array([r.get("robot", 0) for r in records])
    best = 0.0
    for robot in np.unique(robots):
        rows = [r for r, k in zip(records, robots, strict=True) if k == robot]
        settled = np.array(
            [
                r["rmse"] < acquired_rmse or (wider_than is not None and r["spread"] <= wider_than)
                for r in rows
            ]
        )
        best = max(
            best,
            longest_stall(
                np.array([r["time"] for r in rows]),
                np.array([[r["x"], r["y"]] for r in rows]),
                settled,
                step,
            ),
        )
    return best


REGION_FLOOR_GRID = (0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5)
"""m: the model-discrepancy floors (``estimator.region_floor``) at which every summary also
reports whether the truth lies in the 95 % region (``truth_in_95_floor``): the grid the default
was chosen from, so a study shows the coverage at each without flying again."""

OSPA_CUTOFF = 3.0
"""m: the cut-off c of the OSPA distance in every summary: a missed or spurious source costs as
much as one 3 m off, the paper's acquisition radius (``search.acquired_rmse``)."""


def ospa(
    estimated: np.ndarray, true: np.ndarray, cutoff: float = OSPA_CUTOFF, order: float = 1.0
) -> float:
    """The OSPA distance (Schuhmacher, Vo & Vo 2008) between two finite sets of locations, m.

    estimated: (m, D), true: (n, D). With m ≤ n (else swapped), d_c = min(c, ‖x − y‖) and the
    best one-to-one assignment π of the smaller set into the larger,

        OSPA = ((1/n) (min_π Σᵢ d_c(xᵢ, y_π(i))^p + c^p (n − m)))^(1/p):

    the mean error per source over the larger set, each unmatched source costing c (cut-off
    ``cutoff`` m, order ``order``). 0 for two empty sets; c when one is empty."""
    from scipy.optimize import linear_sum_assignment

    a = np.asarray(estimated, dtype=np.float64).reshape(-1, np.shape(true)[-1])
    b = np.asarray(true, dtype=np.float64).reshape(-1, a.shape[1])
    if len(a) > len(b):
        a, b = b, a
    m, n = len(a), len(b)
    if n == 0:
        return 0.0
    if m == 0:
        return float(cutoff)
    d = np.minimum(cutoff, np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)) ** order
    rows, cols = linear_sum_assignment(d)
    return float(((d[rows, cols].sum() + cutoff**order * (n - m)) / n) ** (1.0 / order))


def summarise(
    records: list[dict[str, Any]],
    scenario: Scenario,
    strategy: str,
    seed: int,
    path_length: float,
) -> dict[str, Any]:
    """Summary of one search from its per-step records.

    plume_acquired: any reading at or above the sensor threshold; source_acquired: final RMSE
    below ``search.acquired_rmse`` (3 m in the paper); time_to_rmse_*: first time the RMSE of
    the particles about the true source falls below 1 m / 0.5 m (null if never);
    longest_stall: :func:`search_stall`, s (a robot pacing on one spot before it has the source);
    longest_wander: :func:`search_wander`, s (one staying in a 15 m region with a belief wider
    than it before it has the source);
    true_sources: how many releases the truth holds; final_ospa: :func:`ospa` (3 m cut-off,
    order 1) between the estimated set (one source, at the posterior mean) and the true
    releases, m (one release: the final mean's error, capped at 3 m; each release the search
    reports nothing of adds 3 m / K).
    """
    times = np.array([r["time"] for r in records])
    rmse = np.array([r["rmse"] for r in records])
    decision = np.array([r["decision_seconds"] for r in records])
    update = np.array([r["update_seconds"] for r in records])
    final = records[-1]
    steps = len(np.unique(times)) - 1  # moves: every robot reads once per step
    return {
        "scenario": scenario.name,
        "strategy": strategy,
        "seed": int(seed),
        "unknown": scenario.unknown,
        "truth_model": scenario.truth.model_name,
        "particles": scenario.search.particles,
        "hypotheses": scenario.search.hypotheses,
        "budget": scenario.search.budget,
        "final_time": float(final["time"]),
        "final_rmse": float(final["rmse"]),
        "final_mean_error": float(final["mean_error"]),
        "final_spread": float(final["spread"]),
        "final_mean": [float(final["mean_x"]), float(final["mean_y"]), float(final["mean_z"])],
        "true_sources": 1 + len(scenario.truth.extra_sources),
        "final_ospa": ospa(
            np.array([[final["mean_x"], final["mean_y"], final["mean_z"]]]),
            scenario.truth.source_locations(),
        ),
        "plume_acquired": bool(any(r["detection"] for r in records)),
        "source_acquired": bool(final["rmse"] < scenario.search.acquired_rmse),
        "detections": int(sum(r["detection"] for r in records)),
        "time_to_rmse_1m": first_time_below(times, rmse, 1.0),
        "time_to_rmse_0_5m": first_time_below(times, rmse, 0.5),
        "longest_stall": search_stall(records, scenario.agent.step, scenario.search.acquired_rmse),
        "longest_wander": search_wander(records, scenario.search.acquired_rmse),
        "steps": steps,
        "readings": len(records),
        "agents": int(scenario.agent.count),
        "path_length": float(path_length),
        "decision_seconds_total": float(decision.sum()),
        "decision_seconds_mean": float(decision.sum() / steps) if steps else 0.0,
        "update_seconds_total": float(update.sum()),
        "compute_seconds_total": float(decision.sum() + update.sum()),
    }


def search_summary(
    records: list[dict[str, Any]],
    scenario: Scenario,
    strategy: str,
    seed: int,
    path_length: float,
    searcher: Searcher,
) -> dict[str, Any]:
    """A search's summary: :func:`dcee.runs.metrics.summarise` of its ``records``, the
    planner's options and the filter's diagnostics (recoveries, calibration against the
    scenario's true source, resamplings) and the scenario's resolved settings. The simulation,
    ``dcee replay`` and the ROS demo all summarise through it."""
    pf = searcher.filter
    out = summarise(records, scenario, strategy, seed, path_length)
    planner = searcher.planner
    out["planner_options"] = planner.options() if planner is not None else {}
    out["recoveries"] = len(pf.recoveries)
    out["tempering_events"] = sum(r["kind"] == "tempering" for r in pf.recoveries)
    out["rejected_readings"] = sum(r["kind"] == "rejected" for r in pf.recoveries)
    truth = scenario.truth_theta()[:3]
    out["truth_in_95"] = pf.in_credible_region(truth, 0.95, scenario.region_floor)
    # the region at every floor of the grid the default was chosen from (docs/plumes.md)
    out["truth_in_95_floor"] = {
        f"{f:.2f}": pf.in_credible_region(truth, 0.95, f) for f in REGION_FLOOR_GRID
    }
    out.update(scenario.resolved_settings())
    out["resamples"] = pf.n_resamples
    out["stall_guard_fired"] = searcher.guard_fired  # decisions the stall guard restricted
    out["explore_guard_fired"] = searcher.explore_fired  # and the exploration guard,
    out["wander_guard_fired"] = searcher.wander_fired  # of them for keeping to one region
    if isinstance(pf, SourceCountBank):  # the count was unknown: what the search made of it
        out.update(pf.count_summary())
        out["count_correct"] = out["estimated_count"] == out["true_sources"]
        out["final_ospa"] = ospa(pf.estimated_sources(), scenario.truth.source_locations())
    choice = pf.reading_model()
    if choice is not None:  # which reading model the readings chose, and how firmly
        out["model"] = choice.name
        out["model_probability"] = choice.probability
        out["model_switches"] = choice.switches
    out["config"] = scenario.name
    out["parameter_names"] = list(scenario.unknown_names)
    return out
