"""The 95 % region at each model-discrepancy floor (``estimator.region_floor``, issue 42): the
share of searches with the truth inside it, per truth, and the rule that chooses the default.

Reads searches that recorded ``truth_in_95_floor`` (every summary since the floor existed):
a ``studies/precision_variants.py`` CSV (columns ``truth_in_95_floor_<σ>``) or campaign
folders (every ``summary.json`` below them). Writes one row per truth and floor: n, inside, the
share with its Wilson 95 % interval, and the median RMS radius of the floored region
√(spread² + D σ²), m.

    .venv/bin/python studies/region_floor.py docs/results/tuning-region-floor-13-40/variants.csv \\
        --csv docs/results/tuning-region-floor-13-40/coverage.csv --choose 0.95
    .venv/bin/python studies/region_floor.py results/turbulent-lbm-held-out-100-floor \\
        --csv docs/results/lbm-held-out-100/region_floor.csv

``--choose LEVEL`` applies the rule written before the tuning run
(docs/results/tuning-region-floor-13-40/README.md): the smallest floor at which every truth's
share reaches LEVEL (else the largest floor), printed as ``chosen floor: σ``.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

PREFIX = "truth_in_95_floor_"


def _searches(source: Path) -> list[dict]:
    """One dict per search: truth, dims, spread, {floor: inside}."""
    out = []
    if source.is_file():
        with open(source, newline="") as fh:
            for row in csv.DictReader(fh):
                floors = {
                    float(k[len(PREFIX) :]): v == "True"
                    for k, v in row.items()
                    if k.startswith(PREFIX)
                }
                out.append(
                    {
                        "truth": row["truth"],
                        "dims": 3,  # precision_variants flies the 3-D turbulent truths
                        "spread": float(row["final_spread"]),
                        "floors": floors,
                    }
                )
        return out
    for path in sorted(source.rglob("summary.json")):  # a campaign's runs/config=…/…/seed=…/
        s = json.loads(path.read_text())
        if "truth_in_95_floor" not in s:
            continue
        out.append(
            {
                "truth": s.get("truth_model", "?"),
                "dims": sum(1 for n in s.get("parameter_names", ["x", "y", "z"]) if n in "xyz"),
                "spread": float(s["final_spread"]),
                "floors": {float(k): bool(v) for k, v in s["truth_in_95_floor"].items()},
            }
        )
    return out


def coverage_rows(searches: list[dict]) -> list[dict]:
    """Per truth (and ``all`` when there are several) and floor: the share inside."""
    truths = sorted({s["truth"] for s in searches})
    groups = [(t, [s for s in searches if s["truth"] == t]) for t in truths]
    if len(truths) > 1:
        groups.append(("all", searches))
    floors = sorted({f for s in searches for f in s["floors"]})
    rows = []
    for truth, group in groups:
        for f in floors:
            hits = sum(s["floors"][f] for s in group)
            ci = binomtest(hits, len(group)).proportion_ci(0.95, method="wilson")
            radius = np.median([math.sqrt(s["spread"] ** 2 + s["dims"] * f**2) for s in group])
            rows.append(
                {
                    "truth": truth,
                    "floor": f,
                    "n": len(group),
                    "inside": hits,
                    "share": hits / len(group),
                    "lo": ci.low,
                    "hi": ci.high,
                    "median_radius": float(radius),
                }
            )
    return rows


def choose(rows: list[dict], level: float) -> float:
    """The smallest floor at which every truth's share is at least ``level`` (else the largest)."""
    floors = sorted({r["floor"] for r in rows})
    for f in floors:
        if all(
            r["share"] >= level - 1e-12 for r in rows if r["floor"] == f and r["truth"] != "all"
        ):
            return f
    return floors[-1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sources", nargs="+", type=Path, help="a variants CSV or campaign folders")
    ap.add_argument("--csv", type=Path, default=None, help="where to write the table")
    ap.add_argument("--choose", type=float, default=None, help="apply the rule at this share")
    args = ap.parse_args(argv)
    searches = [s for src in args.sources for s in _searches(src)]
    if not searches:
        print("error: sources: no search recorded truth_in_95_floor", file=sys.stderr)
        return 2
    rows = coverage_rows(searches)
    for r in rows:
        print(
            f"{r['truth']:9s} floor {r['floor']:.2f} m: {r['inside']}/{r['n']} "
            f"{r['share']:.0%} [{r['lo']:.0%}, {r['hi']:.0%}], radius {r['median_radius']:.2f} m"
        )
    if args.csv is not None:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    if args.choose is not None:
        print(f"chosen floor: {choose(rows, args.choose):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
