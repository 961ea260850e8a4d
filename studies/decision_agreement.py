"""Do the speed-ups change what the planners choose? (dcee.perf.agreement; issues 17 and 46)

Flies searches with the fast path and, before every decision, decides again on the same belief
with the reference path (no merged particles, no terms kept across decisions, double
precision), same random numbers; prints one line per (configuration, strategy, seed) and the
totals. ``--precision single`` flies the planners' single-precision weights against it.
``--json`` writes every row, the totals and the machine (docs/results/perf/, the table on
docs/performance.md is generated from it).

Usage: .venv/bin/python studies/decision_agreement.py [--particles N] [--steps S] [--seeds K]
    [--precision double|single] [--strategies a,b] [--json PATH]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dcee.io import write_json
from dcee.perf.agreement import search_agreement
from dcee.perf.machine import machine_record
from dcee.planning.predicted import PRECISIONS

STRATEGIES = ("dcee", "infotaxis", "entrotaxis", "dcee-cl", "dcee-ms")
CONFIGS = ("paper:1", "paper:5", "paper:12")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=20_000)
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--precision", default="double")
    parser.add_argument("--strategies", default=",".join(STRATEGIES))
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    if args.precision not in PRECISIONS:
        print(
            f"decision_agreement: error: --precision must be one of {', '.join(PRECISIONS)}, "
            f"got {args.precision!r}",
            file=sys.stderr,
        )
        return 2
    if args.json is not None and not args.json.parent.is_dir():
        print(f"decision_agreement: error: --json: no folder {args.json.parent}", file=sys.stderr)
        return 2
    strategies = [s for s in args.strategies.split(",") if s]
    rows = []
    for config in CONFIGS:
        for strategy in strategies:
            for seed in range(args.seeds):
                a = search_agreement(
                    config, strategy, seed, args.particles, args.steps, args.precision
                )
                rows.append(a.as_dict())
                print(
                    f"{config:9s} {strategy:10s} seed {seed}: {a.same_choice}/{a.decisions} "
                    f"same choice, largest cost difference {a.max_cost_diff_over_spread:.1e} "
                    "of the costs' spread",
                    flush=True,
                )
    total = sum(r["decisions"] for r in rows)
    same = sum(r["same_choice"] for r in rows)
    worst = max((r["max_cost_diff_over_spread"] for r in rows), default=0.0)
    print(f"total: {same}/{total} decisions identical; largest cost difference {worst:.1e}")
    if args.json is not None:
        settings = {k: getattr(args, k) for k in ("particles", "steps", "seeds", "precision")}
        write_json(
            args.json,
            {
                "machine": machine_record(),
                "settings": {**settings, "configs": list(CONFIGS), "strategies": strategies},
                "searches": rows,
                "decisions": total,
                "same_choice": same,
                "max_cost_diff_over_spread": worst,
            },
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
