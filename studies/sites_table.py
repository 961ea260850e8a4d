"""The obstacle study's table (issue 32): per site and planner, how often the source was
acquired, the final error, the path flown against the straight line and the shortest way round
the obstacles, and whether any search touched an obstacle or no-go zone (every recorded
position and every drive, against the shapes themselves).

    python studies/sites_table.py results/sites results/sites-mcts results/sites-robot \\
        [--csv docs/results/sites/sites.csv]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from dcee.analysis.results import find_runs
from dcee.analysis.statistics import median_ci, wilson
from dcee.scenarios.schema.scenario import validate_scenario

NEAR = 8.0
"""m: "reached the source" for the path-length column: within 8 m (outside site:nogo's 5 m
zone and its margin), so the way flown there compares with the way round the obstacles."""


def rows_of(folder: Path) -> list[dict]:
    out = []
    for run in find_runs(folder):
        summary = json.loads((run / "summary.json").read_text())
        config = json.loads((run / "config.json").read_text())
        scenario = validate_scenario(config["scenario"])
        steps = pd.read_parquet(run / "steps.parquet", columns=["x", "y"])
        xy = steps[["x", "y"]].to_numpy()
        inside = int(scenario.in_obstacle(xy).sum())
        start = np.array(scenario.agent.start[:2])
        source = scenario.truth_theta()[:2]
        # the way flown until the robot first came within NEAR m of the source
        flown = np.concatenate(
            [[0.0], np.cumsum(np.hypot(*np.diff(np.vstack([start, xy]), axis=0).T))]
        )[1:]
        near = np.flatnonzero(np.hypot(*(xy - source).T) <= NEAR)
        to_near = float(flown[near[0]]) if len(near) else np.nan
        out.append(
            {
                "scenario": summary["scenario"],
                "strategy": summary["strategy"],
                "motion": scenario.agent.model,
                "seed": summary["seed"],
                "acquired": bool(summary["source_acquired"]),
                "final_rmse": float(summary["final_rmse"]),
                "time_to_1m": summary.get("time_to_rmse_1m"),
                "longest_stall": float(summary.get("longest_stall", np.nan)),
                "path_length": float(summary["path_length"]),
                "straight": float(np.hypot(*(source - start))),
                "round": float(summary.get("start_to_source_travel", np.nan)),
                "to_near": to_near,
                "positions_inside": inside,
                "drives_into_obstacles": int(summary.get("drives_into_obstacles", 0)),
            }
        )
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folders", nargs="+", type=Path)
    ap.add_argument("--csv", type=Path)
    args = ap.parse_args(argv)
    runs = pd.DataFrame([r for f in args.folders for r in rows_of(f)])
    table = []
    for (scenario, strategy, motion), g in runs.groupby(["scenario", "strategy", "motion"]):
        n = len(g)
        acq = wilson(int(g["acquired"].sum()), n)
        med = median_ci(g["final_rmse"].to_numpy())
        table.append(
            {
                "scenario": scenario,
                "strategy": strategy,
                "motion": motion,
                "searches": n,
                "source_acquired_rate": acq[0],
                "source_acquired_lo": acq[1],
                "source_acquired_hi": acq[2],
                "median_final_rmse": med[0],
                "median_final_rmse_lo": med[1],
                "median_final_rmse_hi": med[2],
                "longest_stall": float(g["longest_stall"].max()),
                "straight": float(g["straight"].iloc[0]),
                "round": float(g["round"].iloc[0]),
                "path_length": float(g["path_length"].median()),
                "to_near": float(g["to_near"].median()),
                "reached_near": float(g["to_near"].notna().mean()),
                "positions_inside": int(g["positions_inside"].sum()),
                "drives_into_obstacles": int(g["drives_into_obstacles"].sum()),
            }
        )
    frame = pd.DataFrame(table)
    print(
        "| site | planner | motion | n | acquired | median final RMSE (m) | start→source "
        "straight / round the obstacles (m) | median way flown until within 8 m of it (m) | "
        "positions or drives inside an obstacle | longest stall (s) |"
        "\n|---|---|---|---|---|---|---|---|---|---|"
    )
    for _, r in frame.iterrows():
        n = int(r["searches"])
        print(
            f"| `{r['scenario']}` | `{r['strategy']}` | {r['motion']} | {n} "
            f"| {round(r['source_acquired_rate'] * n)}/{n} | {r['median_final_rmse']:.2f} "
            f"| {r['straight']:.0f} / {r['round']:.0f} | {r['to_near']:.0f} "
            f"({100 * r['reached_near']:.0f} % got there) "
            f"| {r['positions_inside']} / {r['drives_into_obstacles']} | {r['longest_stall']:.0f} |"
        )
    total_inside = int(frame["positions_inside"].sum() + frame["drives_into_obstacles"].sum())
    print(f"\n{len(runs)} searches; positions or drives inside an obstacle: {total_inside}")
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        frame.to_csv(args.csv, index=False, float_format="%.6g")
    return 1 if total_inside else 0


if __name__ == "__main__":
    sys.exit(main())
