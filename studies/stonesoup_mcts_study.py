"""Issue 28 / 46: our tree search against Stone Soup's MCTSRolloutSensorManager on Stone Soup's
own STE example (dcee.perf.stonesoup_mcts), side by side in one process, one seed after
another. Needs the `bench` extra (Stone Soup). Resumable: one JSON per seed in OUT (with the
load beside it, dcee.perf.machine); rerun to finish, then it prints the table (final x-y RMSE
and median ms per decision, with the ratio) and, with ``--json``, writes the summary that
docs/results/perf/ stores and the speed tables are generated from.

    .venv/bin/python studies/stonesoup_mcts_study.py results/stonesoup-mcts [--strategy S] \\
        [--seeds 10] [--json docs/results/perf/stonesoup-mcts.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from dcee.io import write_json
from dcee.perf.machine import LoadMonitor, machine_record
from dcee.perf.stonesoup_mcts import PUBLISHED_EXAMPLE, compare_mcts


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="folder of the per-seed JSON files")
    ap.add_argument("--strategy", default="dcee-mcts")
    ap.add_argument("--seeds", type=int, default=10, help="seeds 0 … N-1")
    ap.add_argument("--json", type=Path, help="write the summary here")
    args = ap.parse_args(argv)
    if args.seeds < 1:
        print("stonesoup_mcts_study: --seeds must be >= 1", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    stem = args.strategy.replace(":", "_")
    for seed in range(args.seeds):
        path = args.out / f"{stem}-seed{seed}.json"
        if not path.exists():
            with LoadMonitor() as load:
                (row,) = compare_mcts(range(seed, seed + 1), args.strategy)
            # a finished seed only, with the code and machine that ran it
            write_json(path, {**row, "load": load.record(), "machine": machine_record()})
    rows = [json.loads((args.out / f"{stem}-seed{s}.json").read_text()) for s in range(args.seeds)]
    print(
        "| seed | moves | Stone Soup final RMSE (m) | ours | Stone Soup ms/decision | ours "
        "| ratio |"
    )
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        s, d = r["stonesoup"], r["dcee"]
        sm, dm = np.median(s["decision_ms"]), np.median(d["decision_ms"])
        print(
            f"| {r['seed']} | {s['moves']} | {s['rmse'][-1]:.2f} | {d['rmse'][-1]:.2f} "
            f"| {sm:.0f} | {dm:.1f} | {sm / dm:.0f}x |"
        )
    ss_final = [r["stonesoup"]["rmse"][-1] for r in rows]
    our_final = [r["dcee"]["rmse"][-1] for r in rows]
    lower = sum(o < s for o, s in zip(our_final, ss_final, strict=True))
    ss_ms = float(np.median(np.concatenate([r["stonesoup"]["decision_ms"] for r in rows])))
    our_ms = float(np.median(np.concatenate([r["dcee"]["decision_ms"] for r in rows])))
    # the first ten decisions of each search beside the median: Stone Soup's decisions are
    # dearest while its particles are spread (0.7-1 s), cheaper once they gather (0.2-0.3 s)
    ss_first = float(np.median(np.concatenate([r["stonesoup"]["decision_ms"][:10] for r in rows])))
    our_first = float(np.median(np.concatenate([r["dcee"]["decision_ms"][:10] for r in rows])))
    print(
        f"\n{len(rows)} seeds: median final x-y RMSE Stone Soup {np.median(ss_final):.2f} m, "
        f"{args.strategy} {np.median(our_final):.2f} m (ours lower in {lower}); "
        f"median ms per decision {ss_ms:.0f} vs {our_ms:.1f}: {ss_ms / our_ms:.0f}x faster; "
        f"first ten decisions {ss_first:.0f} vs {our_first:.1f}: {ss_first / our_first:.0f}x"
    )
    if args.json:
        loads = [r.get("load", {}) for r in rows]
        other = [x["other_cores"] for x in loads if x.get("other_cores") is not None]
        ran = [r["machine"] for r in rows if "machine" in r]
        summary = {
            # the machine and code of the seeds' runs (all the same when the study ran at once)
            "machine": ran[0] if len(ran) == len(rows) else machine_record(),
            "load": {
                "started": min((x["started"] for x in loads if "started" in x), default=None),
                "other_cores": max(other) if other else None,
                "idle": all(x.get("idle") is True for x in loads),
            },
            "workload": "Stone Soup MCTS STE example: 10,000 particles, 100 iterations, depth 5",
            "settings": PUBLISHED_EXAMPLE,
            "strategy": args.strategy,
            "seeds": len(rows),
            "stonesoup_median_ms": ss_ms,
            "dcee_median_ms": our_ms,
            "speedup": ss_ms / our_ms,
            "stonesoup_first10_median_ms": ss_first,
            "dcee_first10_median_ms": our_first,
            "first10_speedup": ss_first / our_first,
            "stonesoup_median_final_rmse": float(np.median(ss_final)),
            "dcee_median_final_rmse": float(np.median(our_final)),
            "dcee_lower_rmse": int(lower),
            "per_seed": [
                {
                    "seed": r["seed"],
                    "moves": r["stonesoup"]["moves"],
                    "stonesoup_median_ms": float(np.median(r["stonesoup"]["decision_ms"])),
                    "dcee_median_ms": float(np.median(r["dcee"]["decision_ms"])),
                    "stonesoup_final_rmse": r["stonesoup"]["rmse"][-1],
                    "dcee_final_rmse": r["dcee"]["rmse"][-1],
                    "other_cores": r.get("load", {}).get("other_cores"),
                }
                for r in rows
            ],
        }
        write_json(args.json, summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
