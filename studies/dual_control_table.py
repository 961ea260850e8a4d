"""Markdown table of the dual-control ablation (docs/dual-control.md): every strategy of the given
campaign folders on the hard configurations (K = 5, 7, 12: the plume points away from the start)
and the easy ones (K = 1, 3), with Wilson intervals, median final RMSE, the median time to
RMSE < 1 m (a search that never gets there counts as later than the budget, so the median is
censored, not conditional), and an exact McNemar test against a reference strategy on searches
paired by (configuration, repeat).

    .venv/bin/python studies/dual_control_table.py results/dual-ablation [--reference dcee]
    .venv/bin/python studies/dual_control_table.py results/paper-source-cl --study \
        --reference infotaxis

``--study`` pools every configuration instead: acquired with its Wilson interval, median final
RMSE and median time to RMSE < 1 m (censored at the budget) with distribution-free 95 %
order-statistic intervals, and the paired McNemar test.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import binomtest, wilcoxon

from dcee.analysis.report import load_campaign
from dcee.analysis.statistics import median_order_statistic_ranks, wilson

HARD = (5, 7, 12)


def _median_time(times: pd.Series, budget: float) -> str:
    """Median time to RMSE < 1 m, a search that never got there counting as later than the
    budget (censored)."""
    m = float(np.median(times.fillna(np.inf).to_numpy()))
    return f"> {budget:.0f}" if not np.isfinite(m) else f"{m:.0f}"


def _median_with_interval(x: np.ndarray, budget: float, digits: int) -> str:
    """Median [95 % order-statistic interval]; inf (never reached) sorts last, shown as
    "> budget"."""
    x = np.sort(np.asarray(x, dtype=float))
    lo, hi = median_order_statistic_ranks(len(x))

    def fmt(v: float) -> str:
        return f"> {budget:.0f}" if not np.isfinite(v) else f"{v:.{digits}f}"

    return f"{fmt(float(np.median(x)))} [{fmt(x[lo])}, {fmt(x[hi])}]"


def _mcnemar(ref: pd.DataFrame, g: pd.DataFrame) -> tuple[int, int, float]:
    paired = g.set_index(["scenario", "seed"])
    keys = paired.index.intersection(ref.index)
    a = ref.loc[keys, "source_acquired"].astype(bool)
    b = paired.loc[keys, "source_acquired"].astype(bool)
    only_ref, only_this = int((a & ~b).sum()), int((b & ~a).sum())
    p = binomtest(only_ref, only_ref + only_this).pvalue if only_ref + only_this else 1.0
    return only_ref, only_this, p


def study(runs: pd.DataFrame, reference: str, budget: float) -> None:
    ref = runs[runs["strategy"] == reference].set_index(["scenario", "seed"])
    print(
        "| strategy | n | source acquired | median final RMSE (m) | "
        f"median time to RMSE < 1 m (s) | only {reference} / only this | McNemar p | "
        f"paired final RMSE − {reference}: median, Wilcoxon p |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for strategy, g in runs.groupby("strategy", sort=True):
        k, n = int(g["source_acquired"].sum()), len(g)
        r, lo, hi = wilson(k, n)
        rmse = _median_with_interval(g["final_rmse"], budget, 2)
        t1 = _median_with_interval(g["time_to_rmse_1m"].fillna(np.inf), budget, 0)
        only_ref, only_this, p = _mcnemar(ref, g)
        paired = g.set_index(["scenario", "seed"])["final_rmse"]
        keys = paired.index.intersection(ref.index)
        diff = (paired.loc[keys] - ref.loc[keys, "final_rmse"]).to_numpy()
        w = wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
        print(
            f"| {strategy} | {n} | {r:.1%} [{lo:.1%}, {hi:.1%}] | {rmse} | {t1} "
            f"| {only_ref} / {only_this} | {p:.3f} | {np.median(diff):+.3f} m, {w:.1g} |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", type=Path)
    ap.add_argument("--reference", default="dcee")
    ap.add_argument("--study", action="store_true", help="pool every configuration")
    args = ap.parse_args()
    runs = pd.concat([load_campaign(d)[1] for d in args.campaigns], ignore_index=True)
    budget = float(runs["budget"].max())
    if args.study:
        study(runs, args.reference, budget)
        return
    runs["k"] = runs["scenario"].str.split(":").str[1].astype(int)
    runs["hard"] = runs["k"].isin(HARD)
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
        only_ref, only_this, p = _mcnemar(ref, g)
        print(
            f"| {strategy} | {cells[0]} | {cells[1]} | {cells[2]} | {cells[3]} | {times} "
            f"| {only_ref} / {only_this} | {p:.3f} |"
        )


if __name__ == "__main__":
    main()
