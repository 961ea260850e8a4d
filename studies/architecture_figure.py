"""Figure: the package layers and the imports between packages, read from the source with the
same checker as tests/test_architecture.py (docs/design.md).

    .venv/bin/python studies/architecture_figure.py [--out docs/figures/architecture.png]
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from tests.test_architecture import LAYERS, import_graph, owner

ROLE = {
    "dcee.models": "plume, sensor, agent, motion",
    "dcee.recordings": "plume files: CF, layout, statistics",
    "dcee.estimation": "Estimator: particle filter, model bank",
    "dcee.planning": "planners, registered by name",
    "dcee.scenarios": "schema, builders, files",
    "dcee.searcher": "ask / tell",
    "dcee.simulation": "truths, registered by kind",
    "dcee.runs": "assemble, step, record, score, save",
    "dcee.campaign": "suites, executors, resumption",
    "dcee.robot": "ROS-free cycle, bags, replay",
    "dcee.analysis": "statistics, figures, report",
    "dcee.console": "summaries, errors, exit codes",
    "dcee.perf": "timings vs references",
    "dcee.cli": "dcee command",
    "dcee.ros": "ROS 2 nodes",
    "dcee.gym": "Gymnasium, PettingZoo",
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", type=Path, default=Path("docs/figures/architecture.png"))
    args = ap.parse_args()
    packages = [p for p in LAYERS if p in ROLE]
    edges: set[tuple[str, str]] = set()
    for src, targets in import_graph().items():
        for dst in targets:
            a, b = owner(src), owner(dst)
            if a in ROLE and b in ROLE and a != b:
                edges.add((a, b))
    by_layer: dict[int, list[str]] = defaultdict(list)
    for p in packages:
        by_layer[LAYERS[p]].append(p)
    layers = sorted(by_layer)
    width, height = 3.3, 0.62
    pos = {}
    fig, ax = plt.subplots(figsize=(10.5, 9.5))
    for row, layer in enumerate(layers):
        names = by_layer[layer]
        y = row * 0.95
        for k, p in enumerate(names):
            x = (k - (len(names) - 1) / 2) * (width + 0.3)
            pos[p] = (x, y)
            interface = layer == max(layers)
            ax.add_patch(
                FancyBboxPatch(
                    (x - width / 2, y - height / 2),
                    width,
                    height,
                    boxstyle="round,pad=0.02",
                    fc="#fde7c7" if interface else "#dbe8f6",
                    ec="#555",
                    lw=0.8,
                    zorder=2,
                )
            )
            ax.text(
                x,
                y + 0.1,
                p.removeprefix("dcee."),
                ha="center",
                va="center",
                fontsize=10,
                weight="bold",
                zorder=3,
            )
            ax.text(x, y - 0.13, ROLE[p], ha="center", va="center", fontsize=7.5, zorder=3)
        ax.text(-6.2, y, f"layer {layer}", ha="right", va="center", fontsize=8, color="#666")
    for a, b in sorted(edges):  # a imports b: b is lower, the arrow points down to it
        (xa, ya), (xb, yb) = pos[a], pos[b]
        ax.add_patch(
            FancyArrowPatch(
                (xa, ya - height / 2),
                (xb, yb + height / 2),
                arrowstyle="-|>",
                mutation_scale=7,
                lw=0.5,
                color="#8899aa",
                alpha=0.6,
                connectionstyle="arc3,rad=0.08",
                zorder=1,
            )
        )
    ax.set_xlim(-7.2, 6.2)
    ax.set_ylim(-0.6, (len(layers) - 1) * 0.95 + 0.6)
    ax.axis("off")
    ax.set_title(
        "dcee: packages by layer; an arrow is an import (always downwards; "
        "tests/test_architecture.py)",
        fontsize=10,
    )
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(args.out, len(edges), "package imports")


if __name__ == "__main__":
    main()
