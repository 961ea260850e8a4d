"""Figure: the two turbulent truths side by side on one configuration (docs/scenarios.md).

Top row: the instantaneous field at t = 200 s; bottom row: its mean over 300 s, at the source
height, for the filament truth and the independent puff truth (log colour scale, g/m³).

    .venv/bin/python studies/turbulent_truths_figure.py [--scenario paper:1] [--seed 0] \\
        [--out docs/figures/turbulent-truths.png]
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm

from dcee.scenarios import load_scenario
from dcee.simulation import make_truth


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenario", default="paper:1")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="docs/figures/turbulent-truths.png")
    args = ap.parse_args()
    base = load_scenario(args.scenario)
    theta = base.truth_theta()
    xs = np.linspace(0.0, 50.0, 126)
    gx, gy = np.meshgrid(xs, xs)
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, theta[2])])
    fig, axes = plt.subplots(2, 2, figsize=(10, 9), constrained_layout=True)
    norm = LogNorm(vmin=base.sensor.threshold, vmax=1.0)
    for col, model in enumerate(("filament", "puffs")):
        truth = make_truth(base.with_overrides(**{"truth.model": model}), args.seed)
        now = truth.field(pts, 200.0).reshape(gx.shape)
        mean = np.mean([truth.field(pts, t) for t in np.arange(0.0, 300.0, 2.0)], axis=0)
        for row, (field, what) in enumerate(
            ((now, "at t = 200 s"), (mean.reshape(gx.shape), "mean over 300 s"))
        ):
            ax = axes[row, col]
            im = ax.pcolormesh(gx, gy, np.maximum(field, 1e-9), norm=norm, shading="auto")
            ax.plot(theta[0], theta[1], "r*", ms=12)
            ax.set_title(f"{model} truth, {what}")
            ax.set_aspect("equal")
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
    fig.colorbar(im, ax=axes, shrink=0.6, label="concentration at the source height (g/m³)")
    fig.savefig(args.out, dpi=90)
    print(args.out)


if __name__ == "__main__":
    main()
