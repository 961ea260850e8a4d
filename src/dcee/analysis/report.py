"""Report of a campaign or of any folder of saved searches: per-strategy metrics with 95%
confidence intervals, paired comparisons, the paper's figures, and a self-contained HTML page
(figures embedded) plus the tables as CSV and Markdown.

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

import base64
import io
import json
import math
import warnings
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from scipy import stats

from dcee.analysis.results import describe_folder, load_config, load_summaries
from dcee.io import write_atomic

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


def load_campaign(folder: Path) -> tuple[dict[str, Any], pd.DataFrame]:
    """(campaign.json or a description of the loose searches, one row per finished search)."""
    return describe_folder(folder), load_summaries(folder)


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
        for key, col in (("path_length", "path_length"), ("decision_ms", "decision_seconds_mean")):
            scale = 1e3 if key == "decision_ms" else 1.0
            v, lo, hi = mean_ci(g[col].to_numpy() * scale)
            row.update({key: v, f"{key}_lo": lo, f"{key}_hi": hi})
        out.append(row)
    return pd.DataFrame(out)


def model_selection_markdown(runs: pd.DataFrame) -> str | None:
    """Which reading model each strategy's searches ended with, when the filter selected between
    several (the fluctuation likelihood with its calm model): per strategy and model the searches
    that ended with it (share, Wilson 95 % interval), the median final probability of the
    selected model and the mean number of switches. None when no search selected a model."""
    if "model" not in runs or runs["model"].isna().all():
        return None
    lines = [
        "| strategy | final reading model | searches | median P(model) at the end | "
        "mean switches |",
        "|---|---|---|---|---|",
    ]
    for strategy, g in runs.dropna(subset=["model"]).groupby("strategy", sort=True):
        n = len(g)
        for model, h in g.groupby("model", sort=True):
            r, lo, hi = wilson(len(h), n)
            lines.append(
                f"| {strategy} | {model} | {len(h)}/{n} ({_fmt(r, lo, hi, pct=True)}) "
                f"| {h['model_probability'].median():.3f} | {h['model_switches'].mean():.1f} |"
            )
    return "\n".join(lines) + "\n"


def per_configuration_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Searches that acquired the source, per configuration (rows, in suite order) and strategy
    (columns), as "k/n" strings: where a strategy fails, which the pooled rates hide."""
    counts = runs.groupby(["scenario", "strategy"])["source_acquired"].agg(["sum", "count"])
    cells = counts["sum"].astype(int).astype(str) + "/" + counts["count"].astype(str)
    table = cells.unstack("strategy").fillna("—")
    table = table.loc[sorted(table.index, key=_config_key)]
    table.index.name = "configuration"
    return table


def per_configuration_markdown(table: pd.DataFrame) -> str:
    cols = list(table.columns)
    lines = [
        "| configuration | " + " | ".join(cols) + " |",
        "|" + "---|" * (len(cols) + 1),
    ]
    for config, row in table.iterrows():
        lines.append(f"| {config} | " + " | ".join(row[c] for c in cols) + " |")
    return "\n".join(lines) + "\n"


def _fmt_time(v: float, lo: float, hi: float, budget: float) -> str:
    """A censored median time: "> 900" where it lies beyond the budget."""

    def one(x: float) -> str:
        if math.isnan(x):
            return "—"
        return f"> {budget:.0f}" if math.isinf(x) else f"{x:.0f}"

    if math.isnan(v):
        return "—"
    return one(v) if math.isinf(v) else f"{one(v)} [{one(lo)}, {one(hi)}]"


def _fmt(v: float, lo: float, hi: float, digits: int = 2, pct: bool = False) -> str:
    if not np.isfinite(v):
        return "—"
    s = 100.0 if pct else 1.0
    body = f"{v * s:.{0 if pct else digits}f}"
    if np.isfinite(lo) and np.isfinite(hi):
        body += f" [{lo * s:.{0 if pct else digits}f}, {hi * s:.{0 if pct else digits}f}]"
    return body + ("%" if pct else "")


