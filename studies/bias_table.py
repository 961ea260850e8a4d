"""Where the estimate ends, relative to the wind, for the searches of one or more campaigns: a
Markdown table row per folder (the turbulent-plume sweeps of docs/scenarios.md).

    .venv/bin/python studies/bias_table.py results/sweep3/c0-20k results/sweep3/c0-n10-20k

Columns: searches, source acquired (Wilson 95 % interval), median final RMSE, median error of
the posterior mean, median posterior spread, the median error of the mean *downwind* (positive:
the estimate lies downwind of the source), its median absolute *crosswind* part, the median
vertical error, the share of searches whose truth lies inside the posterior's 95 % region, and
(with the calm model) the share of steps the calm model led.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import load_summaries
from dcee.scenarios import load_scenario


def wilson(k: int, n: int) -> tuple[float, float]:
    ci = stats.binomtest(k, n).proportion_ci(method="wilson")
    return ci.low, ci.high


def row(folder: str) -> str:
    out = []
    calm_steps = []
    for _, summary in load_summaries(folder).iterrows():
        theta = load_scenario(summary["scenario"]).truth_theta()
        err = np.asarray(summary["final_mean"]) - theta[:3]
        c, s = math.cos(theta[5]), math.sin(theta[5])
        downwind = -(err[0] * c + err[1] * s)  # the plume runs towards −(cos φ, sin φ)
        crosswind = -err[0] * s + err[1] * c
        out.append(
            (
                summary["source_acquired"],
                summary["final_rmse"],
                summary["final_mean_error"],
                summary["final_spread"],
                downwind,
                abs(crosswind),
                err[2],
                summary.get("truth_in_95", False),
            )
        )
        if "model" in summary and isinstance(summary["model"], str):
            steps = pd.read_parquet(Path(summary["run_dir"]) / "steps.parquet", columns=["model"])
            calm_steps.append(float((steps["model"] == "paper").mean()))
    a = np.array(out, dtype=float)
    n, k = len(a), int(a[:, 0].sum())
    lo, hi = wilson(k, n)
    med = np.median(a, axis=0)
    calm = f"{100 * np.mean(calm_steps):.1f} %" if calm_steps else "—"
    return (
        f"| {folder} | {n} | {k}/{n} ({100 * k / n:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]) | "
        f"{med[1]:.2f} | {med[2]:.2f} | {med[3]:.2f} | {med[4]:+.2f} | {med[5]:.2f} | "
        f"{med[6]:+.2f} | {100 * a[:, 7].mean():.0f} % | {calm} |"
    )


def main() -> None:
    print(
        "| campaign | n | source acquired | median final RMSE (m) | error of the mean (m) | "
        "spread (m) | downwind (m) | crosswind (m) | vertical (m) | truth in 95 % | calm model "
        "led |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for folder in sys.argv[1:]:
        print(row(folder))


if __name__ == "__main__":
    main()
