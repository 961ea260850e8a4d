"""The report of a campaign or of any folder of saved searches (``dcee report``): the tables of
:mod:`dcee.analysis.statistics` as CSV and Markdown, the figures of
:mod:`dcee.analysis.report_figures`, and a self-contained HTML page with the figures embedded."""

from __future__ import annotations

import base64
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from dcee.analysis.report_figures import (
    figure_acquisition,
    figure_grid,
    figure_posteriors,
    figure_rmse,
)
from dcee.analysis.results import describe_folder, load_summaries
from dcee.analysis.statistics import (
    STALL_SECONDS,
    WANDER_SECONDS,
    metrics_table,
    pairwise_table,
    per_configuration_table,
    rmse_over_time,
    wilson,
)
from dcee.io import write_atomic


def load_campaign(folder: Path) -> tuple[dict[str, Any], pd.DataFrame]:
    """(campaign.json or a description of the loose searches, one row per finished search)."""
    return describe_folder(folder), load_summaries(folder)


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


def map_estimates_markdown(runs: pd.DataFrame) -> str | None:
    """Searches on a site in geographic coordinates (issue 81): each estimate in degrees and in
    the site's local frame, with the file that holds it on a map; None when no search has one."""
    if "final_mean_geo" not in runs:
        return None
    rows = [
        "| configuration | strategy | seed | latitude (°) | longitude (°) | height (m) | local "
        "x, y (m) | final RMSE (m) | on a map |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in runs.sort_values(["scenario", "strategy", "seed"]).iterrows():
        geo = r["final_mean_geo"]
        if not isinstance(geo, dict):
            continue
        x, y = r["final_mean"][:2]
        rows.append(
            f"| {r['scenario']} | {r['strategy']} | {r['seed']} | {geo['latitude']:.7f} | "
            f"{geo['longitude']:.7f} | {geo['height_m']:.2f} | {x:.2f}, {y:.2f} | "
            f"{r['final_rmse']:.2f} | {'/'.join(Path(r['run_dir']).parts[-3:])}/estimate.geojson |"
        )
    return "\n".join(rows) + "\n" if len(rows) > 2 else None


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


def _fmt_stall(longest: float, stalled: int, limit: float = STALL_SECONDS) -> str:
    """The longest stall (or wander) of any search, s, and how many were longer than
    ``limit`` s."""
    if not math.isfinite(longest):
        return "n/a"
    return f"{longest:.0f} ({stalled} > {limit:.0f} s)"


def region_floor_text(runs: pd.DataFrame) -> str:
    """The sentence that says which 95 % region "truth in 95% region" counts: the particles'
    own, or widened by ``estimator.region_floor`` σ (m, docs/plumes.md); a summary written
    before the floor existed has none (the particles' own)."""
    floors = (
        sorted({float(f) for f in runs["region_floor"].dropna()}) if "region_floor" in runs else []
    )
    if not any(f > 0 for f in floors):
        return "The 95% region is the particles' own."
    return (
        "The 95% region is the posterior's widened by the reading model's own error, "
        f"estimator.region_floor = {', '.join(f'{f:g}' for f in floors)} m (0: the "
        "particles' own region; the region at every floor is in each summary, "
        "truth_in_95_floor)."
    )


def markdown_table(table: pd.DataFrame) -> str:
    head = (
        "| strategy | n | source acquired | plume acquired | mean final RMSE (m) | "
        "median final RMSE (m) | median time to RMSE < 1 m (s) | to < 0.5 m (s) | "
        "path (m) | decision (ms) | truth in 95% region | longest stall (s) | "
        "longest wander in 15 m (s) |"
    )
    lines = [head, "|" + "---|" * 13]
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
            f"| {_fmt_stall(r.longest_stall, r.stalled)} "
            f"| {_fmt_stall(r.longest_wander, r.wandered, WANDER_SECONDS)} |"
        )
    if "count_correct_rate" in table and table["count_correct_rate"].notna().any():
        # the count of releases was unknown: its own table, the set's error beside it
        lines += [
            "",
            "| strategy | n | right count of releases | median OSPA (m, 3 m cut-off) |",
            "|---|---|---|---|",
        ]
        for _, r in table.iterrows():
            right = _fmt(r.count_correct_rate, r.count_correct_lo, r.count_correct_hi, pct=True)
            ospa = _fmt(r.median_ospa, r.median_ospa_lo, r.median_ospa_hi)
            lines.append(f"| {r.strategy} | {r.searches} | {right} | {ospa} |")
    return "\n".join(lines) + "\n"


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
    map_md = map_estimates_markdown(runs)
    if map_md is not None:
        tables["map_estimates.md"] = lambda p: p.write_text(map_md)
    for name, writer in tables.items():
        write_atomic(out_dir / name, writer)
    failed = len(list(results_dir.rglob("error.json")))
    s = meta["settings"]
    truths = sorted(runs["truth_model"].unique()) if "truth_model" in runs else ["isotropic"]
    codes = meta.get("code_versions") or list(
        {json.dumps(c, sort_keys=True): c for c in runs.get("code", []) if c}.values()
    )
    code_text = "; ".join(describe(c) for c in codes) or "unknown"
    # a campaign's --set/--likelihood/--particles edits apply to every configuration: the
    # report names them so an edited campaign is never read as the built-in configurations
    edits = {
        **({"search.particles": s["particles"]} if s.get("particles") else {}),
        **(s.get("overrides") or {}),
    }
    floor_text = region_floor_text(runs)
    edits_text = (
        "; settings changed from the configurations' own: "
        + ", ".join(f"{k} = {v}" for k, v in sorted(edits.items()))
        if edits
        else ""
    )
    html = [
        "<!doctype html><html><head><meta charset='utf-8'><title>dcee report</title>",
        "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:"
        "collapse}td,th{border:1px solid #ccc;padding:4px 8px;font-size:13px}</style></head><body>",
        f"<h1>Report: {s['suite']}</h1>",
        f"<p>{len(runs)} finished searches ({failed} failed), {runs['scenario'].nunique()} "
        f"configurations, strategies: {', '.join(sorted(runs['strategy'].unique()))}; unknowns: "
        f"{s.get('unknown') or 'as configured'}; ground truth: {', '.join(truths)}{edits_text}; "
        "code: "
        f"dcee {code_text}. Intervals are 95%; times to an RMSE level are Kaplan–Meier "
        f"medians with searches that never got there censored at the budget. {floor_text}</p>",
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
    if map_md is not None:
        html += ["<h2>estimates on the map (WGS 84 and the site's local frame)</h2>",
                 _md_to_html(map_md)]  # fmt: skip
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
