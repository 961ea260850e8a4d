"""Search in three dimensions on the 3-D surface-layer plume (recipe lbm3d, issue 78)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import wilcoxon

from dcee.recordings.statistics import briggs_sigma_y, briggs_sigma_z
from dcee.simulation.lbm3d_solver import SURFACE_LAYER_SIGMAS
from studies.tables.common import RESULTS, table

FOLDER = RESULTS / "lbm3d"
HEIGHTS = ("0.25", "0.75", "1.25", "1.75", "2.25", "2.75")
DISTANCES = (10.0, 20.0, 40.0)
CAMPAIGNS = (
    ("lbm3d-held-out-100", "3-D plume, stored in 1 m blocks", "random:7000-7099"),
    ("lbm3d-held-out-100b", "3-D plume, every 0.5 m cell stored", "random:7100-7199"),
    (
        "lbm3d-slice-held-out-50",
        "its 4 m slice (1 m blocks), as a planar recording",
        "50 from random:8000",
    ),
)
LOOKS = {"lbm3d-held-out-100": 1, "lbm3d-held-out-100b": 1, "lbm3d-slice-held-out-50": 1}
"""How many times each published range was looked at (flown and read) before these rows: the
protocol of docs/three-d.md. A range looked at and then changed for becomes a tuning range."""


CLAIM = "lbm3d-held-out-100b"
"""The flight of issue 78's claim (the truth stored cell by cell, a range never flown before)."""


def load_result(name: str) -> dict:
    """A stored JSON of docs/results/lbm3d (studies/lbm3d_table.py and the plume checks)."""
    return json.loads((FOLDER / name).read_text(encoding="utf-8"))


def lbm3d_plume_table() -> str:
    """The six release cells' spreads against Briggs and their turbulence against Panofsky &
    Dutton (``dcee plume --model lbm3d --json``)."""
    rows = []
    for h in HEIGHTS:
        doc = load_result(f"plume-{h}.json")
        by_x = {round(s["x"]): s for s in doc["sections"]}
        cells = []
        for d in DISTANCES:
            s = by_x[round(d)]
            cells.append(f"{s['sigma_y']:.1f} / {s['sigma_z']:.1f} / {s['centroid_z']:.1f}")
        t = doc["turbulence_over_u_star"]
        rows.append(
            [f"{doc['release_height']:g}", *cells, " / ".join(f"{t[c]:.2f}" for c in "uvw")]
        )
    rows.append(
        [
            "Briggs D … A",
            *(
                f"{briggs_sigma_y(d, 'D'):.1f}…{briggs_sigma_y(d, 'A'):.1f} / "
                f"{briggs_sigma_z(d, 'D'):.1f}…{briggs_sigma_z(d, 'A'):.1f} / —"
                for d in DISTANCES
            ),
            " / ".join(f"{v:g}" for v in SURFACE_LAYER_SIGMAS) + " (P&D)",
        ]
    )
    header = [
        "release (m)",
        *(f"{d:g} m: σ_y / σ_z / z̄ (m)" for d in DISTANCES),
        "σu / σv / σw over u*",
    ]
    return table(header, rows)


def lbm3d_search_table() -> str:
    """The held-out 3-D searches and the slice's (studies/lbm3d_table.py)."""
    rows = []
    for name, what, range_ in CAMPAIGNS:
        for r in load_result(f"{name}.json")["rows"]:
            n = r["searches"]
            lo, hi = r["median_final_rmse_ci95"]
            rows.append(
                [
                    what,
                    f"`{r['strategy']}`",
                    range_,
                    str(LOOKS[name]),
                    f"{r['acquired']}/{n}",
                    f"{r['median_final_rmse']:.2f} [{lo:.2f}, {hi:.2f}]",
                    f"{r['truth_in_95']}/{n}",
                    f"{r['median_detections']:.0f}",
                    f"{r['lowest_altitude']:g}-{r['highest_altitude']:g}",
                ]
            )
    header = [
        "truth",
        "planner",
        "configurations",
        "looks",
        "acquired",
        "median final 3-D RMSE (m) [95 % CI]",
        "truth in 95 % region",
        "median detections",
        "altitudes (m)",
    ]
    return table(header, rows)


def lbm3d_altitude_table() -> str:
    """The share of readings at each altitude (studies/lbm3d_table.py)."""
    name = CLAIM  # the claim's flight
    rows_in = load_result(f"{name}.json")["rows"]
    levels = sorted({float(z) for r in rows_in for z in r["altitude_share"]})
    rows = [
        [
            f"`{r['strategy']}`",
            *(f"{100 * r['altitude_share'].get(f'{z:g}', 0.0):.0f} %" for z in levels),
        ]
        for r in rows_in
    ]
    return table(["planner", *(f"{z:g} m" for z in levels)], rows)


