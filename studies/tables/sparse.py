"""Issue 78, item 4: where gas is rare on the 3-D plume, which change shrinks the spread (recipe
lbm3d-sparse-tune; a tuning range, never a claim)."""

from __future__ import annotations

import json

from studies.tables.common import RESULTS, table

FOLDER = RESULTS / "lbm3d-sparse-tune"
ARMS = {
    "today": "today's defaults",
    "weak-zeros": "zero readings say less (intermittency 0.7, not 0.93)",
    "no-average": "no hold averaging (the hold's last sample)",
}


def _paired(row: dict, key: str) -> str:
    pair = row.get(f"paired_{key}")
    if pair is None:
        return ""
    return f"{pair['median_difference']:+.2f} m (p = {pair['wilcoxon_p']:.2g})"


def sparse_table() -> str:
    """Per arm and planner: searches, median detections, searches below 60 detections, median
    final spread and RMSE, acquired, truth in the 95 % region, and the paired change of the
    spread and the RMSE against today's dcee-cl on the same configurations."""
    doc = json.loads((FOLDER / "sparse.json").read_text(encoding="utf-8"))
    rows = []
    for r in doc["rows"]:
        n = r["searches"]
        rows.append(
            [
                ARMS.get(r["arm"], r["arm"]),
                f"`{r['strategy']}`",
                str(n),
                f"{r['median_detections']:.0f} ({r['sparse_searches']} below 60)",
                f"{r['median_final_spread']:.2f}",
                f"{r['median_final_rmse']:.2f}",
                f"{r['acquired']}/{n}",
                f"{r['truth_in_95']}/{n}",
                _paired(r, "final_spread"),
                _paired(r, "final_rmse"),
            ]
        )
    return table(
        [
            "change",
            "planner",
            "searches (tuning)",
            "median detections",
            "median final spread (m)",
            "median final RMSE (m)",
            "acquired",
            "truth in 95 % region",
            "paired spread change",
            "paired RMSE change",
        ],
        rows,
    )
