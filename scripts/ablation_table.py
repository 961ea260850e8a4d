"""Markdown table of an ablation: each campaign folder against a reference one, searches paired
by (configuration, repeat) — the common random numbers make the pairing exact — with Wilson
intervals, exact McNemar tests and median final RMSE.

    .venv/bin/python scripts/ablation_table.py results/ablation/all results/ablation/*
"""

from __future__ import annotations

import sys
from pathlib import Path

from scipy.stats import binomtest

from dcee.analysis.report import load_campaign, wilson


def main() -> None:
    ref_dir, *others = (Path(a) for a in sys.argv[1:])
    _, ref = load_campaign(ref_dir)
    ref = ref.set_index(["scenario", "seed"])
    print(
        "| variant | n | source acquired | truth in 95% region | median final RMSE (m) | "
        "only reference / only variant | McNemar p |"
    )
    print("|---|---|---|---|---|---|---|")
    for d in [ref_dir, *others]:
        _, runs = load_campaign(d)
        runs = runs.set_index(["scenario", "seed"])
        keys = runs.index.intersection(ref.index)
        a = ref.loc[keys, "source_acquired"].astype(bool)
        b = runs.loc[keys, "source_acquired"].astype(bool)
        only_ref, only_var = int((a & ~b).sum()), int((b & ~a).sum())
        p = binomtest(only_ref, only_ref + only_var).pvalue if only_ref + only_var else 1.0
        r, lo, hi = wilson(int(b.sum()), len(b))
        c, clo, chi = wilson(int(runs.loc[keys, "truth_in_95"].astype(bool).sum()), len(b))
        print(
            f"| {d.name} | {len(b)} | {r:.0%} [{lo:.0%}, {hi:.0%}] "
            f"| {c:.0%} [{clo:.0%}, {chi:.0%}] "
            f"| {runs.loc[keys, 'final_rmse'].median():.2f} | {only_ref} / {only_var} | {p:.3f} |"
        )


if __name__ == "__main__":
    main()
