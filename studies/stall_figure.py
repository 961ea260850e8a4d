"""Trajectories at a stall (docs/dual-control.md): paper:12, seed 0, 10,000 particles, wind
known, with mpc, dcee, dcee-cl and infotaxis side by side on the same truth.

    .venv/bin/python studies/stall_figure.py [--out docs/figures/dual-control-stall.png]
"""

from __future__ import annotations

import argparse

import matplotlib.pyplot as plt
import numpy as np

from dcee.analysis.figures import _draw_map
from dcee.runs import run_episode
from dcee.scenarios import load_scenario
from dcee.simulation import make_truth

STRATEGIES = ("mpc", "dcee", "dcee-cl", "infotaxis")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/figures/dual-control-stall.png")
    ap.add_argument("--scenario", default="paper:12")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--particles", type=int, default=10_000)
    args = ap.parse_args()
    scenario = load_scenario(args.scenario).with_overrides(**{"search.particles": args.particles})
    fig, axes = plt.subplots(2, 2, figsize=(12, 11))
    for ax, strategy in zip(axes.ravel(), STRATEGIES, strict=True):
        truth = make_truth(scenario, args.seed)
        result = run_episode(scenario, strategy, args.seed, truth=truth)
        idx = np.random.default_rng(0).choice(
            len(result.final_weights), size=3000, p=result.final_weights
        )
        end = result.records[-1]["time"]
        _draw_map(ax, result, scenario, truth, end, result.final_theta[idx, :3])
        s = result.summary
        ax.set_title(
            f"{strategy}: final RMSE {s['final_rmse']:.2f} m, {s['detections']} detections"
        )
        print(strategy, s["final_rmse"], s["detections"])
    axes[0, 0].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{args.scenario}, seed {args.seed}, {args.particles:,} particles, 900 s")
    fig.tight_layout()
    fig.savefig(args.out, dpi=90, bbox_inches="tight")


if __name__ == "__main__":
    main()
