"""The figures of a report (PNG bytes): the median RMSE over time, the acquisition rates, the
comparison grid of one configuration's posteriors over time, and the final posteriors."""

from __future__ import annotations

import io
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from dcee.analysis.results import load_config


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
    (fractions of the budget, :data:`dcee.runs.SNAPSHOT_FRACTIONS`): particles,
    trajectory so far, true source; returns (PNG, configuration)."""
    from dcee.scenarios import Scenario

    config = grid_configuration(runs)
    if config is None:
        return None
    reps = runs[(runs["seed"] == 0) & (runs["scenario"] == config)].sort_values("strategy")
    reps = reps.drop_duplicates("strategy")
    scenario = Scenario.model_validate(load_config(reps["run_dir"].iloc[0])["scenario"])
    sources = scenario.truth.source_locations()
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
            ax.plot(sources[:, 0], sources[:, 1], "*", color="gold", mec="k", ms=12, ls="none")
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
