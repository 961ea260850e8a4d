"""Markdown table of the dual-control ablation (docs/dual-control.md): every strategy of the given
campaign folders on the hard configurations (K = 5, 7, 12: the plume points away from the start)
and the easy ones (K = 1, 3), with Wilson intervals, median final RMSE, the median time to
RMSE < 1 m (a search that never gets there counts as later than the budget, so the median is
censored, not conditional), and an exact McNemar test against a reference strategy on searches
paired by (configuration, repeat).

    .venv/bin/python scripts/dual_control_table.py results/dual-ablation [--reference dcee]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import binomtest

from dcee.analysis.report import load_campaign, wilson

HARD = (5, 7, 12)


def _median_time(times: pd.Series, budget: float) -> str:
    t = np.sort(times.fillna(np.inf).to_numpy())
    m = np.median(t)
    return f"> {budget:.0f}" if not np.isfinite(m) else f"{m:.0f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", type=Path)
    ap.add_argument("--reference", default="dcee")
    args = ap.parse_args()
    runs = pd.concat([load_campaign(d)[1] for d in args.campaigns], ignore_index=True)
    runs["k"] = runs["scenario"].str.split(":").str[1].astype(int)
    runs["hard"] = runs["k"].isin(HARD)
    budget = float(runs["budget"].max())
    ref = runs[runs["strategy"] == args.reference].set_index(["scenario", "seed"])
    print(
        "| strategy | hard: acquired | hard: median final RMSE (m) | easy: acquired | "
        "easy: median final RMSE (m) | median time to RMSE < 1 m, hard / easy (s) | "
        f"only {args.reference} / only this | McNemar p |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for strategy, g in runs.groupby("strategy", sort=True):
        cells = []
        for hard in (True, False):
            h = g[g["hard"] == hard]
            k, n = int(h["source_acquired"].sum()), len(h)
            _, lo, hi = wilson(k, n)
            cells += [f"{k}/{n} [{lo:.0%}, {hi:.0%}]", f"{h['final_rmse'].median():.2f}"]
        times = " / ".join(
            _median_time(g[g["hard"] == hard]["time_to_rmse_1m"], budget) for hard in (True, False)
        )
        paired = g.set_index(["scenario", "seed"])
        keys = paired.index.intersection(ref.index)
        a = ref.loc[keys, "source_acquired"].astype(bool)
        b = paired.loc[keys, "source_acquired"].astype(bool)
        only_ref, only_this = int((a & ~b).sum()), int((b & ~a).sum())
        p = binomtest(only_ref, only_ref + only_this).pvalue if only_ref + only_this else 1.0
        print(
            f"| {strategy} | {cells[0]} | {cells[1]} | {cells[2]} | {cells[3]} | {times} "
            f"| {only_ref} / {only_this} | {p:.3f} |"
        )


if __name__ == "__main__":
    main()
