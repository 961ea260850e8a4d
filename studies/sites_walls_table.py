"""The gas-round-buildings study's tables (issue 44): per site and estimator, acquisition, final
error, time to 1 m, the truth in the 95 % region, the longest wander in one 15 m region, the
decision time; and the wall-aware estimator paired with the wall-blind one search by search
(McNemar on acquisition, Wilcoxon on the final error).

    python studies/sites_walls_table.py aware=results/sites-walls-aware \\
        blind=results/sites-walls-blind --out docs/results/sites-walls
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import find_runs
from dcee.analysis.statistics import median_ci, wilson
from dcee.runs.metrics import search_wander

SAME_SEARCH = 1e-6
"""m: paired final errors closer than this are the same search (code changed elsewhere between
two campaigns moves a search's numbers by rounding, 1e-14 m)."""

WANDER_LIMIT = 120.0
"""s: issue 44's bar for the longest wander of any search of the study."""


def searches(label: str, folder: Path) -> pd.DataFrame:
    rows = []
    for run in find_runs(folder):
        s = json.loads((run / "summary.json").read_text())
        rows.append(
            {
                "estimator": label,
                "scenario": s["scenario"],
                "strategy": s["strategy"],
                "seed": s["seed"],
                "acquired": bool(s["source_acquired"]),
                "final_rmse": float(s["final_rmse"]),
                "time_to_1m": s.get("time_to_rmse_1m"),
                "truth_in_95": bool(s["truth_in_95"]),
                # recomputed from the record: the metric's definition, whatever the version
                "longest_wander": search_wander(
                    pd.read_parquet(run / "steps.parquet").to_dict("records"),
                    float(s.get("acquired_rmse", 3.0)),
                ),
                "explore_guard_fired": s.get("explore_guard_fired"),
                "wander_guard_fired": s.get("wander_guard_fired"),
                "decision_ms": 1e3 * float(s["decision_seconds_mean"]),
                "budget": float(s["budget"]),
                "commit": s["code"]["commit"],
            }
        )
    if not rows:
        raise SystemExit(f"sites_walls_table: error: {folder}: no searches")
    return pd.DataFrame(rows)


def summary(frame: pd.DataFrame) -> pd.DataFrame:
    out = []
    groups = [("all sites", frame), *frame.groupby("scenario")]
    for label, strategy in (
        frame[["estimator", "strategy"]].drop_duplicates().itertuples(index=False)
    ):
        for site, g in groups:
            g = g[(g.estimator == label) & (g.strategy == strategy)]
            if g.empty:
                continue
            rate, lo, hi = wilson(int(g.acquired.sum()), len(g))
            med, mlo, mhi = median_ci(g.final_rmse.to_numpy())
            t1 = pd.to_numeric(g.time_to_1m, errors="coerce")
            out.append(
                {
                    "scenario": site,
                    "estimator": label,
                    "strategy": strategy,
                    "searches": len(g),
                    "acquired": int(g.acquired.sum()),
                    "acquired_rate": rate,
                    "acquired_lo": lo,
                    "acquired_hi": hi,
                    "median_final_rmse": med,
                    "median_final_rmse_lo": mlo,
                    "median_final_rmse_hi": mhi,
                    "median_time_to_1m": float(t1.median()) if t1.notna().any() else np.nan,
                    "reached_1m": float(t1.notna().mean()),
                    "truth_in_95": float(g.truth_in_95.mean()),
                    "longest_wander": float(g.longest_wander.max()),
                    "wandered": int((g.longest_wander > WANDER_LIMIT).sum()),
                    "decision_ms": float(g.decision_ms.mean()),
                }
            )
    return pd.DataFrame(out)


def paired(frame: pd.DataFrame, a: str, b: str) -> pd.DataFrame:
    out = []
    keys = ["scenario", "strategy", "seed"]
    for strategy, site in (
        (st, si)
        for st in sorted(frame.strategy.unique())
        for si in [None, *sorted(frame.scenario.unique())]
    ):
        sub = frame[frame.strategy == strategy]
        sub = sub if site is None else sub[sub.scenario == site]
        m = sub[sub.estimator == a].merge(sub[sub.estimator == b], on=keys, suffixes=("_a", "_b"))
        if m.empty:
            continue
        only_a = int((m.acquired_a & ~m.acquired_b).sum())
        only_b = int((~m.acquired_a & m.acquired_b).sum())
        mcnemar = stats.binomtest(only_a, only_a + only_b).pvalue if only_a + only_b else 1.0
        diff = (m.final_rmse_a - m.final_rmse_b).to_numpy(copy=True)
        # a search the change left as it was, flown on other code, may differ in its last bits
        diff[np.abs(diff) < SAME_SEARCH] = 0.0
        wilcoxon = stats.wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
        out.append(
            {
                "scenario": site or "all sites",
                "strategy": strategy,
                "a": a,
                "b": b,
                "pairs": len(m),
                "changed": int(np.sum(diff != 0)),
                "acquired_a_only": only_a,
                "acquired_b_only": only_b,
                "mcnemar_p": float(mcnemar),
                "median_rmse_difference": float(np.median(diff)),
                "median_changed_difference": float(np.median(diff[diff != 0]))
                if np.any(diff != 0)
                else 0.0,
                "changed_wilcoxon_p": float(stats.wilcoxon(diff[diff != 0], method="exact").pvalue)
                if np.any(diff != 0)
                else 1.0,
                "wilcoxon_p": float(wilcoxon),
            }
        )
    return pd.DataFrame(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", help="LABEL=FOLDER, the wall-aware first")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    parts = []
    for item in args.campaigns:
        label, sep, folder = item.partition("=")
        if not sep or not Path(folder).is_dir():
            print(
                f"sites_walls_table: error: campaigns: {item!r} is not LABEL=FOLDER",
                file=sys.stderr,
            )
            return 2
        parts.append(searches(label, Path(folder)))
    frame = pd.concat(parts, ignore_index=True)
    args.out.mkdir(parents=True, exist_ok=True)
    frame.to_csv(args.out / "searches.csv", index=False)
    summary(frame).to_csv(args.out / "summary.csv", index=False)
    labels = list(dict.fromkeys(frame.estimator))
    pairs = [paired(frame, labels[0], other) for other in labels[1:]]
    if pairs:
        pd.concat(pairs, ignore_index=True).to_csv(args.out / "paired.csv", index=False)
    print(summary(frame).round(3).to_string(index=False))
    if pairs:
        print(pd.concat(pairs).round(4).to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
