"""Where a turbulent campaign's calibration fails: along the wind or across it (issue 29).

For every search of the campaigns given (``dcee bench`` folders with ``posterior.npz``), the final
posterior sample's mean error and spread are split into the along-wind component (positive:
the estimate lies upwind of the source) and the crosswind one, and each error is divided by the
spread in its direction. A calibrated posterior has median |z| ≈ 0.67 in both directions and a
median error near 0; what is left is reported per campaign and planner.

    .venv/bin/python studies/calibration_diagnosis.py results/turbulent-puffs-held-out-100-cm \\
        results/turbulent-filament-held-out-cm [--csv out.csv]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd


def search_rows(campaign: Path) -> list[dict]:
    rows = []
    for folder in sorted(campaign.glob("runs/*/*/*")):
        if not (folder / "posterior.npz").exists():
            continue
        summary = json.loads((folder / "summary.json").read_text())
        truth = json.loads((folder / "config.json").read_text())["scenario"]["truth"]
        sample = np.load(folder / "posterior.npz")["final_particles"][:, :2]
        phi = math.radians(truth["phi"])
        up = np.array([math.cos(phi), math.sin(phi)])  # towards where the wind comes from
        across = np.array([-up[1], up[0]])
        mean = sample.mean(axis=0)
        error = mean - np.array([truth["x"], truth["y"]])
        spread = sample - mean
        rows.append(
            {
                "campaign": campaign.name,
                "strategy": summary["strategy"],
                "config": summary["config"],
                "truth_in_95": summary["truth_in_95"],
                "upwind_error": float(error @ up),
                "crosswind_error": float(error @ across),
                "upwind_sd": float(np.sqrt(np.mean((spread @ up) ** 2))),
                "crosswind_sd": float(np.sqrt(np.mean((spread @ across) ** 2))),
            }
        )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", type=Path)
    ap.add_argument("--csv", type=Path)
    args = ap.parse_args()
    df = pd.DataFrame([r for c in args.campaigns for r in search_rows(c)])
    df["z_up"] = (df.upwind_error / df.upwind_sd).abs()
    df["z_cross"] = (df.crosswind_error / df.crosswind_sd).abs()
    table = df.groupby(["campaign", "strategy"]).agg(
        n=("config", "size"),
        truth_in_95=("truth_in_95", "mean"),
        upwind_error_median=("upwind_error", "median"),
        upwind_sd_median=("upwind_sd", "median"),
        crosswind_sd_median=("crosswind_sd", "median"),
        z_up_median=("z_up", "median"),
        z_cross_median=("z_cross", "median"),
    )
    t = table.round(2).reset_index()
    print("| " + " | ".join(t.columns) + " |")
    print("|" + "---|" * len(t.columns))
    for row in t.itertuples(index=False):
        print("| " + " | ".join(str(v) for v in row) + " |")
    if args.csv:
        df.to_csv(args.csv, index=False)


if __name__ == "__main__":
    main()
