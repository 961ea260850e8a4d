"""Do the speed-ups of issue 17 change what the planners choose? (dcee.perf.agreement)

Flies searches with the fast path and, before every decision, decides again on the same belief
with the reference path (no merged particles, no terms kept across decisions), same random
numbers; prints one line per (configuration, strategy, seed) and the totals.

Usage: .venv/bin/python studies/decision_agreement.py [--particles N] [--steps S]
"""

from __future__ import annotations

import argparse

from dcee.perf.agreement import search_agreement

STRATEGIES = ("dcee", "infotaxis", "entrotaxis", "dcee-cl", "dcee-ms")
CONFIGS = ("paper:1", "paper:5", "paper:12")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=20_000)
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--seeds", type=int, default=2)
    args = parser.parse_args()
    total = same = 0
    worst = 0.0
    for config in CONFIGS:
        for strategy in STRATEGIES:
            for seed in range(args.seeds):
                a = search_agreement(config, strategy, seed, args.particles, args.steps)
                total += a.decisions
                same += a.same_choice
                worst = max(worst, a.max_cost_diff_over_spread)
                print(
                    f"{config:9s} {strategy:10s} seed {seed}: {a.same_choice}/{a.decisions} "
                    f"same choice, largest cost difference {a.max_cost_diff_over_spread:.1e} "
                    "of the costs' spread",
                    flush=True,
                )
    print(f"total: {same}/{total} decisions identical; largest cost difference {worst:.1e}")


if __name__ == "__main__":
    main()
