"""The fluid solver's plume (recipes lbm-plume, lbm-endgame, cross-truth)."""

from __future__ import annotations

import pandas as pd

from studies.tables.common import (
    RESULTS,
    table,
)


def lbm_statistics_table() -> str:
    """The solver plume's statistics downwind (studies/lbm_statistics.py's stored table)."""
    frame = pd.read_csv(RESULTS / "lbm-plume" / "statistics.csv")
    rows = [
        [
            f"{r['x']:.0f}",
            f"{r['sigma_y']:.2f}",
            f"{r['briggs_D']:.1f} … {r['briggs_A']:.1f}",
            f"{r['flux']:.2f}",
            f"{r['intensity']:.2f}",
            f"{r['intermittency']:.2f}",
        ]
        for _, r in frame.iterrows()
    ]
    header = [
        "x downwind (m)",
        "σ_y of the mean (m)",
        "Briggs D … A (m)",
        "flux ∫C̄ dy · U",
        "centreline σc/C̄",
        "intermittency (c > C̄/10)",
    ]
    return table(header, rows)


def lbm_near_source_table() -> str:
    """The lbm truth near its release as the playback samples it (studies/lbm_near_source.py,
    docs/results/lbm-plume/near_source.csv)."""
    frame = pd.read_csv(RESULTS / "lbm-plume" / "near_source.csv")
    rows = [
        [
            f"{r['along_m']:+.2f}",
            f"{r['mean_over_peak']:.3f}",
            f"{100 * r['above_0.001_peak']:.0f} %",
            f"{100 * r['above_0.01_peak']:.0f} %",
        ]
        for _, r in frame.iterrows()
    ]
    header = [
        "along the mean wind from the release centre (m; < 0 upwind)",
        "time mean / peak",
        "frames above 0.1 % of the peak",
        "frames above 1 % of the peak",
    ]
    return table(header, rows)


def lbm_endgame_table() -> str:
    """Where each planner reads last and ends on the lbm plume (studies/lbm_endgame.py,
    docs/results/lbm-plume/endgame.csv; a lab note on eight tuning configurations)."""
    frame = pd.read_csv(RESULTS / "lbm-plume" / "endgame.csv")
    rows = []
    for strategy, g in frame.groupby("strategy", sort=False):
        m = g.median(numeric_only=True)
        rows.append(
            [
                f"`{strategy}`",
                str(len(g)),
                f"{m['late_along_median_m']:+.2f}",
                f"{100 * m['late_detections_upwind_share']:.0f} %",
                f"{m['final_along_m']:+.2f}",
                f"{m['final_spread_m']:.2f}",
                f"{m['final_rmse_m']:.2f}",
                f"{int(g['truth_in_95'].sum())}/{len(g)}",
            ]
        )
    header = [
        "planner",
        "searches",
        "last 300 s: median reading along the wind (m; < 0 upwind)",
        "last 300 s: detections upwind",
        "final mean along the wind (m)",
        "final spread √tr P (m)",
        "final RMSE (m)",
        "truth in 95 %",
    ]
    return table(header, rows)
