"""What each change of issue 17 bought: the same workloads timed for several commits, each in
fresh processes, the commits alternated round by round so that all see the same machine load.

Usage: .venv/bin/python studies/perf_history.py COMMIT [COMMIT ...] [--rounds N]
Each commit is checked out into a temporary git worktree (its numba kernels are compiled there
once, in a warm-up run). Workloads, per commit and round:

* ``stonesoup-infotaxis``: median of 20 infotaxis decisions on Stone Soup's STE workload
  (10,000 particles, 9 moves × 4 hypotheses; our side only);
* ``search-dcee``: wall time of one complete paper:1 dcee search (20,000 particles, 900 s), one
  numba thread, as in a ``dcee bench`` worker;
* ``mcmc-ratio``: resample + one MCMC sweep over 500 readings divided by one filter update
  (20,000 particles), and the two times.

Prints one line per commit with the medians over rounds.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PY = str(ROOT / ".venv" / "bin" / "python")

PROBE = r"""
import json, time, numpy as np
out = {}
try:
    from dcee.perf.stonesoup_compare import dcee_decisions
    t = list(dcee_decisions(20))
except ImportError:
    from dcee.perf.stonesoup_compare import time_dcee
    t = time_dcee(20)
out["stonesoup-infotaxis"] = float(np.median(t))
import numba
numba.set_num_threads(1)
from dcee.scenarios import load_scenario
from dcee.runs import run_episode
t0 = time.perf_counter()
run_episode(load_scenario("paper:1"), "dcee", 0)
out["search-dcee"] = 1e3 * (time.perf_counter() - t0)
numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
from dcee.perf.workloads import _filter_update, _resample_move
u = _filter_update(9)
m = _resample_move(3)
out["update"] = u.median
out["mcmc"] = m.median
out["mcmc-ratio"] = m.median / u.median
print(json.dumps(out))
"""


def run(tree: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree / "src"))
    proc = subprocess.run(
        [PY, "-c", PROBE], capture_output=True, text=True, env=env, cwd=tempfile.gettempdir()
    )
    if proc.returncode:
        raise SystemExit(f"{tree}: {proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    args = sys.argv[1:]
    rounds = 2
    if "--rounds" in args:
        i = args.index("--rounds")
        rounds = int(args[i + 1])
        del args[i : i + 2]
    trees = {}
    for commit in args:
        tree = Path(tempfile.gettempdir()) / f"dcee-wt-{commit}"
        if not tree.exists():
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "add", "-q", "--detach", str(tree), commit],
                check=True,
            )
        trees[commit] = tree
        run(tree)  # warm-up: compiles this commit's kernels into its own cache
    results: dict[str, list[dict]] = {c: [] for c in trees}
    for _ in range(rounds):
        for commit, tree in trees.items():
            results[commit].append(run(tree))
    for commit, rows in results.items():
        med = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
        print(
            f"{commit}: stonesoup-infotaxis {med['stonesoup-infotaxis']:.2f} ms · "
            f"search-dcee {med['search-dcee'] / 1e3:.1f} s · update {med['update']:.3f} ms · "
            f"mcmc {med['mcmc']:.1f} ms · ratio {med['mcmc-ratio']:.0f}"
        )


if __name__ == "__main__":
    main()