def lbm3d_timing_table() -> str:
    """One decision with the altitude free and at a fixed altitude (studies/altitude_timing.py)."""
    doc = load_result("altitude-timing.json")
    med = doc["median_ms"]
    load = doc["load"]
    rows = [
        [
            name,
            str(doc["moves"][name]),
            f"{med[name]:.0f}",
            f"{len(doc['decisions_ms'][name])}",
        ]
        for name in ("fixed altitude", "altitude free")
    ]
    rows.append(["ratio", "", f"{doc['ratio']:.2f}x", ""])
    body = table(["dcee-cl decision", "moves", "median (ms)", "decisions"], rows)
    cpu = doc.get("cpu_model") or doc["machine"].get("machine", "")
    return body + (
        f"\nOne pinned core of an {cpu} ({doc['machine']['cpus']} CPUs), alternating decision by "
        f"decision; other processes used {load.get('other_cores', 0):.2f} cores on average.\n"
    )


__all__ = [
    "lbm3d_altitude_table",
    "lbm3d_plume_table",
    "lbm3d_search_table",
    "lbm3d_timing_table",
]


SURFACE_PROBE = (
    ("lbm3d-tune", "3-D plume", "random:1-40", "today's"),
    ("lbm3d-tune-surface", "3-D plume", "random:1-40", "surface layer"),
    ("lbm3d-slice-tune", "4 m slice", "lbm3d-slice-tune (20)", "today's"),
    ("lbm3d-slice-tune-surface", "4 m slice", "lbm3d-slice-tune (20)", "surface layer"),
)


def _pairs(folder: Path, key: str) -> dict[str, dict]:
    """The rows of ``folder``/pairs.csv (studies/pair_campaigns.py) by their ``key`` column."""
    with (folder / "pairs.csv").open(encoding="utf-8") as f:
        return {r[key]: r for r in csv.DictReader(f)}


def _campaign_row(folder: Path, name: str) -> dict:
    """The first strategy's row of ``folder``/``name``.json (studies/lbm3d_table.py)."""
    return json.loads((folder / f"{name}.json").read_text(encoding="utf-8"))["rows"][0]


def _paired(p: dict) -> str:
    """A pairs.csv row's median paired RMSE change with its Wilcoxon p."""
    change, p_value = float(p["median_rmse_b_minus_a"]), float(p["rmse_wilcoxon_p"])
    return f"{change:+.2f} m (p = {p_value:.2g})"


def lbm3d_surface_tune_table() -> str:
    """The surface-layer reading model beside today's on the tuning ranges (recipe
    lbm3d-surface-tune; studies/lbm3d_table.py and studies/pair_campaigns.py)."""
    folder = RESULTS / "lbm3d-surface-tune"
    pairs = _pairs(folder, "truth")
    rows = []
    for name, truth, range_, model in SURFACE_PROBE:
        r = _campaign_row(folder, name)
        n = r["searches"]
        lo, hi = r["median_final_rmse_ci95"]
        paired = ""
        if model != "today's":
            paired = _paired(pairs["3-D" if truth == "3-D plume" else "slice"])
        rows.append(
            [
                truth,
                range_,
                model,
                f"{r['acquired']}/{n}",
                f"{r['median_final_rmse']:.2f} [{lo:.2f}, {hi:.2f}]",
                f"{r['truth_in_95']}/{n}",
                f"{r['median_downwind_error']:+.2f}",
                f"{r['median_height_error']:+.2f}",
                paired,
            ]
        )
    header = [
        "truth",
        "configurations (tuning)",
        "reading model",
        "acquired",
        "median final RMSE (m) [95 % CI]",
        "truth in 95 % region",
        "error downwind (m, median)",
        "error in height (m, median)",
        "paired RMSE change (Wilcoxon)",
    ]
    return table(header, rows)


def lbm3d_store_tune_table() -> str:
    """The 3-D plume stored in 1 m blocks against every 0.5 m cell, 17 searches of the tuning
    range (docs/results/lbm3d-store-tune/pairs.csv)."""
    pairs = pd.read_csv(RESULTS / "lbm3d-store-tune" / "pairs.csv")
    n = len(pairs)
    diff = pairs["rmse_cells_05m"] - pairs["rmse_blocks_1m"]
    p_value = float(wilcoxon(diff).pvalue)
    rows = []
    for label, key in (
        ("1 m blocks (until 2026-12-05)", "blocks_1m"),
        ("every 0.5 m cell", "cells_05m"),
    ):
        rows.append(
            [
                label,
                str(n),
                f"{np.median(pairs[f'rmse_{key}']):.2f}",
                f"{np.median(pairs[f'downwind_{key}']):+.2f}",
                f"{int(pairs[f'in95_{key}'].sum())}/{n}",
                "" if key == "blocks_1m" else f"{np.median(diff):+.2f} m (p = {p_value:.1g})",
            ]
        )
    header = [
        "truth's recording",
        "searches (tuning)",
        "median final RMSE (m)",
        "error downwind (m, median)",
        "truth in 95 % region",
        "paired change (Wilcoxon)",
    ]
    return table(header, rows)


