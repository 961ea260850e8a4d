"""Issue 28: our tree search against Stone Soup's MCTSRolloutSensorManager on Stone Soup's own
STE example (dcee.perf.stonesoup_mcts), seeds 0-9, side by side in one process. Needs the
`bench` extra (Stone Soup). Resumable: one JSON per seed in OUT; rerun to finish, then it prints
the table (median final x-y RMSE and median ms per decision, with the ratio).

    .venv/bin/python studies/stonesoup_mcts_study.py results/stonesoup-mcts [STRATEGY]
"""

import json
import sys
from pathlib import Path

import numpy as np

from dcee.perf.stonesoup_mcts import compare_mcts

out = Path(sys.argv[1])
strategy = sys.argv[2] if len(sys.argv) > 2 else "dcee-mcts"
out.mkdir(parents=True, exist_ok=True)
for seed in range(10):
    path = out / f"{strategy.replace(':', '_')}-seed{seed}.json"
    if not path.exists():
        (row,) = compare_mcts(range(seed, seed + 1), strategy)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(row))
        tmp.replace(path)  # a finished seed only
rows = [
    json.loads(p.read_text()) for p in sorted(out.glob(f"{strategy.replace(':', '_')}-seed*.json"))
]
print(
    "| seed | moves | Stone Soup MCTS final RMSE (m) | ours | Stone Soup ms/decision | ours "
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
ss_ms = np.concatenate([r["stonesoup"]["decision_ms"] for r in rows])
our_ms = np.concatenate([r["dcee"]["decision_ms"] for r in rows])
print(
    f"\n{len(rows)} seeds: median final x-y RMSE Stone Soup {np.median(ss_final):.2f} m, "
    f"{strategy} {np.median(our_final):.2f} m (ours lower in {lower}); "
    f"median ms per decision {np.median(ss_ms):.0f} vs {np.median(our_ms):.1f}: "
    f"{np.median(ss_ms) / np.median(our_ms):.0f}x faster"
)
