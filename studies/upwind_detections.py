"""Where a campaign's estimates and detections lie along the wind (docs/plumes.md): the median
signed along-wind error of the final mean (> 0 downwind of the source), the median cross-wind
error and posterior spread, and the share of detections taken upwind of the source (more than
0, 1, 2 m against the mean wind).

    .venv/bin/python studies/upwind_detections.py results/turbulent-lbm-held-out-100=dcee-cl \\
        [results/turbulent-lbm-held-out-100-decay=dcee-cl ...]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from urllib.parse import quote

import numpy as np
import pandas as pd

from dcee.scenarios import load_scenario


def along_wind(folder: Path, strategy: str) -> dict[str, float]:
    along, cross, spread = [], [], []
    upwind = np.zeros(3)
    detections = 0
    # the campaign's folder names quote the planner spec (dcee-cl:horizon=2 → dcee-cl%3Ahorizon%3D2)
    for summary in sorted(
        folder.glob(f"runs/*/strategy={quote(strategy, safe='')}/*/summary.json")
    ):
        s = json.loads(summary.read_text())
        scenario = load_scenario(s["config"])
        t = scenario.truth
        phi = math.radians(t.phi)
        down = -np.array([math.cos(phi), math.sin(phi)])
        left = np.array([-down[1], down[0]])
        error = np.asarray(s["final_mean"][:2]) - np.array([t.x, t.y])
        along.append(float(error @ down))
        cross.append(abs(float(error @ left)))
        spread.append(s["final_spread"])
        steps = pd.read_parquet(summary.with_name("steps.parquet"))
        rel = steps[["x", "y"]].to_numpy() - np.array([t.x, t.y])
        detected = steps["reading"].to_numpy() >= scenario.sensor.threshold
        a = rel[detected] @ down
        detections += int(detected.sum())
        upwind += [np.sum(a < 0), np.sum(a < -1), np.sum(a < -2)]
    return {
        "searches": len(along),
        "median_along_m": float(np.median(along)),
        "median_cross_m": float(np.median(cross)),
        "median_spread_m": float(np.median(spread)),
        "detections": detections,
        "upwind_share": float(upwind[0] / detections),
        "upwind_1m_share": float(upwind[1] / detections),
        "upwind_2m_share": float(upwind[2] / detections),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", help="DIR=STRATEGY")
    args = ap.parse_args()
    for arg in args.campaigns:
        folder, _, strategy = arg.partition("=")
        row = along_wind(Path(folder), strategy)
        print(f"{folder} ({strategy}): " + ", ".join(f"{k} {v:.3g}" for k, v in row.items()))


if __name__ == "__main__":
    main()
