"""Markdown table of an ablation: each campaign folder against a reference one, searches paired
by (configuration, repeat) — the common random numbers make the pairing exact — with Wilson
intervals, exact McNemar tests, median final RMSE, the paired time to RMSE < 1 m (Wilcoxon) and
the longest stall (summary ``longest_stall``: the longest time within one step of one position
before the source was acquired; how many searches stalled > 60 s).

A folder may hold several strategies: ``DIR=STRATEGY`` picks one (the strategy spec as stored,
e.g. ``results/filament-calm=infotaxis``); a folder without ``=`` must hold just one.

    .venv/bin/python studies/ablation_table.py results/ablation/all results/ablation/*
    .venv/bin/python studies/ablation_table.py results/paper-full-cl2=infotaxis \\
        results/paper-full-info-loc results/paper-full-cl2=dcee-cl
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd
from scipy.stats import binomtest, wilcoxon

from dcee.analysis.report import load_campaign
from dcee.analysis.statistics import wilson


def _runs(arg: str) -> tuple[str, pd.DataFrame]:
    folder, _, strategy = arg.partition("=")
    _, runs = load_campaign(Path(folder))
    if strategy:
        runs = runs[runs["strategy"] == strategy]
    if runs.empty or runs["strategy"].nunique() != 1:
        sys.exit(f"ablation_table: {arg}: name one strategy with DIR=STRATEGY")
    label = f"{Path(folder).name} ({runs['strategy'].iloc[0]})"
    return label, runs.set_index(["scenario", "seed"])


def main() -> None:
    ref_arg, *others = sys.argv[1:]
    _, ref = _runs(ref_arg)
    print(
        "| variant | n | source acquired | truth in 95% region | median final RMSE (m) | "
        "only reference / only variant | McNemar p | median time to RMSE < 1 m (s) | "
        "paired difference to the reference (s), Wilcoxon p | longest stall (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for arg in [ref_arg, *others]:
        label, runs = _runs(arg)
        keys = runs.index.intersection(ref.index)
        a = ref.loc[keys, "source_acquired"].astype(bool)
        b = runs.loc[keys, "source_acquired"].astype(bool)
        only_ref, only_var = int((a & ~b).sum()), int((b & ~a).sum())
        p = binomtest(only_ref, only_ref + only_var).pvalue if only_ref + only_var else 1.0
        r, lo, hi = wilson(int(b.sum()), len(b))
        c, clo, chi = wilson(int(runs.loc[keys, "truth_in_95"].astype(bool).sum()), len(b))
        t_ref = ref.loc[keys, "time_to_rmse_1m"].astype(float)
        t_var = runs.loc[keys, "time_to_rmse_1m"].astype(float)
        both = t_ref.notna() & t_var.notna()
        diff = (t_var - t_ref)[both]
        paired = "—"
        if both.sum() > 0 and (diff != 0).any():
            paired = f"{diff.median():+.0f} (p = {wilcoxon(t_var[both], t_ref[both]).pvalue:.2g})"
        got = int(t_var.notna().sum())
        # the median over every search, one that never got there counting as later than all
        median = t_var.fillna(float("inf")).median()
        reached = f"{median:.0f} ({got}/{len(t_var)} got there)" if got else "— (none got there)"
        stall = pd.to_numeric(runs.loc[keys].get("longest_stall"), errors="coerce")
        stalls = "n/a"
        if stall.notna().all():
            stalls = f"{stall.max():.0f} ({int((stall > 60).sum())} > 60 s)"
        print(
            f"| {label} | {len(b)} | {int(b.sum())}/{len(b)}, {r:.1%} [{lo:.1%}, {hi:.1%}] "
            f"| {c:.0%} [{clo:.0%}, {chi:.0%}] "
            f"| {runs.loc[keys, 'final_rmse'].median():.2f} | {only_ref} / {only_var} | {p:.3f} "
            f"| {reached} | {paired} | {stalls} |"
        )


if __name__ == "__main__":
    main()
