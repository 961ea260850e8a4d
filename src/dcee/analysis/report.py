"""Campaign report: per-strategy metrics with 95% confidence intervals, the paper's figures,
and a self-contained HTML page (figures embedded) plus the table as CSV and Markdown.

Confidence intervals: Wilson score intervals for rates; for means a normal interval
(mean ± 1.96 s/√n); for the table's medians a percentile bootstrap (2,000 resamples, fixed
seed, so the report is reproducible); for the median RMSE curve, evaluated at every time step,
the exact order-statistic interval (`median_order_statistic_ranks`). Times to an RMSE level
are over the searches that reached it; the fraction that reached it is reported beside.
"""

from __future__ import annotations

import base64
import io
import json
import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from scipy import stats

from dcee.campaign.runner import SNAPSHOT_TIMES
from dcee.errors import DceeInputError
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


def median_ci(x: np.ndarray, n_boot: int = 2000) -> tuple[float, float, float]:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return (math.nan, math.nan, math.nan)
    rng = np.random.default_rng(0)
    boots = np.median(rng.choice(x, size=(n_boot, len(x)), replace=True), axis=1)
    lo, hi = np.percentile(boots, [2.5, 97.5])
    return (float(np.median(x)), float(lo), float(hi))


def load_campaign(campaign_dir: Path) -> tuple[dict[str, Any], pd.DataFrame]:
    """(campaign.json, one row per finished search)."""
    meta_path = campaign_dir / "campaign.json"
    if not meta_path.is_file():
        raise DceeInputError(
            "campaign", f"{campaign_dir} is not a campaign folder (no campaign.json)"
        )
    meta = json.loads(meta_path.read_text())
    rows = []
    for path in sorted((campaign_dir / "runs").glob("*/*/seed-*.json")):
        if path.name.endswith(".error.json"):
            continue
        try:
            s = json.loads(path.read_text())
        except json.JSONDecodeError:
            continue  # a corrupt summary is not a finished search
        s["_stem"] = str(path.with_suffix(""))
        rows.append(s)
    if not rows:
        raise DceeInputError("campaign", f"{campaign_dir} holds no finished searches yet")
    return meta, pd.DataFrame(rows)


