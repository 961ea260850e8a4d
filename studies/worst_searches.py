"""Figures of the worst searches of held-out campaigns (docs/held-out.md): for each
``DIR=STRATEGY`` the ``--count`` searches that failed worst (not acquired first, then the
longest stall, then the final RMSE), drawn from their stored results (trajectory, detections,
final particles, the truth's plume), one row per strategy.

    .venv/bin/python studies/worst_searches.py results/held-out-wind-known=dcee-cl \\
        results/held-out-wind-known=infotaxis --out docs/figures/held-out-worst-wind-known.png
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from dcee.analysis.figures import _draw_map
from dcee.analysis.report import load_campaign
from dcee.runs import EpisodeResult
from dcee.scenarios import validate_scenario
from dcee.simulation import make_truth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaigns", nargs="+", help="DIR=STRATEGY")
    ap.add_argument("--count", type=int, default=3)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    rows = len(args.campaigns)
    fig, axes = plt.subplots(
        rows, args.count, figsize=(4.2 * args.count, 4.4 * rows), squeeze=False
    )
    for r, spec in enumerate(args.campaigns):
        folder, _, strategy = spec.partition("=")
        _, runs = load_campaign(Path(folder))
        runs = runs[runs["strategy"] == strategy].copy()
        runs["bad"] = ~runs["source_acquired"].astype(bool)
        worst = runs.sort_values(["bad", "longest_stall", "final_rmse"], ascending=False)
        for c, (_, run) in enumerate(worst.head(args.count).iterrows()):
            result = EpisodeResult.load(run["run_dir"])
            config = json.loads((Path(run["run_dir"]) / "config.json").read_text())
            scenario = validate_scenario(config["scenario"])
            truth = make_truth(scenario, int(run["seed"]))
            idx = np.random.default_rng(0).choice(
                len(result.final_weights), size=2000, p=result.final_weights
            )
            ax = axes[r, c]
            _draw_map(
                ax, result, scenario, truth, result.records[-1]["time"], result.final_theta[idx, :3]
            )
            s = result.summary
            ax.set_title("", loc="left")  # the map's own time and RMSE: said below instead
            ax.set_title(  # above the north and wind arrows
                f"{strategy} · {s['scenario']}, t = {result.records[-1]['time']:.0f} s\n"
                f"RMSE {s['final_rmse']:.1f} m, stall {s['longest_stall']:.0f} s, "
                f"{s['detections']} detections",
                fontsize=9,
                pad=26,
            )
            if c == 0:  # which campaign the row is
                ax.set_ylabel(f"{Path(folder).name}\ny (m)", fontsize=9)
            print(strategy, s["scenario"], round(s["final_rmse"], 2), s["longest_stall"])
    fig.tight_layout()
    fig.savefig(args.out, dpi=80, bbox_inches="tight")


if __name__ == "__main__":
    main()
