"""The README's and docs/index.md's one table (recipes: every study it cites)."""

from __future__ import annotations

import pandas as pd

from studies.tables.common import (
    RESULTS,
    count,
    latest_defaults,
    pick,
    study,
    table,
)
from studies.tables.three_d import load_result as lbm3d_result

HEADLINE_HEADER = [
    "result",
    "`dcee-cl`",
    "`infotaxis`",
    "defaults tuned on this truth",
    "stored in docs/results/",
    "details",
]
"""Each planner's cell: searches that acquired the source, and the median final error."""


def _headline_cell(r: pd.Series | None) -> str:
    """ "120/120, 0.21 m" (a missing row: "—")."""
    if r is None:
        return "—"
    return f"{count(r)}, {r['median_final_rmse']:.2f} m"


def headline_table(docs: str = "docs/") -> str:
    """The README's one table (docs/index.md too, ``docs`` "" for links from there): short
    labels, the study folder and the page that says what each row is, when it was flown and at
    which defaults. Per planner the latest defaults flown on that truth (the linked page says
    which)."""
    rows: list[list[str]] = []

    def add(label: str, cl, info, chosen: str, source: str, page: str) -> None:
        assert len(label) <= 60, label
        rows.append([label, _headline_cell(cl), _headline_cell(info), chosen, f"`{source}`", page])

    paper_source, paper_full = study("paper-source"), study("paper-full")
    results = f"[results]({docs}results.md)"
    for label, frame, name in (
        ("The paper's study: 12 configurations × 10, wind known", paper_source, "paper-source"),
        ("The paper's study, all eight parameters unknown", paper_full, "paper-full"),
    ):
        add(label, pick(frame, "dcee-cl"), pick(frame, "infotaxis"), "yes", name, results)
    today = study("held-out-today")
    held_out = f"[held-out]({docs}held-out.md)"
    for label, name in (
        ("200 held-out configurations, wind known", "wind-known"),
        ("200 held-out configurations, all eight unknown", "full"),
    ):
        add(
            label,
            pick(today, "dcee-cl", study=name),
            pick(today, "infotaxis", study=name),
            "yes",
            "held-out-today",
            held_out,
        )
    turbulent = study("turbulent-held-out-100-today")
    # the filament plume (ours) is on its page only: the README's table holds eight rows, and a
    # truth nobody here wrote says more (docs/turbulent.md has both)
    newest = latest_defaults(turbulent, ("dcee-cl", "infotaxis"), truth_model="puffs")
    add(
        "100 held-out, turbulent puff plume (Farrell et al. 2002)",
        pick(turbulent, "dcee-cl", truth_model="puffs", defaults=newest),
        pick(turbulent, "infotaxis", truth_model="puffs", defaults=newest),
        "yes",
        "turbulent-held-out-100-today",
        f"[turbulent plumes]({docs}turbulent.md)",
    )
    lbm = study("lbm-held-out-100")
    lbm = lbm[(lbm["learn"] == "none") & ~lbm["strategy"].astype(str).str.contains(":")]
    newest = latest_defaults(lbm, ("dcee-cl", "infotaxis"))
    add(
        "100 held-out, a fluid solver's plume (lbmpy)",
        pick(lbm, "dcee-cl", defaults=newest),
        pick(lbm, "infotaxis", defaults=newest),
        "**no**",
        "lbm-held-out-100",
        f"[plumes nobody here wrote]({docs}plumes.md)",
    )
    # the claim's flight; its slice (5/50, 7.15 m) is said under the table, in words
    three_d = {
        r["strategy"]: pd.Series(
            {
                "searches": r["searches"],
                "source_acquired_rate": r["acquired"] / r["searches"],
                "median_final_rmse": r["median_final_rmse"],
            }
        )
        for r in lbm3d_result("lbm3d-held-out-100b.json")["rows"]
    }
    add(
        "100 held-out, a 3-D plume (lbmpy), the UAV climbing",
        three_d.get("dcee-cl"),
        three_d.get("infotaxis"),
        "**no**",
        "lbm3d",
        f"[three dimensions]({docs}three-d.md)",
    )
    searches = pd.read_csv(RESULTS / "source-count" / "searches.csv")
    two = searches[searches["campaign"] == "two-source-held-out-100-climb"]
    label = "100 held-out, two releases, their number unknown"
    assert len(label) <= 60
    rows.append(
        [
            label,
            f"count right {int(two['count_correct'].sum())}/{len(two)}, "
            f"median OSPA {two['final_ospa'].median():.2f} m",
            "—",
            "yes",
            "`source-count`",
            f"[several releases]({docs}multi-source.md)",
        ]
    )
    return table(HEADLINE_HEADER, rows)
