"""Numbers quoted on the pages agree with the stored results they cite.

docs/results/<study>/ hold the stored study results; studies/publish_tables.py writes the
tables of the README, docs/index.md, docs/results.md and docs/held-out.md from them (checked here).
docs/results/public-wind-known-dcee-cl holds the `dcee report` tables of the public wind-known
`dcee-cl` study (`bash studies/run.sh public-wind-known` regenerates them); docs/turbulent.md's
row is formatted from them here and must appear verbatim."""

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


def _publisher():
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "publish_tables", ROOT / "studies" / "publish_tables.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_generated_tables_agree_with_the_stored_results():
    """Every table between generated markers on the README, docs/index.md, docs/results.md
    and docs/held-out.md is what studies/publish_tables.py writes from docs/results/."""
    pub = _publisher()
    used = set()
    for page in pub.PAGES:
        text = (ROOT / page).read_text(encoding="utf-8")
        names = [m.group("name") for m in pub.MARKER.finditer(text)]
        assert names, f"{page} has no generated table"
        used.update(names)
        _, stale = pub.render(text)
        assert not stale, f"{page}: {stale} disagree (run python studies/publish_tables.py)"
    assert used == set(pub.TABLES), "every table is published, every marker known"
    assert pub.main(["--check"]) == 0


def test_the_check_catches_a_number_typed_by_hand():
    pub = _publisher()
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    body = next(pub.MARKER.finditer(text)).group("body")
    edited = text.replace(body, body.replace("120/120", "119/120", 1))
    assert edited != text
    _, stale = pub.render(edited)
    assert stale == ["headline"]


def test_the_readme_is_a_front_door():
    """The README shows the product in one screen (issue 79): at most 150 lines, one results
    table of at most 8 rows whose labels are at most 60 characters (what a row is, its range
    and its date are on the page it links), and links that reach a first study and one's own
    plume data."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150
    tables = [m.group("body") for m in _publisher().MARKER.finditer(text)]
    assert len(tables) == 1
    rows = [line for line in tables[0].splitlines() if line.startswith("| ")][1:]
    assert 1 <= len(rows) <= 8
    for row in rows:
        label = row.split(" | ")[0].removeprefix("| ")
        assert len(label) <= 60, label
    for page in ("docs/guide/first-study.md", "docs/guide/plume-data.md", "docs/guide/site.md"):
        assert f"]({page})" in text and (ROOT / page).is_file(), page


def test_every_stored_study_says_where_it_came_from():
    for folder in sorted((ROOT / "docs" / "results").iterdir()):
        if folder.is_dir():
            readme = (folder / "README.md").read_text(encoding="utf-8")
            assert "studies/run.sh" in readme, folder.name
            # tables (csv; here or in a folder per arm), or the stored timing runs of
            # docs/results/perf (json)
            assert any(folder.rglob("*.csv")) or any(folder.glob("*.json")), folder.name
