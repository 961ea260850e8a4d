"""Do two code versions fly the same searches? Flies 200 decisions of paper:1, 5 and 12 with
dcee, dcee-cl, infotaxis and entrotaxis (10,000 particles, seed 0) and writes, per search, a hash
of every waypoint and the final location estimate; run it with each version's source on
PYTHONPATH and compare the two files (issue 46: a kernel change must not change a decision).

    PYTHONPATH=src .venv/bin/python studies/same_paths.py after.json
    PYTHONPATH=/path/to/old/worktree/src .venv/bin/python studies/same_paths.py before.json
    cmp before.json after.json

A second argument names other strategies, comma-separated (``dcee-ms,dcee-mcts``: the
kernels of several stages; fewer decisions there, ``--decisions``-free: 100 each).
"""

import hashlib
import json
import sys

import numpy as np

from dcee.planning import get as get_planner
from dcee.runs import SearchSimulation, planner_defaults
from dcee.scenarios import load_scenario

ONE_STEP = ("dcee", "dcee-cl", "infotaxis", "entrotaxis")


def main(path: str, strategies: tuple[str, ...] = ONE_STEP) -> int:
    if not path.endswith(".json"):
        print("same_paths.py: the output must be a .json file, e.g. after.json", file=sys.stderr)
        return 2
    decisions = 200 if strategies == ONE_STEP else 100
    out = {}
    for config in ("paper:1", "paper:5", "paper:12"):
        for strategy in strategies:
            sc = load_scenario(config).with_overrides(**{"search.particles": 10000})
            planner = get_planner(strategy, **planner_defaults(strategy, sc, None))
            sim = SearchSimulation(sc, 0, planner)
            positions = []
            for _ in range(decisions):
                sim.sense()
                if sim.finished:
                    break
                wp = sim.searcher.ask()
                positions.append(wp.copy())
                sim.move(wp)
            est = sim.searcher.filter.theta[:, :3].T @ sim.searcher.filter.weights
            h = hashlib.sha1(np.asarray(positions).tobytes()).hexdigest()[:12]
            out[f"{config} {strategy}"] = (h, len(positions), [round(float(x), 9) for x in est])
            print(config, strategy, h, len(positions), out[f"{config} {strategy}"][2], flush=True)
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], *([tuple(sys.argv[2].split(","))] if len(sys.argv) > 2 else [])))
