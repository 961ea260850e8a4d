"""The lab-experiment table (issue 15): the paper's indoor search in simulation with the
unicycle robot against the idealised grid agent, per start and planner, paired by seed.

    .venv/bin/python studies/lab_table.py results/lab-robot results/lab-grid \
        [results/lab-robot-filament]

prints the per-start table (robot against grid, paired) and a compact one pooled over both
starts with one column group per campaign given.

"Source acquired" is the lab scenarios' criterion (final RMSE < 0.5 m). Rates carry Wilson 95 %
intervals, medians distribution-free intervals, times Kaplan-Meier medians (searches that never
get there censored at the 450 s budget); robot vs grid: exact McNemar on acquired and Wilcoxon
signed-rank on the final RMSE over the same (start, seed).
"""

from __future__ import annotations

import sys

import numpy as np
from scipy import stats

from dcee.analysis.results import load_summaries
from dcee.analysis.statistics import censored_median_time, median_ci, wilson


def table(robot_dir: str, grid_dir: str) -> str:
    robot, grid = load_summaries(robot_dir), load_summaries(grid_dir)
    lines = [
        "| start | planner | robot | n | source acquired (RMSE < 0.5 m) | median final RMSE (m) "
        "| time to RMSE < 0.5 m (s) | readings | robot vs grid: acquired (only grid / only "
        "robot, McNemar p), final RMSE (median diff., Wilcoxon p) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scenario in sorted(robot.scenario.unique()):
        for planner in sorted(robot.strategy.unique()):
            rows = {}
            for name, runs in (("unicycle", robot), ("grid", grid)):
                g = runs[(runs.scenario == scenario) & (runs.strategy == planner)]
                rows[name] = g.set_index("seed").sort_index()
            common = rows["unicycle"].index.intersection(rows["grid"].index)
            for name in ("unicycle", "grid"):
                g = rows[name].loc[common]
                n = len(g)
                if n == 0:
                    continue
                k = int(g.source_acquired.sum())
                rate = wilson(k, n)
                med = median_ci(g.final_rmse.to_numpy())
                t = censored_median_time(
                    g.time_to_rmse_0_5m.to_numpy(dtype=float), g.budget.to_numpy(dtype=float)
                )
                tfmt = f"{t[0]:.0f} [{t[1]:.0f}, {t[2]:.0f}]".replace("inf", "> 450")
                test = "—"
                if name == "unicycle":
                    a = rows["grid"].loc[common]
                    only_grid = int((a.source_acquired & ~g.source_acquired).sum())
                    only_robot = int((~a.source_acquired & g.source_acquired).sum())
                    b = only_grid + only_robot
                    p_mc = stats.binomtest(only_grid, b).pvalue if b else 1.0
                    diff = (g.final_rmse - a.final_rmse).dropna()
                    p_w = stats.wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
                    test = (
                        f"{only_grid} / {only_robot}, p = {p_mc:.2g}; "
                        f"{np.median(diff):+.3f} m, p = {p_w:.2g}"
                    )
                lines.append(
                    f"| {scenario.removeprefix('lab:')} | {planner} | {name} | {n} | "
                    f"{k}/{n} ({100 * rate[0]:.0f} [{100 * rate[1]:.0f}, {100 * rate[2]:.0f}]%) | "
                    f"{med[0]:.2f} [{med[1]:.2f}, {med[2]:.2f}] | {tfmt} | "
                    f"{int(np.median(g.readings))} | {test} |"
                )
    return "\n".join(lines)


def pooled(folders: list[str]) -> str:
    """Per planner, both starts pooled (20 searches), one column group per campaign."""
    runs = [load_summaries(f) for f in folders]
    head = "| planner | " + " | ".join(
        f"{f.rstrip('/').split('/')[-1]}: acquired, median RMSE (m), time to 0.5 m (s), readings"
        for f in folders
    )
    lines = [head + " |", "|---|" + "---|" * len(folders)]
    for planner in sorted(runs[0].strategy.unique()):
        cells = []
        for r in runs:
            g = r[r.strategy == planner]
            if g.empty:
                cells.append("—")
                continue
            k, n = int(g.source_acquired.sum()), len(g)
            t = censored_median_time(
                g.time_to_rmse_0_5m.to_numpy(dtype=float), g.budget.to_numpy(dtype=float)
            )
            tfmt = f"{t[0]:.0f}".replace("inf", "> 450")
            cells.append(
                f"{k}/{n}, {np.median(g.final_rmse):.2f}, {tfmt}, {int(np.median(g.readings))}"
            )
        lines.append(f"| {planner} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table(sys.argv[1], sys.argv[2]))
    print()
    print(pooled(sys.argv[1:]))
