"""Issue 78: what the altitude as a decision costs. ``dcee-cl`` at today's defaults decides on
one posterior with the altitude free (the UAV may climb or descend ``agent.climb``) and at a fixed
altitude (``agent.climb = 0``), the two sides alternating decision by decision on one pinned
core, every decision computing its own terms. The posterior: a search on the 3-D plume
(``random:9``, ``truth.model = "lbm3d"``, all eight parameters unknown, 10,000 particles) flown
for ``--warm`` seconds with the altitude free.

    python studies/altitude_timing.py --json docs/results/lbm3d/altitude-timing.json
"""

from __future__ import annotations

import argparse
import copy
import os
import statistics
import time
from pathlib import Path

from dcee.perf.machine import LoadMonitor, store_timing
from dcee.planning import get as get_planner
from dcee.runs import SearchSimulation
from dcee.runs.assemble import planner_defaults
from dcee.scenarios import load_scenario

SCENARIO = "random:9"
OVERRIDES = {
    "truth.model": "lbm3d",
    "estimator.likelihood": "fluctuation",
    "unknown": "full",
    "search.particles": 10_000,
}


def _cpu_model() -> str:
    """The CPU's model name (Linux), or the platform's processor string."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    import platform

    return platform.processor()


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--decisions", type=int, default=20, help="decisions per side")
    ap.add_argument("--warm", type=float, default=200.0, help="s of search before timing")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    if args.json is not None and not args.json.parent.is_dir():
        ap.error(f"--json: no folder {args.json.parent}")
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})  # one pinned core
    scenario = load_scenario(SCENARIO).with_overrides(**OVERRIDES)
    planner = get_planner("dcee-cl", **planner_defaults("dcee-cl", scenario, None))
    sim = SearchSimulation(scenario, 0, planner)
    while sim.time < args.warm:  # a real posterior: the search with the altitude free
        sim.sense()
        sim.move(sim.searcher.ask())
    free = sim.searcher
    fixed = copy.copy(free)
    fixed.agent = scenario.with_overrides(**{"agent.climb": 0.0}).make_agent()
    assert free.agent.climb > 0 and fixed.agent.climb == 0
    times: dict[str, list[float]] = {"altitude free": [], "fixed altitude": []}
    with LoadMonitor() as load:
        for _ in range(args.decisions):
            for name, searcher in (("altitude free", free), ("fixed altitude", fixed)):
                searcher.planning_cache.forget()
                started = time.perf_counter()
                searcher.ask()
                times[name].append(1000.0 * (time.perf_counter() - started))
    medians = {k: statistics.median(v) for k, v in times.items()}
    ratio = medians["altitude free"] / medians["fixed altitude"]
    for name, median in medians.items():
        print(f"{name}: median {median:.1f} ms over {args.decisions} decisions")
    print(f"altitude free / fixed: {ratio:.2f}x (the bar: at most 2x)")
    store_timing(
        args.json,
        load.record(),
        cpu_model=_cpu_model(),
        scenario=SCENARIO,
        overrides=OVERRIDES,
        warm_seconds=args.warm,
        position=[float(v) for v in free.position],
        moves={
            "altitude free": len(free.agent.candidates(free.position)[0]),
            "fixed altitude": len(fixed.agent.candidates(fixed.position)[0]),
        },
        decisions_ms=times,
        median_ms=medians,
        ratio=ratio,
    )


if __name__ == "__main__":
    main()