STALL_SECONDS = 60.0
"""s: a search that stays within one step of one position longer than this before it has the
source is counted as stalled (the issue-28 bar)."""


def _fmt_stall(longest: float, stalled: int) -> str:
    """The longest stall of any search, s, and how many searches stalled > STALL_SECONDS."""
    if not math.isfinite(longest):
        return "n/a"
    return f"{longest:.0f} ({stalled} > {STALL_SECONDS:.0f} s)"


def markdown_table(table: pd.DataFrame) -> str:
    head = (
        "| strategy | n | source acquired | plume acquired | mean final RMSE (m) | "
        "median final RMSE (m) | median time to RMSE < 1 m (s) | to < 0.5 m (s) | "
        "path (m) | decision (ms) | truth in 95% region | longest stall (s) |"
    )
    lines = [head, "|" + "---|" * 12]
    for _, r in table.iterrows():
        src = _fmt(r.source_acquired_rate, r.source_acquired_lo, r.source_acquired_hi, pct=True)
        plume = _fmt(r.plume_acquired_rate, r.plume_acquired_lo, r.plume_acquired_hi, pct=True)
        t1 = _fmt_time(r.time_to_1m, r.time_to_1m_lo, r.time_to_1m_hi, r.budget)
        t05 = _fmt_time(r.time_to_0_5m, r.time_to_0_5m_lo, r.time_to_0_5m_hi, r.budget)
        lines.append(
            f"| {r.strategy} | {r.searches} | {src} | {plume} "
            f"| {_fmt(r.mean_final_rmse, r.mean_final_rmse_lo, r.mean_final_rmse_hi)} "
            f"| {_fmt(r.median_final_rmse, r.median_final_rmse_lo, r.median_final_rmse_hi)} "
            f"| {t1} ({r.reached_1m:.0%} got there) "
            f"| {t05} ({r.reached_0_5m:.0%}) "
            f"| {_fmt(r.path_length, r.path_length_lo, r.path_length_hi, 0)} "
            f"| {_fmt(r.decision_ms, r.decision_ms_lo, r.decision_ms_hi, 1)} "
            f"| {_fmt(r.truth_in_95_rate, r.truth_in_95_lo, r.truth_in_95_hi, pct=True)} "
            f"| {_fmt_stall(r.longest_stall, r.stalled)} |"
        )
    return "\n".join(lines) + "\n"


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


