"""The per-reading record of a search (one row of ``steps.parquet``): what the robot read and
where, and the posterior and the filter's diagnostics after it. Made in one place for the
simulation, the ROS node and ``dcee replay``."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from dcee.estimation.particle_filter import UpdateInfo
from dcee.searcher import Searcher


def reading_record(
    searcher: Searcher,
    info: UpdateInfo,
    *,
    step: int,
    robot: int,
    time: float,
    position: np.ndarray,
    told: np.ndarray,
    reading: float,
    detection: bool,
    true_location: np.ndarray | None,
    heading: float,
    travel_time: float,
    true_concentration: float = math.nan,
) -> dict[str, Any]:
    """One row of a search's per-reading record (``steps.parquet``), made after ``searcher``
    assimilated ``reading`` (g/m³) taken at ``position`` (3,) m (told as ``told``): the
    posterior summary and the filter's diagnostics. ``true_location`` (3,) m gives the RMSE
    and the error of the mean (NaN without one); ``heading`` in °; ``travel_time`` s of the
    drive before the reading. The simulation, the ROS node and ``dcee replay`` all use it."""
    est = searcher.estimate()
    pf = searcher.filter
    if true_location is None:
        rmse = mean_error = math.nan
    else:
        rmse = pf.rmse(true_location)
        mean_error = float(np.linalg.norm(est.mean - true_location))
    return {
        "step": step,
        "robot": robot,
        "time": time,
        "x": position[0],
        "y": position[1],
        "z": position[2],
        "heading": heading,
        "told_x": told[0],
        "told_y": told[1],
        "travel_time": travel_time,
        "true_concentration": true_concentration,
        "reading": reading,
        "detection": detection,
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
        "rmse": rmse,
        "mean_error": mean_error,
        "ess": info.ess,
        "resampled": info.resampled,
        "tempering_stages": info.tempering_stages,
        "acceptance": info.acceptance,
        "move_sweeps": info.move_sweeps,
        "distinct": info.distinct,
        "rejected": info.rejected,
        "update_seconds": searcher.last_update_seconds,
        "decision_seconds": 0.0,
        "log_evidence": pf.log_evidence,
        **(
            {"model": choice.name, "model_probability": choice.probability}
            if (choice := pf.reading_model()) is not None
            else {}
        ),
    }
