"""The statistics of a report: per-strategy metrics with 95% confidence intervals, per-configuration
counts, paired comparisons and median curves, computed from the summaries of a folder of
saved searches (one row per search).

Statistics (all from scipy.stats, all 95%):

* rates: Wilson score intervals (``binomtest(...).proportion_ci``), exactly 0 and 1 at the ends;
* medians: the distribution-free order-statistic interval (``quantile_test``);
* means: a normal interval (mean ± 1.96 s/√n);
* times to an RMSE level: a search that never got there is *censored* at its budget, not
  dropped, so a planner that rarely arrives cannot look fast. The median time is the
  Kaplan–Meier estimate (``ecdf`` of ``CensoredData``) with the interval where the log-log
  confidence band of the CDF crosses 1/2; "> budget" when fewer than half arrive;
* paired comparisons between every two strategies on their common (configuration, seed)
  searches, which share the truth's random numbers: the exact McNemar test on source acquired
  (a two-sided binomial test on the discordant pairs) and the Wilcoxon signed-rank test on the
  final RMSE;
* the median RMSE curve at every time step: the exact order-statistic band
  (:func:`median_order_statistic_ranks`).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats

from dcee.runs.metrics import WANDER_SECONDS

Z95 = 1.959963984540054


def wilson(k: int, n: int) -> tuple[float, float, float]:
    """(rate, low, high) with the Wilson score interval at 95% (scipy), clamped so that
    low ≤ rate ≤ high holds exactly (round-off left it 1e-17 inside at 0/n and n/n)."""
    if n == 0:
        return (math.nan, math.nan, math.nan)
    p = k / n
    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=0.95, method="wilson")
    return (p, min(float(ci.low), p), max(float(ci.high), p))


def mean_ci(x: np.ndarray) -> tuple[float, float, float]:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return (math.nan, math.nan, math.nan)
    m = float(x.mean())
    if len(x) == 1:
        return (m, math.nan, math.nan)
    half = Z95 * float(x.std(ddof=1)) / math.sqrt(len(x))
    return (m, m - half, m + half)


def median_ci(x: np.ndarray) -> tuple[float, float, float]:
    """(median, low, high): the sample median with its distribution-free 95% interval from
    order statistics (``scipy.stats.quantile_test``); NaN bounds below 6 values, where no pair of
    order statistics covers the median with 95% probability."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return (math.nan, math.nan, math.nan)
    med = float(np.median(x))
    ci = stats.quantile_test(x, q=med, p=0.5).confidence_interval(0.95)
    lo, hi = float(ci.low), float(ci.high)
    return (med, lo if np.isfinite(lo) else math.nan, hi if np.isfinite(hi) else math.nan)


def censored_median_time(times: np.ndarray, budgets: np.ndarray) -> tuple[float, float, float]:
    """(median, low, high) time to an event that some searches never reach (NaN in ``times``):
    those are right-censored at their budget. Kaplan–Meier via ``scipy.stats.ecdf``; the
    interval is where the 95% log-log band of the CDF crosses 1/2. ``inf`` means "later than
    the budget" (fewer than half, or for the bound too few, got there)."""
    t = np.asarray(times, dtype=float)
    b = np.asarray(budgets, dtype=float)
    reached = np.isfinite(t)
    if len(t) == 0:
        return (math.nan, math.nan, math.nan)
    if not reached.any():
        return (math.inf, math.inf, math.inf)
    data = stats.CensoredData(uncensored=t[reached], right=b[~reached])
    cdf = stats.ecdf(data).cdf
    grid = cdf.quantiles
    with warnings.catch_warnings():  # undefined at CDF 0 and 1 (NaN there): expected
        warnings.simplefilter("ignore", RuntimeWarning)
        lo_band, hi_band = cdf.confidence_interval(0.95, method="log-log")

    def crossing(values: np.ndarray) -> float:
        hit = np.flatnonzero(np.nan_to_num(values, nan=0.0) >= 0.5 - 1e-12)
        return float(grid[hit[0]]) if len(hit) and grid[hit[0]] < b.max() else math.inf

    return (
        crossing(cdf.evaluate(grid)),
        crossing(hi_band.evaluate(grid)),
        crossing(lo_band.evaluate(grid)),
    )


