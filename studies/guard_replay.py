"""A campaign flown before the stall guard existed, completed as if it had had it.

The guard (Searcher, ``search.stall_guard``) changes a search only from the first decision at
which it fires, and whether it fires depends only on what the search recorded: the told
positions and times and the posterior spread after each reading (``steps.parquet``). So this
script replays the guard's rule over every stored search; a search in which it never fires is
exactly what the guarded code flies (same seed, same draws), and one in which it fires is flown
again with the guard. The result is a copy of the campaign (hard links) with those searches
replaced:

    .venv/bin/python studies/guard_replay.py results/held-out-wind-known \\
        results/held-out-wind-known-guard [--guard 30]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
from pathlib import Path

import pandas as pd

from dcee.analysis.results import find_runs
from dcee.models.agent import stall_start
from dcee.runs import run_episode
from dcee.scenarios import validate_scenario
from dcee.searcher import STALL_HISTORY


def guard_fires(steps: pd.DataFrame, step: float, guard: float, spread_limit: float) -> bool:
    """Whether the stall guard would fire at any decision of a recorded single-robot search
    (the rule of :meth:`dcee.searcher.Searcher.stall_anchor`, replayed on the record)."""
    t = steps["time"].to_numpy()
    xy = steps[["told_x", "told_y"]].to_numpy()
    spread = steps["spread"].to_numpy()
    for k in range(1, len(t) - 1):  # a decision follows every reading but the last
        lo = max(0, k + 1 - STALL_HISTORY)
        first = lo + stall_start(xy[lo : k + 1], step)
        if t[k] - t[first] >= guard and spread[k] > spread_limit:
            return True
    return False


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--guard", type=float, default=30.0)
    args = ap.parse_args()
    if not args.out.exists():
        subprocess.run(["cp", "-al", str(args.campaign), str(args.out)], check=True)
    fired = []
    for run in find_runs(args.out):
        config = json.loads((run / "config.json").read_text())
        scenario = config["scenario"]
        if scenario["search"].get("stall_guard", 0.0) == args.guard:
            continue  # already flown with the guard
        steps = pd.read_parquet(
            run / "steps.parquet", columns=["time", "told_x", "told_y", "spread"]
        )
        search = scenario["search"]
        if not guard_fires(steps, scenario["agent"]["step"], args.guard, search["acquired_rmse"]):
            continue
        scenario["search"] = {**search, "stall_guard": args.guard}
        result = run_episode(validate_scenario(scenario), config["strategy"], int(config["seed"]))
        shutil.rmtree(run)  # hard links: the original campaign keeps its files
        result.save(run)
        s = result.summary
        fired.append(
            f"{s['scenario']} {s['strategy']}: final RMSE {s['final_rmse']:.2f} m, "
            f"longest stall {s['longest_stall']:.0f} s"
        )
        print(fired[-1], flush=True)
    print(f"{len(fired)} searches flown again with the guard")


if __name__ == "__main__":
    main()