SLICE_PROBES = (
    ("lbm3d-slice-tune-cells", "today's defaults"),
    ("lbm3d-slice-tune-height-known", "the source height declared known (a diagnostic)"),
    ("lbm3d-slice-tune-decay", "the fall learned: 1/r or 1/r^(1/2)"),
    ("lbm3d-slice-tune-decay-surface", "that, with the ground and vertical ratio 0.66"),
    ("lbm3d-slice-tune-vmeander", "a vertical meander, i_z = 0.1"),
    ("lbm3d-slice-tune-anemometer", "a measured wind (the anemometer on)"),
    (
        "lbm3d-slice-tune-height-wind",
        "the source height declared known and the wind measured (a diagnostic)",
    ),
)
"""The slice's tuning probes, one change of the reading model at a time (recipes
lbm3d-store-tune and lbm3d-slice-probes)."""


def lbm3d_slice_probes_table() -> str:
    """The slice's tuning range under each probe of the reading model (recipe
    lbm3d-slice-probes; studies/lbm3d_table.py and studies/pair_campaigns.py)."""
    folder = RESULTS / "lbm3d-slice-probes"
    pairs = _pairs(folder, "arm")
    rows = []
    for name, change in SLICE_PROBES:
        r = _campaign_row(folder, name)
        n = r["searches"]
        lo, hi = r["median_final_rmse_ci95"]
        paired = _paired(pairs[name]) if name in pairs else ""
        rows.append(
            [
                change,
                f"{r['acquired']}/{n}",
                f"{r['median_final_rmse']:.2f} [{lo:.2f}, {hi:.2f}]",
                f"{r['median_downwind_error']:+.2f}",
                f"{r['median_height_error']:+.2f}",
                f"{r['median_final_spread']:.2f}",
                f"{r['truth_in_95']}/{n}",
                f"{r['median_detections']:.0f}",
                paired,
            ]
        )
    header = [
        "reading model (lbm3d-slice-tune, 20 searches)",
        "acquired",
        "median final RMSE (m) [95 % CI]",
        "error downwind (m, median)",
        "error in height (m, median)",
        "final spread (m, median)",
        "truth in 95 % region",
        "median detections",
        "paired RMSE change (Wilcoxon)",
    ]
    return table(header, rows)


SLICE_ORACLES = (
    (
        "reading-model-rate-unknown",
        "oracle: today's reading model, its exact posterior (height and wind known, ζ1, ζ2 and "
        "the rate weighed)",
    ),
    ("reading-model", "oracle: the same, the release rate known too"),
    (
        "reading-model-meander-0.1",
        "oracle: that, its likelihood a mixture over a meandering centre height, i_z = 0.1 (a "
        "probe)",
    ),
    ("reading-model-meander-0.2", "oracle: the same, i_z = 0.2 (a probe)"),
    (
        "reading-model-gamma-1",
        "oracle: today's plume, rate known, its fluctuations gamma of intensity 1 (the "
        "exponential; a probe)",
    ),
    (
        "gaussian-rate-unknown",
        "oracle: a textbook Gaussian plume instead (Taylor's growth, σ = √(0.3² + (i d)²), the "
        "ground reflecting; i_y, i_z and the rate weighed; a probe)",
    ),
    (
        "mean",
        "oracle: the plume's exact time mean, read through the estimator's log-normal fluctuations",
    ),
    (
        "mean-gamma-0.7",
        "oracle: the plume's exact time mean, its fluctuations gamma of intensity 0.7 (a probe)",
    ),
    ("mean-gamma-1", "oracle: the same, intensity 1 (the exponential of Hanna 1984; a probe)"),
    ("mean-gamma-1.5", "oracle: the same, intensity 1.5 (a probe)"),
    ("mean-gamma-1-rate-unknown", "oracle: intensity 1, the release rate unknown (1/4 to 4 times)"),
    ("mixture", "oracle: the plume's own fluctuation statistics (its every frame, held-averaged)"),
    ("mixture-rate-unknown", "oracle: the same, the release rate unknown (1/4 to 4 times)"),
    (
        "known-environment-exact",
        "oracle: today's reading model, its exact posterior, the height, wind and ζ declared "
        "known (the scenario's ζ), the rate weighed (1/4 to 4 times)",
    ),
    (
        "known-environment-filter-10000",
        "not an oracle: `dcee-cl`'s own filter (10,000 particles, its own priors) told the same "
        "readings, the height, wind and ζ declared known",
    ),
    ("known-environment-filter-40000", "the same, 40,000 particles"),
    (
        "known-environment-filter-10000-untempered",
        "the same, 10,000 particles, each reading weighing 1 (`reading_weight` 1, "
        "`repeat_radius` 0)",
    ),
)
"""The slice oracle's arms (recipe lbm3d-slice-oracle, studies/slice_oracle.py)."""


