"""Searches on a site in geographic coordinates, checked position by position against the site
file (recipe geo-site, issue 81)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from studies.tables.common import RESULTS, table

FOLDER = RESULTS / "geo-site"
"""The constructed example site's check (recipe geo-site)."""
REAL_SITE_FOLDER = RESULTS / "geo-site-fontvieille"
"""The real site's check (recipe geo-site-fontvieille: area:fontvieille, OpenStreetMap)."""


def geo_site_table(folder: Path = FOLDER) -> str:
    """Per planner: searches, positions checked, positions or segments in a building the UAV
    cannot overfly, a no-go zone or outside the fence, acquired, median final RMSE, from the
    ``check.json`` in ``folder`` (studies/geo_site_check.py)."""
    check = json.loads((folder / "check.json").read_text(encoding="utf-8"))
    rows = []
    for strategy in sorted({r["strategy"] for r in check["searches"]}):
        runs = [r for r in check["searches"] if r["strategy"] == strategy]
        rmse = np.array([r["final_rmse"] for r in runs])
        rows.append(
            [
                f"`{strategy}`",
                str(len(runs)),
                f"{sum(r['positions'] for r in runs):,}",
                str(sum(len(r["entered"]) for r in runs)),
                f"{sum(r['source_acquired'] for r in runs)}/{len(runs)}",
                f"{np.median(rmse):.2f} ({rmse.min():.2f}-{rmse.max():.2f})",
            ]
        )
    return table(
        [
            "planner",
            "searches",
            "positions checked",
            "positions or moves in a building, no-go zone or outside the fence",
            "acquired (RMSE < 3 m)",
            "median final RMSE (m) (range)",
        ],
        rows,
    )