def metrics_table(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per strategy: every metric with its 95% interval."""
    out = []
    for strategy, g in runs.groupby("strategy", sort=True):
        n = len(g)
        row: dict[str, Any] = {
            "strategy": strategy,
            "searches": n,
            "budget": float(g["budget"].max()),
        }
        for key, col in (
            ("source_acquired", "source_acquired"),
            ("plume_acquired", "plume_acquired"),
            ("truth_in_95", "truth_in_95"),
        ):
            if col not in g or g[col].isna().any():  # campaigns from before calibration
                row.update({f"{key}_rate": math.nan, f"{key}_lo": math.nan, f"{key}_hi": math.nan})
                continue
            r, lo, hi = wilson(int(g[col].astype(bool).sum()), n)
            row.update({f"{key}_rate": r, f"{key}_lo": lo, f"{key}_hi": hi})
        for key, fn in (("mean", mean_ci), ("median", median_ci)):
            v, lo, hi = fn(g["final_rmse"].to_numpy())
            row.update(
                {f"{key}_final_rmse": v, f"{key}_final_rmse_lo": lo, f"{key}_final_rmse_hi": hi}
            )
        for level, col in (("1m", "time_to_rmse_1m"), ("0_5m", "time_to_rmse_0_5m")):
            t = pd.to_numeric(g[col], errors="coerce").to_numpy()
            v, lo, hi = censored_median_time(t, g["budget"].to_numpy(dtype=float))
            row.update(
                {
                    f"time_to_{level}": v,
                    f"time_to_{level}_lo": lo,
                    f"time_to_{level}_hi": hi,
                    f"reached_{level}": float(np.isfinite(t).mean()),
                }
            )
        # the longest stall of any search (s), and how many stalled > STALL_SECONDS; NaN for
        # searches saved before the metric existed
        stall = pd.to_numeric(g.get("longest_stall", pd.Series(np.nan, g.index)), errors="coerce")
        row["longest_stall"] = float(stall.max()) if stall.notna().all() else math.nan
        row["stalled"] = int((stall > STALL_SECONDS).sum()) if stall.notna().all() else -1
        # and the longest wander in one 15 m region (issue 44), how many wandered > 120 s
        wander = pd.to_numeric(g.get("longest_wander", pd.Series(np.nan, g.index)), errors="coerce")
        row["longest_wander"] = float(wander.max()) if wander.notna().all() else math.nan
        row["wandered"] = int((wander > WANDER_SECONDS).sum()) if wander.notna().all() else -1
        # the count of releases unknown (issue 45): how often it came out right, and the OSPA
        # distance between the estimated and the true set; NaN for other campaigns
        if "count_correct" in g and g["count_correct"].notna().all():
            r, lo, hi = wilson(int(g["count_correct"].astype(bool).sum()), n)
            v, olo, ohi = median_ci(g["final_ospa"].to_numpy(dtype=float))
            row.update({"count_correct_rate": r, "count_correct_lo": lo, "count_correct_hi": hi})
            row.update({"median_ospa": v, "median_ospa_lo": olo, "median_ospa_hi": ohi})
        for key, col in (("path_length", "path_length"), ("decision_ms", "decision_seconds_mean")):
            scale = 1e3 if key == "decision_ms" else 1.0
            v, lo, hi = mean_ci(g[col].to_numpy() * scale)
            row.update({key: v, f"{key}_lo": lo, f"{key}_hi": hi})
        out.append(row)
    return pd.DataFrame(out)


def per_configuration_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Searches that acquired the source, per configuration (rows, in suite order) and strategy
    (columns), as "k/n" strings: where a strategy fails, which the pooled rates hide."""
    counts = runs.groupby(["scenario", "strategy"])["source_acquired"].agg(["sum", "count"])
    cells = counts["sum"].astype(int).astype(str) + "/" + counts["count"].astype(str)
    table = cells.unstack("strategy").fillna("—")
    table = table.loc[sorted(table.index, key=config_key)]
    table.index.name = "configuration"
    return table


STALL_SECONDS = 60.0
"""s: a search that stays within one step of one position longer than this before it has the
source is counted as stalled (the issue-28 bar)."""


def median_order_statistic_ranks(n: int) -> tuple[int, int]:
    """0-based ranks (lo, hi) of the sorted sample whose interval covers the median with at
    least 95% probability (n >= 6), for any continuous distribution: the order statistics at the
    Binomial(n, 1/2) 2.5% and 97.5% quantiles. Exact and distribution-free, and cheap enough to
    evaluate at every time step of a curve (a bootstrap would not be)."""
    from scipy.stats import binom

    if n < 1:
        raise ValueError("n must be at least 1")
    # X_(l) <= median <= X_(n-1-l) (0-based ranks) unless at most l samples fall on one side:
    # coverage 1 - 2 P(B <= l), B ~ Binomial(n, 1/2). Take the largest l with coverage >= 95%;
    # below n = 6 no l reaches 95% and the band is the sample range.
    lo = 0
    while lo + 1 <= (n - 1) // 2 and binom.cdf(lo + 1, n, 0.5) <= 0.025:
        lo += 1
    return lo, n - 1 - lo


def rmse_over_time(runs: pd.DataFrame, step: float = 10.0) -> dict[str, pd.DataFrame]:
    """Per strategy, on a common time grid: mean RMSE over searches with a 95% normal band
    (lo, hi; lo no lower than the smallest RMSE), and median RMSE with a 95% distribution-free
    order-statistic band (median_lo, median_hi). A search that ended early keeps its last value
    (its estimate no longer changes). The mean is the paper's statistic; the median shows the
    typical search, which the mean hides when a few searches are lost ~20 m from the source."""
    budget = float(runs["budget"].max())
    grid = np.arange(0.0, budget + 1e-9, step)
    out = {}
    for strategy, g in runs.groupby("strategy", sort=True):
        curves = []
        for run_dir in g["run_dir"]:
            steps = pd.read_parquet(Path(run_dir) / "steps.parquet", columns=["time", "rmse"])
            t, r = steps["time"].to_numpy(), steps["rmse"].to_numpy()
            idx = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, len(t) - 1)
            curves.append(r[idx])
        c = np.array(curves)
        mean = c.mean(axis=0)
        half = (
            Z95 * c.std(axis=0, ddof=1) / math.sqrt(len(c)) if len(c) > 1 else np.zeros_like(mean)
        )
        ordered = np.sort(c, axis=0)
        rank_lo, rank_hi = median_order_statistic_ranks(len(c))
        out[strategy] = pd.DataFrame(
            {
                "time": grid,
                "mean": mean,
                # the normal interval can fall below every search's RMSE for small n (a dip
                # to 1e-2 on the log axis); the mean cannot, so the band stops at the minimum
                "lo": np.maximum(mean - half, c.min(axis=0)),
                "hi": mean + half,
                "median": np.median(c, axis=0),
                "median_lo": ordered[rank_lo],
                "median_hi": ordered[rank_hi],
            }
        )
    return out


