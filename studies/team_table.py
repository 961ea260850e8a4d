"""The robots-vs-time table of the team study (issue 16): time to RMSE < 1 m and final RMSE
against the number of robots sharing one belief, per planner, on common (configuration, seed).

    .venv/bin/python studies/team_table.py results/paper-source results/team-a2 results/team-a3 \\
        [--out docs/results/team]

Each folder holds `dcee bench` searches (1, 2 or 3 robots; the count is read from the summaries,
searches from before team support count as 1). Only (configuration, seed) pairs present for
every robot count of a planner are used, so the rows are paired.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import load_summaries
from dcee.analysis.statistics import censored_median_time, median_ci, wilson

PLANNERS = ("infotaxis", "dcee-cl")


def load(folders: list[str]) -> pd.DataFrame:
    frames = [load_summaries(f) for f in folders]
    runs = pd.concat(frames, ignore_index=True)
    runs["agents"] = runs.get("agents", pd.Series(1, index=runs.index)).fillna(1).astype(int)
    return runs[runs.strategy.isin(PLANNERS)]


def rows(runs: pd.DataFrame) -> list[dict[str, object]]:
    """One row per planner and robot count over the (configuration, seed) pairs every count
    of that planner has: the columns of docs/results/team/metrics.csv."""
    out: list[dict[str, object]] = []
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
            acquired = int(g.source_acquired.sum())
            row: dict[str, object] = {"strategy": planner, "robots": int(k), "searches": n}
            rate = wilson(acquired, n)
            row |= dict(
                zip(
                    ("source_acquired_rate", "source_acquired_lo", "source_acquired_hi"),
                    rate,
                    strict=True,
                )
            )
            rmse = median_ci(g.final_rmse.to_numpy())
            row |= dict(
                zip(
                    ("median_final_rmse", "median_final_rmse_lo", "median_final_rmse_hi"),
                    rmse,
                    strict=True,
                )
            )
            for col, key in (
                ("time_to_rmse_1m", "time_to_1m"),
                ("time_to_rmse_0_5m", "time_to_0_5m"),
            ):
                t = censored_median_time(
                    g[col].to_numpy(dtype=float), g.budget.to_numpy(dtype=float)
                )
                row |= dict(zip((key, f"{key}_lo", f"{key}_hi"), t, strict=True))
            row["reached_1m"] = float(np.isfinite(g.time_to_rmse_1m.to_numpy(dtype=float)).mean())
            diff, p = math.nan, math.nan
            if k != 1 and len(base):
                d = (g.set_index(["scenario", "seed"]).final_rmse - base).dropna()
                diff = float(np.median(d))
                p = float(stats.wilcoxon(d).pvalue) if np.any(d != 0) else 1.0
            row["rmse_difference_to_one_robot"], row["wilcoxon_p"] = diff, p
            out.append(row)
    return out


def table(found: list[dict[str, object]]) -> str:
    lines = [
        "| planner | robots | paired searches | source acquired | median final RMSE (m) | "
        "median time to RMSE < 1 m (s) | to < 0.5 m (s) | final RMSE vs 1 robot: median "
        "difference, Wilcoxon p |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in found:
        n = r["searches"]
        fmt = [
            f"{r[k]:.0f} [{r[k + '_lo']:.0f}, {r[k + '_hi']:.0f}]".replace("inf", "> 900")
            for k in ("time_to_1m", "time_to_0_5m")
        ]
        d = r["rmse_difference_to_one_robot"]
        test = "—" if math.isnan(d) else f"{d:+.3f} m, p = {r['wilcoxon_p']:.2g}"
        acquired = round(r["source_acquired_rate"] * n)
        lines.append(
            f"| {r['strategy']} | {r['robots']} | {n} | {acquired}/{n} | "
            f"{r['median_final_rmse']:.2f} [{r['median_final_rmse_lo']:.2f}, "
            f"{r['median_final_rmse_hi']:.2f}] | {fmt[0]} | {fmt[1]} | {test} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", help="campaign folders (1, 2, 3 robots)")
    ap.add_argument("--out", help="a study folder to write metrics.csv and searches.csv into")
    args = ap.parse_args(argv)
    runs = load(args.folders)
    found = rows(runs)
    print(table(found))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        pd.DataFrame(found).to_csv(out / "metrics.csv", index=False)
        keep = ["scenario", "seed", "strategy", "agents", "source_acquired", "final_rmse"]
        keep += ["time_to_rmse_1m", "time_to_rmse_0_5m"]
        runs.reindex(columns=keep).sort_values(["strategy", "agents", "scenario", "seed"]).to_csv(
            out / "searches.csv", index=False
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