def lbm3d_slice_oracle_table() -> str:
    """How well an estimator that knows the plume could place the source from the readings the
    slice's tuning searches took (recipe lbm3d-slice-oracle; studies/slice_oracle.py)."""
    folder = RESULTS / "lbm3d-slice-oracle"
    arms = {name: json.loads((folder / f"{name}.json").read_text()) for name, _ in SLICE_ORACLES}
    searches = arms["mixture"]["searches"]
    if any(a["campaign"] != arms["mixture"]["campaign"] for a in arms.values()):
        raise ValueError("the slice oracle's arms read different campaigns")
    n = len(searches)
    own = np.array([s["search_final_rmse"] for s in searches])
    rows = [
        [
            "`dcee-cl` itself at today's defaults (3-D, every parameter unknown)",
            f"{np.median(own):.2f}",
            f"{int((own <= 1.0).sum())}/{n}",
            "",
            "",
            "",
        ]
    ]
    for name, label in SLICE_ORACLES:
        o = [s["oracle"] for s in arms[name]["searches"]]
        rmse = np.array([x["rmse"] for x in o])
        rows.append(
            [
                label,
                f"{np.median(rmse):.2f}",
                f"{int((rmse <= 1.0).sum())}/{n}",
                f"{sum(x['truth_in_95'] for x in o)}/{n}",
                f"{np.median([x['sd_along'] for x in o]):.2f}",
                f"{np.median([x['error_along'] for x in o]):+.2f}",
            ]
        )
    header = [
        f"who places the source (lbm3d-slice-tune, the {n} searches' own readings)",
        "median final RMSE (m)",
        "≤ 1.0 m",
        "truth in its 95 % region",
        "spread along the wind (m, median)",
        "error along the wind (m, median)",
    ]
    return table(header, rows)


def lbm3d_slice_zeros_table() -> str:
    """How often the slice reads nothing where its time mean is some value: the truth against
    the estimator's fluctuation model, pooled over the tuning range's 20 planes (recipe
    lbm3d-slice-oracle; studies/slice_oracle.py --zeros)."""
    doc = json.loads((RESULTS / "lbm3d-slice-oracle" / "zeros.json").read_text())
    pooled: dict[tuple[float, float], list[float]] = {}
    for search in doc["searches"]:
        for b in search["zeros"]:
            acc = pooled.setdefault((b["low"], b["high"]), [0.0, 0.0, 0.0])
            acc[0] += b["cells"]
            acc[1] += b["cells"] * b["truth_zero_share"]
            acc[2] += b["cells"] * b["model_zero_probability"]
    rows = [
        [
            f"{lo * 1e3:g}-{hi * 1e3:g}",
            f"{int(n):,}",
            f"{truth / n:.2f}",
            f"{model / n:.2f}",
        ]
        for (lo, hi), (n, truth, model) in sorted(pooled.items())
    ]
    header = [
        "time mean at the plane (mg/m³)",
        "cells (20 planes)",
        "readings below the threshold: the plume",
        "the reading model's P(non-detection)",
    ]
    return table(header, rows)


def lbm3d_slice_tails_table() -> str:
    """The plane's gas against a Gaussian profile's, per recording of the slice's tuning range
    (recipe lbm3d-slice-oracle; studies/slice_oracle.py --tails)."""
    doc = json.loads((RESULTS / "lbm3d-slice-oracle" / "tails.json").read_text())
    rows = []
    for rec in sorted(doc["recordings"], key=lambda r: r["release"]):
        for s in rec["sections"]:
            rows.append(
                [
                    f"{rec['release']:.2f}",
                    f"{rec['plane'] - rec['release']:.2f}",
                    f"{s['distance']:g}",
                    f"{s['centroid']:.2f} / {s['sigma_z']:.2f}",
                    f"{s['plane_over_release']:.2g}",
                    f"{s['gaussian_plane_over_release']:.2g}",
                ]
            )
    header = [
        "release cell (m)",
        "plane above the release (m; the cell's first search)",
        "downwind (m)",
        "centroid z̄ / σ_z (m)",
        "plane / release height: the plume",
        "a Gaussian of that z̄ and σ_z",
    ]
    return table(header, rows)
