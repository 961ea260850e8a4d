"""Several releases, their number unknown (recipes source-count*)."""

from __future__ import annotations

import pandas as pd

from studies.tables.common import (
    RESULTS,
    ROOT,
    table,
)


def _source_count(kind: str) -> str:
    """Issue 45's unknown-count study: studies/source_count_table.py's tables of the stored
    searches (``kind`` "table", "table_latest", "paired", "observable" or "worst")."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "source_count_table", ROOT / "studies" / "source_count_table.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    frame = pd.read_csv(RESULTS / "source-count" / "searches.csv")
    return getattr(module, kind)(frame) + "\n"


def source_count_timing_table() -> str:
    """Decision and update time with the count unknown (studies/source_count_timing.py)."""
    frame = pd.read_csv(RESULTS / "source-count" / "timing.csv")
    rows = [
        [
            str(r["truth"]),
            str(int(r["max_sources"])),
            f"{r['decision_ms_mean']:.1f} ({r['decision_ratio']:.2f}×)",
            f"{r['update_ms_mean']:.1f} ({r['update_ratio']:.2f}×)",
            f"{r['load_before']:.2f}",
        ]
        for _, r in frame.iterrows()
    ]
    return table(
        [
            "truth (dcee-cl, seed 0, 10,000 particles, one pinned core)",
            "estimator.max_sources",
            "mean decision (ms) (× one release)",
            "mean update per reading (ms) (× one release)",
            "load before",
        ],
        rows,
    )
