"""Markdown table of an ablation: each campaign folder against a reference one, searches paired
by (configuration, repeat) — the common random numbers make the pairing exact — with Wilson
intervals, exact McNemar tests, median final RMSE, the paired time to RMSE < 1 m (Wilcoxon) and
the longest stall (summary ``longest_stall``: the longest time within one step of one position
before the source was acquired; how many searches stalled > 60 s).

A folder may hold several strategies: ``DIR=STRATEGY`` picks one (the strategy spec as stored,
e.g. ``results/filament-calm=infotaxis``); a folder without ``=`` must hold just one. A stored
study's ``searches.csv`` (written by ``studies/collect_metrics.py``) stands in for a folder
whose searches are gone: ``docs/results/held-out-today/searches.csv=infotaxis``; ``KEY:VALUE``
after the strategy picks rows of a tagged study (``…/searches.csv=dcee-cl:truth_model:puffs``).

    .venv/bin/python studies/ablation_table.py results/ablation/all results/ablation/*
    .venv/bin/python studies/ablation_table.py results/paper-full-cl2=infotaxis \\
        results/paper-full-info-loc results/paper-full-cl2=dcee-cl
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import NoReturn

import pandas as pd
from scipy.stats import binomtest, wilcoxon

from dcee.analysis.report import load_campaign
from dcee.analysis.statistics import wilson


def _fail(message: str) -> NoReturn:
    """One line on stderr and exit code 2, as the dcee commands do."""
    print(f"ablation_table: {message}", file=sys.stderr)
    raise SystemExit(2)


def _runs(arg: str) -> tuple[str, pd.DataFrame]:
    folder, _, strategy = arg.partition("=")
    path = Path(folder)
    tags: list[str] = []
    if path.suffix == ".csv":  # STRATEGY[:KEY:VALUE...]; a folder's spec keeps its colons
        strategy, *tags = strategy.split(":")
        if not path.is_file():
            _fail(f"{path}: no such stored study (studies/collect_metrics.py)")
        runs = pd.read_csv(path)
        for key, value in zip(tags[::2], tags[1::2], strict=True):
            try:  # collect_metrics stores a numeric tag as a number
                runs = runs[pd.to_numeric(runs[key], errors="coerce") == float(value)]
            except ValueError:
                runs = runs[runs[key].astype(str) == value]
        name = f"{path.parent.name}{'/' + ':'.join(tags) if tags else ''}"
    else:
        _, runs = load_campaign(path)
        name = path.name
    if strategy:
        runs = runs[runs["strategy"] == strategy]
    if runs.empty:
        _fail(f"{arg}: no search matches")
    if runs["strategy"].nunique() != 1:
        _fail(f"{arg}: several strategies; name one with DIR=STRATEGY")
    if runs.duplicated(["scenario", "seed"]).any():
        _fail(f"{arg}: several studies' rows; pick one with :KEY:VALUE")
    label = f"{name} ({runs['strategy'].iloc[0]})"
    return label, runs.set_index(["scenario", "seed"])


def compare(ref_arg: str, others: list[str]) -> pd.DataFrame:
    """One row per variant (the reference first), each paired with the reference on the
    configurations and seeds both flew."""
    _, ref = _runs(ref_arg)
    rows = []
    for arg in [ref_arg, *others]:
        label, runs = _runs(arg)
        keys = runs.index.intersection(ref.index)
        a = ref.loc[keys, "source_acquired"].astype(bool)
        b = runs.loc[keys, "source_acquired"].astype(bool)
        only_ref, only_var = int((a & ~b).sum()), int((b & ~a).sum())
        t_ref = ref.loc[keys, "time_to_rmse_1m"].astype(float)
        t_var = runs.loc[keys, "time_to_rmse_1m"].astype(float)
        both = t_ref.notna() & t_var.notna()
        diff = (t_var - t_ref)[both]
        changed = both.sum() > 0 and (diff != 0).any()
        stall = pd.to_numeric(runs.loc[keys].get("longest_stall"), errors="coerce")
        rmse_ref, rmse_var = ref.loc[keys, "final_rmse"], runs.loc[keys, "final_rmse"]
        rmse_changed = (rmse_var != rmse_ref).any()
        rows.append(
            {
                "variant": label,
                "strategy": runs["strategy"].iloc[0],
                "pairs": len(keys),
                "acquired": int(b.sum()),
                "truth_in_95": int(runs.loc[keys, "truth_in_95"].astype(bool).sum()),
                "median_final_rmse": float(rmse_var.median()),
                "acquired_reference_only": only_ref,
                "acquired_variant_only": only_var,
                "mcnemar_p": (
                    binomtest(only_ref, only_ref + only_var).pvalue if only_ref + only_var else 1.0
                ),
                # the median over every search, one that never got there later than all
                "time_to_1m": float(t_var.fillna(float("inf")).median()),
                "reached_1m": int(t_var.notna().sum()),
                "time_to_1m_difference": float(diff.median()) if changed else float("nan"),
                "time_wilcoxon_p": (
                    wilcoxon(t_var[both], t_ref[both]).pvalue if changed else float("nan")
                ),
                "final_rmse_difference": float((rmse_var - rmse_ref).median()),
                "rmse_wilcoxon_p": (
                    wilcoxon(rmse_var, rmse_ref).pvalue if rmse_changed else float("nan")
                ),
                "longest_stall": float(stall.max()) if stall.notna().all() else float("nan"),
                "stalled": int((stall > 60).sum()) if stall.notna().all() else -1,
            }
        )
    return pd.DataFrame(rows)


def markdown(table: pd.DataFrame) -> str:
    lines = [
        "| variant | n | source acquired | truth in 95% region | median final RMSE (m) | "
        "only reference / only variant | McNemar p | median time to RMSE < 1 m (s) | "
        "paired difference to the reference (s), Wilcoxon p | longest stall (s) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for _, t in table.iterrows():
        n = int(t["pairs"])
        r, lo, hi = wilson(int(t["acquired"]), n)
        c, clo, chi = wilson(int(t["truth_in_95"]), n)
        paired = "—"
        if not pd.isna(t["time_to_1m_difference"]):
            paired = f"{t['time_to_1m_difference']:+.0f} (p = {t['time_wilcoxon_p']:.2g})"
        got = int(t["reached_1m"])
        reached = f"{t['time_to_1m']:.0f} ({got}/{n} got there)" if got else "— (none got there)"
        stalls = "n/a" if t["stalled"] < 0 else f"{t['longest_stall']:.0f} ({t['stalled']} > 60 s)"
        lines.append(
            f"| {t['variant']} | {n} | {int(t['acquired'])}/{n}, {r:.1%} [{lo:.1%}, {hi:.1%}] "
            f"| {c:.0%} [{clo:.0%}, {chi:.0%}] "
            f"| {t['median_final_rmse']:.2f} | {t['acquired_reference_only']} / "
            f"{t['acquired_variant_only']} | {t['mcnemar_p']:.3f} "
            f"| {reached} | {paired} | {stalls} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference", help="DIR[=STRATEGY] or STUDY/searches.csv=STRATEGY[:KEY:VALUE]")
    ap.add_argument("variants", nargs="*")
    ap.add_argument("--csv", default=None, help="also write the rows to this file")
    ap.add_argument("--tag", action="append", default=[], help="KEY=VALUE column for the CSV")
    args = ap.parse_args(argv)
    table = compare(args.reference, args.variants)
    print(markdown(table))
    if args.csv:
        for i, item in enumerate(args.tag):
            key, _, value = item.partition("=")
            table.insert(i, key, value)
        out = Path(args.csv)
        table.to_csv(out, mode="a", header=not out.exists(), index=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
