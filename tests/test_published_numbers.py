"""Numbers quoted on the pages agree with the stored results they cite.

docs/results/public-wind-known-dcee-cl holds the `dcee report` tables of the public wind-known
`dcee-cl` study (`bash studies/run.sh public-wind-known` regenerates them); the README's row and
docs/turbulent.md's row are formatted from them here and must appear verbatim."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "docs" / "results" / "public-wind-known-dcee-cl"


def _study() -> pd.Series:
    table = pd.read_csv(STUDY / "metrics.csv")
    return table.set_index("strategy").loc["dcee-cl"]


def _pct(x: float) -> str:
    return f"{100 * x:.0f}"


def test_readme_quotes_the_stored_public_study():
    s = _study()
    n = int(s["searches"])
    acquired = round(s["source_acquired_rate"] * n)
    row = f"| {acquired}/{n} | {s['median_final_rmse']:.2f} m | {s['time_to_1m']:.0f} s |"
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    line = next(x for x in readme.splitlines() if "current defaults (2026-11-25" in x)
    assert line.endswith(row), (line, row)


def test_turbulent_page_quotes_the_stored_public_study():
    s = _study()
    n = int(s["searches"])
    acquired = round(s["source_acquired_rate"] * n)
    row = (
        f"| 0.01 (new default) | {n} | {acquired}/{n}, {_pct(s['source_acquired_rate'])} "
        f"[{_pct(s['source_acquired_lo'])}, {_pct(s['source_acquired_hi'])}] % "
        f"| {s['median_final_rmse']:.2f} [{s['median_final_rmse_lo']:.2f}, "
        f"{s['median_final_rmse_hi']:.2f}] "
        f"| {s['time_to_1m']:.0f} [{s['time_to_1m_lo']:.0f}, {s['time_to_1m_hi']:.0f}] "
        f"| {_pct(s['truth_in_95_rate'])} [{_pct(s['truth_in_95_lo'])}, "
        f"{_pct(s['truth_in_95_hi'])}] % | {s['longest_stall']:.0f} |"
    )
    page = (ROOT / "docs" / "turbulent.md").read_text(encoding="utf-8")
    assert row in page, row
