"""The robots-vs-time table of the team study (issue 16): time to RMSE < 1 m and final RMSE
against the number of robots sharing one belief, per planner, on common (configuration, seed).

    .venv/bin/python studies/team_table.py results/paper-source-cl2 results/team-a2 results/team-a3

Each folder holds `dcee bench` searches (1, 2 or 3 robots; the count is read from the summaries,
searches from before team support count as 1). Only (configuration, seed) pairs present for
every robot count of a planner are used, so the rows are paired.
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import load_summaries
from dcee.analysis.statistics import censored_median_time, median_ci

PLANNERS = ("infotaxis", "dcee-cl")


def load(folders: list[str]) -> pd.DataFrame:
    frames = [load_summaries(f) for f in folders]
    runs = pd.concat(frames, ignore_index=True)
    runs["agents"] = runs.get("agents", pd.Series(1, index=runs.index)).fillna(1).astype(int)
    return runs[runs.strategy.isin(PLANNERS)]


def table(runs: pd.DataFrame) -> str:
    lines = [
        "| planner | robots | paired searches | source acquired | median final RMSE (m) | "
        "median time to RMSE < 1 m (s) | to < 0.5 m (s) | final RMSE vs 1 robot: median "
        "difference, Wilcoxon p |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for planner in PLANNERS:
        mine = runs[runs.strategy == planner]
        counts = sorted(mine.agents.unique())
        keys = None
        for k in counts:
            g = mine[mine.agents == k]
            pairs = set(zip(g.scenario, g.seed, strict=True))
            keys = pairs if keys is None else keys & pairs
        if not keys:
            continue
        mine = mine[[(s, d) in keys for s, d in zip(mine.scenario, mine.seed, strict=True)]]
        base = mine[mine.agents == 1].set_index(["scenario", "seed"]).final_rmse
        for k in counts:
            g = mine[mine.agents == k]
            n = len(g)
            rmse = median_ci(g.final_rmse.to_numpy())
            times = [
                censored_median_time(g[col].to_numpy(dtype=float), g.budget.to_numpy(dtype=float))
                for col in ("time_to_rmse_1m", "time_to_rmse_0_5m")
            ]
            fmt = [f"{m:.0f} [{lo:.0f}, {hi:.0f}]".replace("inf", "> 900") for m, lo, hi in times]
            if k == 1 or len(base) == 0:
                test = "—"
            else:
                diff = g.set_index(["scenario", "seed"]).final_rmse - base
                diff = diff.dropna()
                p = stats.wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
                test = f"{np.median(diff):+.3f} m, p = {p:.2g}"
            lines.append(
                f"| {planner} | {k} | {n} | {int(g.source_acquired.sum())}/{n} | "
                f"{rmse[0]:.2f} [{rmse[1]:.2f}, {rmse[2]:.2f}] | {fmt[0]} | {fmt[1]} | {test} |"
            )
    return "\n".join(lines)


if __name__ == "__main__":
    print(table(load(sys.argv[1:])))