def _png(fig: plt.Figure) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def figure_rmse(curves: dict[str, pd.DataFrame]) -> bytes:
    """Two panels sharing the log RMSE axis: the mean (the paper's figure) and the median."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True, layout="constrained")
    panels = (
        ("mean", "lo", "hi", "Mean RMSE over time (95% band)"),
        ("median", "median_lo", "median_hi", "Median RMSE over time (95% band)"),
    )
    for ax, (key, lo, hi, title) in zip(axes, panels, strict=True):
        for name, c in curves.items():
            (line,) = ax.plot(c["time"], c[key], label=name)
            ax.fill_between(c["time"], c[lo], c[hi], alpha=0.2, color=line.get_color())
        ax.set_yscale("log")
        ax.set_xlabel("time (s)")
        ax.axhline(0.5, color="0.5", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
        ax.set_title(title)
    axes[0].set_ylabel("RMSE of the source location (m)")
    axes[0].legend()
    return _png(fig)


def figure_acquisition(table: pd.DataFrame) -> bytes:
    fig, ax = plt.subplots(figsize=(8, 4))
    x = np.arange(len(table))
    for k, (key, label) in enumerate(
        (("source_acquired", "source acquired"), ("plume_acquired", "plume acquired"))
    ):
        rate = table[f"{key}_rate"].to_numpy()
        err = np.vstack([rate - table[f"{key}_lo"], table[f"{key}_hi"] - rate])
        ax.bar(x + (k - 0.5) * 0.38, 100 * rate, 0.38, yerr=100 * err, capsize=3, label=label)
    ax.set_xticks(x, table["strategy"])
    ax.set_ylabel("% of searches")
    ax.set_ylim(0, 105)
    ax.legend(loc="lower right")
    ax.set_title("Acquisition rates (95% Wilson intervals)")
    return _png(fig)


def grid_configuration(runs: pd.DataFrame) -> str | None:
    """The configuration the comparison grid shows: among those with a repeat-0 search of
    every strategy, the one where the strategies differ most at repeat 0: most mixed success
    (some acquire the source, some do not), then the widest spread of log final RMSE. A
    configuration where every strategy succeeds says nothing about the differences."""
    reps = runs[runs["seed"] == 0]
    n_strategies = runs["strategy"].nunique()
    best, best_key = None, None
    for config, g in reps.groupby("scenario"):
        if g["strategy"].nunique() < n_strategies:
            continue
        ok = g["source_acquired"].astype(bool)
        mixed = min(int(ok.sum()), int((~ok).sum()))
        log_rmse = np.log(np.maximum(g["final_rmse"].to_numpy(dtype=float), 1e-6))
        key = (mixed, float(log_rmse.max() - log_rmse.min()))
        if best_key is None or key > best_key:
            best, best_key = str(config), key
    return best


def figure_grid(runs: pd.DataFrame) -> tuple[bytes, str] | None:
    """Repeat 0 of every strategy on :func:`grid_configuration` at its saved snapshot times
    (fractions of the budget, :data:`dcee.simulation.episode.SNAPSHOT_FRACTIONS`): particles,
    trajectory so far, true source; returns (PNG, configuration)."""
    from dcee.scenarios import Scenario

    config = grid_configuration(runs)
    if config is None:
        return None
    reps = runs[(runs["seed"] == 0) & (runs["scenario"] == config)].sort_values("strategy")
    reps = reps.drop_duplicates("strategy")
    scenario = Scenario.model_validate(load_config(reps["run_dir"].iloc[0])["scenario"])
    truth = scenario.truth_theta()
    lo, hi = scenario.volume.low, scenario.volume.high
    snaps = []
    for run_dir in reps["run_dir"]:
        with np.load(Path(run_dir) / "posterior.npz") as z:
            if "snapshot_times" in z:
                snaps.append((z["snapshot_times"].copy(), z["snapshot_particles"].copy()))
            else:
                snaps.append((np.array([]), None))
    columns = max((len(t) for t, _ in snaps), default=0)
    if columns == 0:
        return None
    # Panels are drawn to scale (equal aspect), so size the figure by the area's aspect ratio
    # and let constrained layout place the title: a fixed square cell left wide gaps.
    aspect = (hi[1] - lo[1]) / (hi[0] - lo[0])
    fig, axes = plt.subplots(
        len(reps),
        columns,
        figsize=(2.8 * columns, 2.8 * aspect * len(reps) + 0.5),
        squeeze=False,
        layout="constrained",
    )
    for row, ((_, r), (times, parts)) in enumerate(zip(reps.iterrows(), snaps, strict=True)):
        steps = pd.read_parquet(Path(r["run_dir"]) / "steps.parquet", columns=["time", "x", "y"])
        for col in range(columns):
            ax = axes[row, col]
            if col < len(times):
                ax.scatter(parts[col][:, 0], parts[col][:, 1], s=1, alpha=0.3, color="tab:blue")
                path = steps[steps["time"] <= times[col] + 1e-9]
                ax.plot(path["x"], path["y"], color="tab:red", lw=1)
                ax.set_title(f"t = {times[col]:.0f} s", fontsize=9)
            ax.plot(truth[0], truth[1], marker="*", color="gold", mec="k", ms=12)
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if col == 0:
                verdict = "acquired" if r["source_acquired"] else "FAILED"
                ax.set_ylabel(f"{r['strategy']}\n{verdict}, RMSE {r['final_rmse']:.2g} m")
    fig.suptitle(
        f"{config}, repeat 0 (where the strategies differ most): particles (blue), path (red), "
        "source (star)"
    )
    return _png(fig), config


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


def pairwise_markdown(table: pd.DataFrame) -> str:
    lines = [
        "| A | B | paired searches | acquired by A only | by B only | McNemar p (exact) "
        "| median final RMSE A − B (m) | Wilcoxon p |",
        "|" + "---|" * 8,
    ]
    for _, r in table.iterrows():
        lines.append(
            f"| {r.a} | {r.b} | {r.pairs} | {r.acquired_a_only} | {r.acquired_b_only} "
            f"| {r.mcnemar_p:.2g} | {r.median_rmse_difference:+.3f} | {r.wilcoxon_p:.2g} |"
        )
    return "\n".join(lines) + "\n"


def figure_posteriors(runs: pd.DataFrame) -> bytes:
    """Histograms of the final posterior's error (particle − truth) per unknown parameter,
    pooled over the searches of each strategy. Every strategy shares one robust range per
    parameter (see `_robust_range`), so that a few lost searches ~20 m away do not squeeze the
    peak of the others into one bin; each panel says how many particles fall outside it."""
    from dcee.models.plume import PARAMETER_NAMES, PARAMETER_UNITS
    from dcee.scenarios import Scenario

    names = list(runs["parameter_names"].iloc[0])
    idx = [PARAMETER_NAMES.index(n) for n in names]
    errors: dict[str, np.ndarray] = {}
    for strategy, g in runs.groupby("strategy", sort=True):
        errs = []
        for run_dir in g["run_dir"]:
            truth = Scenario.model_validate(load_config(run_dir)["scenario"]).truth_theta()
            with np.load(Path(run_dir) / "posterior.npz") as z:
                p = z["final_particles"].astype(float)
            errs.append(p[:, idx] - truth[idx])
        errors[str(strategy)] = np.concatenate(errs)
    pooled = np.concatenate(list(errors.values()))
    ncols = min(4, len(names))
    nrows = math.ceil(len(names) / ncols)
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(3.2 * ncols, 2.7 * nrows + 0.4), squeeze=False, layout="constrained"
    )
    for k, ax in enumerate(axes.flat):
        if k >= len(names):
            ax.set_visible(False)
            continue
        lo, hi = _robust_range(pooled[:, k])
        outside = float(np.mean((pooled[:, k] < lo) | (pooled[:, k] > hi)))
        for strategy, e in errors.items():
            ax.hist(e[:, k], bins=60, range=(lo, hi), histtype="step", density=True, label=strategy)
        ax.axvline(0.0, color="0.4", lw=0.8, ls=":")
        unit = PARAMETER_UNITS.get(names[k], "")
        ax.set_title(
            f"{names[k]} − true" + (f" ({unit})" if unit else "") + f"\n{outside:.1%} outside",
            fontsize=10,
        )
        ax.set_yticks([])
    axes.flat[0].legend(fontsize=7)
    fig.suptitle(
        "Final posterior error, pooled over searches (robust range; share of particles outside)"
    )
    return _png(fig)


def _robust_range(errors: np.ndarray) -> tuple[float, float]:
    """Histogram range for pooled errors: the quartiles widened by 3 interquartile ranges,
    clipped to the central 98%. Lost searches (a minority far away) fall outside it instead of
    setting the scale."""
    p1, q1, q3, p99 = np.percentile(errors, [1, 25, 75, 99])
    iqr = q3 - q1
    lo, hi = max(p1, q1 - 3.0 * iqr), min(p99, q3 + 3.0 * iqr)
    if not hi > lo:
        lo, hi = lo - 1.0, hi + 1.0
    return float(lo), float(hi)


def _config_key(name: str) -> tuple:
    head, _, tail = name.partition(":")
    return (head, int(tail) if tail.isdigit() else tail)


def write_report(results_dir: Path, out_dir: Path) -> list[Path]:
    """Write report.html, metrics.csv/.md, pairwise.csv/.md, per_configuration.csv/.md and the
    figures for a campaign or any folder of saved searches; returns the paths. The output
    folder is checked before any work."""
    from dcee.io import check_writable_dir
    from dcee.provenance import describe

    results_dir = Path(results_dir)
    meta, runs = load_campaign(results_dir)
    check_writable_dir(out_dir, "out")
    table = metrics_table(runs)
    md = markdown_table(table)
    pairs = pairwise_table(runs)
    pairs_md = pairwise_markdown(pairs)
    figures = {
        "rmse_over_time.png": figure_rmse(rmse_over_time(runs)),
        "acquisition.png": figure_acquisition(table),
        "posteriors.png": figure_posteriors(runs),
    }
    grid = figure_grid(runs)
    grid_config = None
    if grid is not None:
        figures["comparison_grid.png"], grid_config = grid
    paths = []
    for name, data in figures.items():
        write_atomic(out_dir / name, lambda p, d=data: p.write_bytes(d))
        paths.append(out_dir / name)
    per_config = per_configuration_table(runs)
    per_config_md = per_configuration_markdown(per_config)
    tables = {
        "metrics.csv": lambda p: table.to_csv(p, index=False),
        "metrics.md": lambda p: p.write_text(md),
        "pairwise.csv": lambda p: pairs.to_csv(p, index=False),
        "pairwise.md": lambda p: p.write_text(pairs_md),
        "per_configuration.csv": lambda p: per_config.to_csv(p),
        "per_configuration.md": lambda p: p.write_text(per_config_md),
    }
    models_md = model_selection_markdown(runs)
    if models_md is not None:
        tables["model_selection.md"] = lambda p: p.write_text(models_md)
    for name, writer in tables.items():
        write_atomic(out_dir / name, writer)
    failed = len(list(results_dir.rglob("error.json")))
    s = meta["settings"]
    truths = sorted(runs["truth_model"].unique()) if "truth_model" in runs else ["isotropic"]
    codes = meta.get("code_versions") or list(
        {json.dumps(c, sort_keys=True): c for c in runs.get("code", []) if c}.values()
    )
    code_text = "; ".join(describe(c) for c in codes) or "unknown"
    html = [
        "<!doctype html><html><head><meta charset='utf-8'><title>dcee report</title>",
        "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:"
        "collapse}td,th{border:1px solid #ccc;padding:4px 8px;font-size:13px}</style></head><body>",
        f"<h1>Report: {s['suite']}</h1>",
        f"<p>{len(runs)} finished searches ({failed} failed), {runs['scenario'].nunique()} "
        f"configurations, strategies: {', '.join(sorted(runs['strategy'].unique()))}; unknowns: "
        f"{s.get('unknown') or 'as configured'}; ground truth: {', '.join(truths)}; code: "
        f"dcee {code_text}. Intervals are 95%; times to an RMSE level are Kaplan–Meier "
        "medians with searches that never got there censored at the budget.</p>",
        _md_to_html(md),
        "<h2>paired comparisons (common configurations and seeds)</h2>",
        _md_to_html(pairs_md) if len(pairs) else "<p>fewer than two strategies</p>",
        "<h2>source acquired per configuration</h2>",
        _md_to_html(per_config_md),
    ]
    if models_md is not None:
        html += [
            "<h2>reading model selected by the readings (turbulence level)</h2>",
            _md_to_html(models_md),
        ]
    for name, data in figures.items():
        b64 = base64.b64encode(data).decode()
        title = name[:-4].replace("_", " ")
        if name == "comparison_grid.png":
            title += f" ({grid_config}, repeat 0)"
        html.append(
            f"<h2>{title}</h2><img src='data:image/png;base64,{b64}' style='max-width:100%'>"
        )
    html.append("</body></html>")
    write_atomic(out_dir / "report.html", lambda p: p.write_text("\n".join(html)))
    return [out_dir / "report.html", *(out_dir / t for t in tables), *paths]


def _md_to_html(md: str) -> str:
    rows = [r.strip().strip("|").split("|") for r in md.strip().splitlines()]
    head, body = rows[0], rows[2:]
    out = ["<table><tr>" + "".join(f"<th>{c.strip()}</th>" for c in head) + "</tr>"]
    for r in body:
        out.append("<tr>" + "".join(f"<td>{c.strip()}</td>" for c in r) + "</tr>")
    return "".join(out) + "</table>"
