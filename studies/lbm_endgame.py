"""Where each planner takes its last readings on the lbm plume and where its estimate ends,
relative to the release (docs/plumes.md, a lab note: nothing is chosen from it).

For each `dcee run` folder: over the readings of the last 300 s, the median along-wind
coordinate (m, < 0 upwind of the release centre), the median distance from the release, the
shares taken upwind and within 2 m, the share of the detections among them taken upwind; at
the end, the along- and cross-wind error of the posterior mean, the spread √tr P, the final
RMSE and whether the truth lies in the 95 % region. Per planner: medians, and the count of
searches with the truth in the region.

    .venv/bin/python studies/lbm_endgame.py RUN_FOLDER ... \\
        [--csv docs/results/lbm-plume/endgame.csv]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

LATE = 300.0
"""s: the end of the search the readings are taken from."""


def endgame(folder: Path) -> dict[str, object]:
    summary = json.loads((folder / "summary.json").read_text())
    config = json.loads((folder / "config.json").read_text())
    steps = pd.read_parquet(folder / "steps.parquet")
    truth = config["scenario"]["truth"]
    phi = math.radians(truth["phi"])  # where the wind comes from, counter-clockwise from +x
    down = -np.array([math.cos(phi), math.sin(phi)])
    left = np.array([-down[1], down[0]])
    rel = steps[["x", "y"]].to_numpy() - np.array([truth["x"], truth["y"]])
    along, cross = rel @ down, rel @ left
    late = steps["time"].to_numpy() >= steps["time"].max() - LATE
    detected = late & steps["detection"].to_numpy()
    error = steps[["mean_x", "mean_y"]].to_numpy()[-1] - np.array([truth["x"], truth["y"]])
    return {
        "strategy": config["strategy"],
        "scenario": summary["scenario"],
        "late_along_median_m": float(np.median(along[late])),
        "late_distance_median_m": float(np.median(np.hypot(along, cross)[late])),
        "late_upwind_share": float(np.mean(along[late] < 0)),
        "late_within_2m_share": float(np.mean(np.hypot(along, cross)[late] < 2.0)),
        "late_detections_upwind_share": float(np.mean(along[detected] < 0))
        if detected.any()
        else math.nan,
        "final_along_m": float(error @ down),
        "final_cross_m": float(error @ left),
        "final_spread_m": float(steps["spread"].iloc[-1]),
        "final_rmse_m": float(summary["final_rmse"]),
        "truth_in_95": bool(summary["truth_in_95"]),
        "code": summary["version"],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--csv", type=Path, default=None)
    args = ap.parse_args()
    rows = pd.DataFrame([endgame(folder) for folder in args.runs])
    if args.csv is not None:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        rows.to_csv(args.csv, index=False)
    medians = rows.groupby("strategy").median(numeric_only=True)
    medians["searches"] = rows.groupby("strategy").size()
    medians["truth_in_95"] = rows.groupby("strategy")["truth_in_95"].sum()
    with pd.option_context("display.width", 200):
        print(medians.round(2).to_string())


if __name__ == "__main__":
    main()