def metrics_table(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per strategy: every metric with its 95% interval."""
    out = []
    for strategy, g in runs.groupby("strategy", sort=True):
        n = len(g)
        row: dict[str, Any] = {"strategy": strategy, "searches": n}
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
            v, lo, hi = mean_ci(t)
            row.update(
                {
                    f"time_to_{level}": v,
                    f"time_to_{level}_lo": lo,
                    f"time_to_{level}_hi": hi,
                    f"reached_{level}": float(np.isfinite(t).mean()),
                }
            )
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


def _fmt(v: float, lo: float, hi: float, digits: int = 2, pct: bool = False) -> str:
    if not np.isfinite(v):
        return "—"
    s = 100.0 if pct else 1.0
    body = f"{v * s:.{0 if pct else digits}f}"
    if np.isfinite(lo) and np.isfinite(hi):
        body += f" [{lo * s:.{0 if pct else digits}f}, {hi * s:.{0 if pct else digits}f}]"
    return body + ("%" if pct else "")


def markdown_table(table: pd.DataFrame) -> str:
    head = (
        "| strategy | n | source acquired | plume acquired | mean final RMSE (m) | "
        "median final RMSE (m) | time to RMSE < 1 m (s) | time to < 0.5 m (s) | "
        "path (m) | decision (ms) | truth in 95% region |"
    )
    lines = [head, "|" + "---|" * 11]
    for _, r in table.iterrows():
        src = _fmt(r.source_acquired_rate, r.source_acquired_lo, r.source_acquired_hi, pct=True)
        plume = _fmt(r.plume_acquired_rate, r.plume_acquired_lo, r.plume_acquired_hi, pct=True)
        t05 = _fmt(r.time_to_0_5m, r.time_to_0_5m_lo, r.time_to_0_5m_hi, 0)
        lines.append(
            f"| {r.strategy} | {r.searches} | {src} | {plume} "
            f"| {_fmt(r.mean_final_rmse, r.mean_final_rmse_lo, r.mean_final_rmse_hi)} "
            f"| {_fmt(r.median_final_rmse, r.median_final_rmse_lo, r.median_final_rmse_hi)} "
            f"| {_fmt(r.time_to_1m, r.time_to_1m_lo, r.time_to_1m_hi, 0)} ({r.reached_1m:.0%}) "
            f"| {t05} ({r.reached_0_5m:.0%}) "
            f"| {_fmt(r.path_length, r.path_length_lo, r.path_length_hi, 0)} "
            f"| {_fmt(r.decision_ms, r.decision_ms_lo, r.decision_ms_hi, 1)} "
            f"| {_fmt(r.truth_in_95_rate, r.truth_in_95_lo, r.truth_in_95_hi, pct=True)} |"
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
    (lo, hi), and median RMSE with a 95% distribution-free order-statistic band
    (median_lo, median_hi). A search that ended early keeps its last value (its estimate no
    longer changes). The mean is the paper's statistic; the median shows the typical search,
    which the mean hides when a few searches are lost ~20 m from the source."""
    budget = float(runs["budget"].max())
    grid = np.arange(0.0, budget + 1e-9, step)
    out = {}
    for strategy, g in runs.groupby("strategy", sort=True):
        curves = []
        for stem in g["_stem"]:
            steps = pd.read_parquet(f"{stem}.parquet", columns=["time", "rmse"])
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
                "lo": mean - half,
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


def figure_grid(runs: pd.DataFrame, meta: dict[str, Any]) -> bytes | None:
    """One representative search per strategy (first configuration, repeat 0) at the snapshot
    times: particles, trajectory so far, true source."""
    from dcee.scenarios import Scenario

    reps = runs[runs["seed"] == 0].sort_values(["scenario", "strategy"])
    if reps.empty:
        return None
    config = sorted(reps["scenario"].unique(), key=_config_key)[0]
    reps = reps[reps["scenario"] == config]
    scenario = Scenario.model_validate(meta["settings"]["scenarios"][config])
    truth = scenario.truth_theta()
    lo, hi = scenario.volume.low, scenario.volume.high
    # Panels are drawn to scale (equal aspect), so size the figure by the area's aspect ratio
    # and let constrained layout place the title: a fixed square cell left wide gaps.
    aspect = (hi[1] - lo[1]) / (hi[0] - lo[0])
    fig, axes = plt.subplots(
        len(reps),
        len(SNAPSHOT_TIMES),
        figsize=(2.8 * len(SNAPSHOT_TIMES), 2.8 * aspect * len(reps) + 0.5),
        squeeze=False,
        layout="constrained",
    )
    for row, (_, r) in enumerate(reps.iterrows()):
        steps = pd.read_parquet(f"{r['_stem']}.parquet", columns=["time", "x", "y"])
        with np.load(f"{r['_stem']}.npz") as z:
            times = z["snapshot_times"] if "snapshot_times" in z else np.array([])
            parts = z["snapshot_particles"] if "snapshot_particles" in z else None
        for col, t_snap in enumerate(SNAPSHOT_TIMES):
            ax = axes[row, col]
            if parts is not None and len(times):
                k = int(np.argmin(np.abs(times - t_snap)))
                ax.scatter(parts[k][:, 0], parts[k][:, 1], s=1, alpha=0.3, color="tab:blue")
            path = steps[steps["time"] <= t_snap]
            ax.plot(path["x"], path["y"], color="tab:red", lw=1)
            ax.plot(truth[0], truth[1], marker="*", color="gold", mec="k", ms=12)
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if row == 0:
                ax.set_title(f"t = {t_snap:.0f} s")
            if col == 0:
                ax.set_ylabel(r["strategy"])
    fig.suptitle(f"{config}, repeat 0: particles (blue), path (red), source (star)")
    return _png(fig)


def figure_posteriors(runs: pd.DataFrame, meta: dict[str, Any]) -> bytes:
    """Histograms of the final posterior's error (particle − truth) per unknown parameter,
    pooled over the searches of each strategy. Every strategy shares one robust range per
    parameter (see `_robust_range`), so that a few lost searches ~20 m away do not squeeze the
    peak of the others into one bin; each panel says how many particles fall outside it."""
    from dcee.models.plume import PARAMETER_NAMES, PARAMETER_UNITS
    from dcee.scenarios import Scenario

    names = list(runs["parameter_names"].iloc[0])
    idx = [PARAMETER_NAMES.index(n) for n in names]
    truths = {
        k: Scenario.model_validate(v).truth_theta()
        for k, v in meta["settings"]["scenarios"].items()
    }
    errors: dict[str, np.ndarray] = {}
    for strategy, g in runs.groupby("strategy", sort=True):
        errs = []
        for _, r in g.iterrows():
            with np.load(f"{r['_stem']}.npz") as z:
                p = z["final_particles"].astype(float)
            errs.append(p[:, idx] - truths[r["scenario"]][idx])
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


def write_report(campaign_dir: Path, out_dir: Path) -> list[Path]:
    """Write report.html, metrics.csv/.md, per_configuration.csv/.md and the figures; returns
    the paths."""
    meta, runs = load_campaign(Path(campaign_dir))
    table = metrics_table(runs)
    md = markdown_table(table)
    figures = {
        "rmse_over_time.png": figure_rmse(rmse_over_time(runs)),
        "acquisition.png": figure_acquisition(table),
        "posteriors.png": figure_posteriors(runs, meta),
    }
    grid = figure_grid(runs, meta)
    if grid is not None:
        figures["comparison_grid.png"] = grid
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, data in figures.items():
        write_atomic(out_dir / name, lambda p, d=data: p.write_bytes(d))
        paths.append(out_dir / name)
    write_atomic(out_dir / "metrics.csv", lambda p: table.to_csv(p, index=False))
    write_atomic(out_dir / "metrics.md", lambda p: p.write_text(md))
    per_config = per_configuration_table(runs)
    per_config_md = per_configuration_markdown(per_config)
    write_atomic(out_dir / "per_configuration.csv", lambda p: per_config.to_csv(p))
    write_atomic(out_dir / "per_configuration.md", lambda p: p.write_text(per_config_md))
    failed = len(list((Path(campaign_dir) / "runs").glob("*/*/seed-*.error.json")))
    s = meta["settings"]
    truths = sorted(runs["truth_model"].unique()) if "truth_model" in runs else ["isotropic"]
    html = [
        "<!doctype html><html><head><meta charset='utf-8'><title>dcee campaign report</title>",
        "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:"
        "collapse}td,th{border:1px solid #ccc;padding:4px 8px;font-size:13px}</style></head><body>",
        f"<h1>Campaign report: {s['suite']} suite</h1>",
        f"<p>{len(runs)} finished searches ({failed} failed), {runs['scenario'].nunique()} "
        f"configurations, strategies: {', '.join(sorted(runs['strategy'].unique()))}; unknowns: "
        f"{s['unknown'] or 'as configured'}; ground truth: {', '.join(truths)} (the estimator "
        f"always assumes the isotropic plume); dcee {meta.get('version', '?')}. "
        "Intervals are 95%.</p>",
        _md_to_html(md),
        "<h2>source acquired per configuration</h2>",
        _md_to_html(per_config_md),
    ]
    for name, data in figures.items():
        b64 = base64.b64encode(data).decode()
        html.append(
            f"<h2>{name[:-4].replace('_', ' ')}</h2>"
            f"<img src='data:image/png;base64,{b64}' style='max-width:100%'>"
        )
    html.append("</body></html>")
    write_atomic(out_dir / "report.html", lambda p: p.write_text("\n".join(html)))
    tables = ("metrics.csv", "metrics.md", "per_configuration.csv", "per_configuration.md")
    return [out_dir / "report.html", *(out_dir / t for t in tables), *paths]


def _md_to_html(md: str) -> str:
    rows = [r.strip().strip("|").split("|") for r in md.strip().splitlines()]
    head, body = rows[0], rows[2:]
    out = ["<table><tr>" + "".join(f"<th>{c.strip()}</th>" for c in head) + "</tr>"]
    for r in body:
        out.append("<tr>" + "".join(f"<td>{c.strip()}</td>" for c in r) + "</tr>")
    return "".join(out) + "</table>"
