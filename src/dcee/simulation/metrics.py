"""Per-run summary metrics (the paper's definitions)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from dcee.scenarios.config import Scenario


def first_time_below(times: np.ndarray, values: np.ndarray, level: float) -> float | None:
    """First time at which ``values`` < ``level`` (None if never)."""
    hit = np.flatnonzero(values < level)
    return float(times[hit[0]]) if len(hit) else None


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
    the particles about the true source falls below 1 m / 0.5 m (null if never).
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
        "plume_acquired": bool(any(r["detection"] for r in records)),
        "source_acquired": bool(final["rmse"] < scenario.search.acquired_rmse),
        "detections": int(sum(r["detection"] for r in records)),
        "time_to_rmse_1m": first_time_below(times, rmse, 1.0),
        "time_to_rmse_0_5m": first_time_below(times, rmse, 0.5),
        "steps": steps,
        "readings": len(records),
        "agents": int(scenario.agent.count),
        "path_length": float(path_length),
        "decision_seconds_total": float(decision.sum()),
        "decision_seconds_mean": float(decision.sum() / steps) if steps else 0.0,
        "update_seconds_total": float(update.sum()),
        "compute_seconds_total": float(decision.sum() + update.sum()),
    }
