"""Figure: how the dcee search node sits in a robot's ROS 2 stack (docs/guide/integration.md):
its inputs, outputs, services and lifecycle, with the message types. The topic names and types
are read from the node's own parameter defaults, so the figure cannot drift from the code.

    .venv/bin/python studies/ros_integration_figure.py [--out docs/figures/ros-integration.png]
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

ROOT = Path(__file__).resolve().parent.parent


def node_parameters() -> dict[str, object]:
    """PARAMETERS of dcee/ros/node.py, read without importing rclpy."""
    tree = ast.parse((ROOT / "src" / "dcee" / "ros" / "node.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.AnnAssign) and getattr(node.target, "id", "") == "PARAMETERS":
            return ast.literal_eval(node.value)
    raise SystemExit("PARAMETERS not found in src/dcee/ros/node.py")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "ros-integration.png")
    args = ap.parse_args()
    p = node_parameters()
    inputs = [
        (f"/{p['concentration_topic']}", "std_msgs/Float32", "gas sensor (× calibration = g/m³)"),
        (f"/{p['pose_topic']}", "nav_msgs/Odometry", "localisation (or AMCL pose)"),
        (f"/{p['wind_topic']}", "geometry_msgs/Vector3Stamped", "anemometer, map frame"),
        (f"/{p['map_topic']}", "nav_msgs/OccupancyGrid", "map server (obstacles)"),
    ]
    outputs = [
        (f"/{p['goal_topic']}", "geometry_msgs/PoseStamped", "Nav2 bt_navigator"),
        ("/dcee/estimate_covariance", "PoseWithCovarianceStamped", "source estimate"),
        ("/dcee/particles", "visualization_msgs/MarkerArray", "RViz"),
        ("/dcee/feedback", "std_msgs/String (JSON)", "mission: progress"),
        ("/dcee/result", "std_msgs/String (JSON, latched)", "mission: result"),
        ("/diagnostics", "diagnostic_msgs/DiagnosticArray", "input health"),
    ]
    services = [
        ("~/change_state", "lifecycle_msgs/ChangeState", "lifecycle manager"),
        ("/dcee/start", "std_srvs/Trigger", "mission: begin a search"),
        ("/dcee/cancel", "std_srvs/Trigger", "mission: end it"),
    ]
    fig, ax = plt.subplots(figsize=(13, 6.4))
    ax.set_xlim(0, 13)
    ax.set_ylim(0, 6.4)
    ax.axis("off")
    node = FancyBboxPatch(
        (4.9, 1.5), 3.2, 3.6, boxstyle="round,pad=0.08", fc="#e8f0fb", ec="#2a5d9f", lw=1.6
    )
    ax.add_patch(node)
    ax.text(6.5, 4.75, "dcee_search", ha="center", fontsize=13, weight="bold")
    ax.text(
        6.5,
        3.3,
        "managed (lifecycle) node\n\nvalidate inputs → hold & average\n→ tell (particle filter)\n"
        "→ ask (planner, around obstacles)\n→ publish goal, estimate\n\nstops when localised",
        ha="center",
        va="center",
        fontsize=9,
    )

    def column(items, x_text, ha, y0, arrow_from, arrow_to, color):
        step = 0.78 if len(items) < 5 else 0.66
        for i, (topic, kind, who) in enumerate(items):
            y = y0 - i * step
            ax.text(x_text, y + 0.12, topic, ha=ha, fontsize=10, weight="bold", family="monospace")
            ax.text(x_text, y - 0.16, f"{kind} · {who}", ha=ha, fontsize=8, color="#444")
            ax.add_patch(
                FancyArrowPatch(
                    (arrow_from, y), (arrow_to, y), arrowstyle="-|>", mutation_scale=12, color=color
                )
            )

    column(inputs, 0.1, "left", 5.2, 3.4, 4.85, "#2a7f3f")
    column(outputs, 12.9, "right", 4.95, 8.15, 9.6, "#9f4a2a")
    for i, (name, kind, who) in enumerate(services):
        x, end = 3.9 + i * 2.6, 5.3 + i * 1.2
        ax.text(x, 0.62, name, ha="center", fontsize=8.5, weight="bold", family="monospace")
        ax.text(x, 0.35, kind, ha="center", fontsize=7, color="#444")
        ax.text(x, 0.12, who, ha="center", fontsize=7, color="#444")
        ax.add_patch(
            FancyArrowPatch(
                (x, 0.8), (end, 1.45), arrowstyle="-|>", mutation_scale=10, color="#555"
            )
        )
    ax.text(
        6.5,
        6.15,
        "frames: REP-103 ENU map frame; wind φ = the direction it comes from, CCW from +x; "
        "concentrations g/m³",
        ha="center",
        fontsize=9,
        style="italic",
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110, bbox_inches="tight")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