def pairwise_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Every pair of strategies on their common (configuration, seed) searches: source acquired
    by A only / by B only with the exact McNemar p-value, and the median paired difference of
    final RMSE (A − B) with the Wilcoxon signed-rank p-value."""
    keyed = runs.drop_duplicates(["scenario", "seed", "strategy"]).set_index(
        ["scenario", "seed", "strategy"]
    )
    strategies = sorted(runs["strategy"].unique())
    out = []
    for i, a in enumerate(strategies):
        for b in strategies[i + 1 :]:
            ka = keyed.xs(a, level="strategy")
            kb = keyed.xs(b, level="strategy")
            common = ka.index.intersection(kb.index)
            if len(common) == 0:
                continue
            sa = ka.loc[common, "source_acquired"].astype(bool).to_numpy()
            sb = kb.loc[common, "source_acquired"].astype(bool).to_numpy()
            only_a, only_b = int((sa & ~sb).sum()), int((~sa & sb).sum())
            mcnemar = (
                stats.binomtest(only_a, only_a + only_b, 0.5).pvalue if only_a + only_b else 1.0
            )
            diff = ka.loc[common, "final_rmse"].to_numpy(float) - kb.loc[common, "final_rmse"]
            diff = np.asarray(diff, dtype=float)
            wilcoxon = (
                float(stats.wilcoxon(diff).pvalue) if np.any(diff != 0) and len(diff) > 1 else 1.0
            )
            out.append(
                {
                    "a": a,
                    "b": b,
                    "pairs": len(common),
                    "acquired_a_only": only_a,
                    "acquired_b_only": only_b,
                    "mcnemar_p": float(mcnemar),
                    "median_rmse_difference": float(np.median(diff)),
                    "wilcoxon_p": wilcoxon,
                }
            )
    return pd.DataFrame(out)


def config_key(name: str) -> tuple:
    """Sort key of a configuration name: ``paper:2`` before ``paper:10``, an edited
    ``paper:2+3fa2c1d0`` right after ``paper:2``."""
    head, _, tail = name.partition(":")
    number, _, rest = tail.partition("+")
    return (head, int(number) if number.isdigit() else -1, number, rest)
