"""Whole searches of the public study's five planners on one pinned core, two code versions in
alternation (issue 46: the 600-search study's cost per search).

For each planner of ``dcee bench``'s default set (mpc, dcee, infotaxis, entrotaxis, dcee-ms)
runs the campaign's search of ``paper:1``, seed 0 (20,000 particles, 900 s: what a ``dcee
bench`` worker runs, folder and records written) with one numba, OpenMP and BLAS thread pinned to
one core, with the code of ``--before`` (a git worktree) and with this checkout's, ``--rounds``
times in alternation, each side in a process of its own that first runs a short search of each
planner (loading the compiled kernels; not counted). Writes JSON with each search's wall time
(as the campaign measures it: everything a worker spends on it), its decision and filter-update
parts, the final RMSE (the two sides should fly the same search), the machine and the load
beside the run (docs/results/perf/search-speed.json; the table on docs/performance.md is
generated from it).

    .venv/bin/python studies/search_speed.py --before 31f49fd \\
        [--json docs/results/perf/search-speed.json] [--rounds 2]
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from demo_decision import ONE_CORE, ROOT

from dcee.errors import DceeInputError
from dcee.perf.machine import LoadMonitor, alternation_args, code_at, package_env, store_timing

PLANNERS = ("mpc", "dcee", "infotaxis", "entrotaxis", "dcee-ms")
# run in a fresh process with one side's package first on sys.path: the campaign's own search
# (dcee.campaign.runner.run_search) of paper configuration 1, seed 0, for each planner
_DRIVER = """
import json, sys, tempfile
from pathlib import Path
from dcee.campaign.runner import Campaign, SearchTask, _init_worker, run_search
out = Path(tempfile.mkdtemp())
planners = tuple(sys.argv[1].split(","))
c = Campaign(out, "paper", planners, 1)
c.prepare()
_init_worker(None, True)
tasks = {t.strategy: t for t in c.tasks() if t.config == "paper:1"}
for p in planners:  # load the compiled kernels: a short search of each planner
    t = tasks[p]
    short = dict(t.scenario, search=dict(t.scenario["search"], budget=40.0))
    run_search(SearchTask(str(out / "warm"), t.config, p, 1, short))
result = {}
for p in planners:
    t = tasks[p]
    run_search(t)
    s = json.loads((t.folder / "summary.json").read_text())
    result[p] = {"wall_s": s["wall_seconds"], "decision_s": s["decision_seconds_total"],
                 "update_s": s["update_seconds_total"], "final_rmse": s["final_rmse"],
                 "steps": s["steps"]}
print("RESULT " + json.dumps(result))
"""


def _searches(src: Path) -> dict:
    """Each planner's search with the package under ``src``, one pinned core, one process."""
    env = package_env(src, **ONE_CORE)
    command = ["taskset", "-c", "0", sys.executable, "-c", _DRIVER, ",".join(PLANNERS)]
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=ROOT)
    if done.returncode != 0:
        raise RuntimeError(f"the searches with {src} failed:\n{done.stderr[-3000:]}")
    line = [x for x in done.stdout.splitlines() if x.startswith("RESULT ")][-1]
    return json.loads(line[len("RESULT ") :])


def same_search(before: list[dict], after: list[dict]) -> bool:
    """Both sides ended every round after the same steps at the same final RMSE to 1e-9 m (the
    RMSE's own arithmetic may differ in the last digits between versions)."""
    return all(
        x["steps"] == y["steps"] and abs(x["final_rmse"] - y["final_rmse"]) <= 1e-9
        for x, y in zip(before, after, strict=True)
    )


def _fail(message: str) -> int:
    print(f"search_speed: error: {message}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    try:
        args = alternation_args(argv, __doc__.splitlines()[0], 2)
    except DceeInputError as e:
        print(f"search_speed: error: {e}", file=sys.stderr)
        return 2
    if shutil.which("taskset") is None:
        return _fail("taskset (util-linux) is needed to pin one core")
    runs: dict[str, dict[str, list[dict]]] = {
        side: {p: [] for p in PLANNERS} for side in ("before", "after")
    }
    try:
        with code_at(ROOT, args.before) as before_src:
            sides = {"before": before_src, "after": ROOT / "src"}
            with LoadMonitor() as load:
                for r in range(args.rounds):
                    for side, src in sides.items():
                        result = _searches(src)
                        for planner in PLANNERS:
                            runs[side][planner].append(result[planner])
                        print(f"{side} round {r}: "
                              + ", ".join(f"{p} {result[p]['wall_s']:.2f} s" for p in PLANNERS),
                              flush=True)  # fmt: skip
    except DceeInputError as e:
        return _fail(str(e))
    summary = {}
    for planner in PLANNERS:
        b, a = runs["before"][planner], runs["after"][planner]
        summary[planner] = {
            key: {
                "before": float(np.median([x[key] for x in b])),
                "after": float(np.median([x[key] for x in a])),
            }
            for key in ("wall_s", "decision_s", "update_s")
        }
        summary[planner]["same_search"] = same_search(b, a)
        c = summary[planner]["wall_s"]
        print(f"{planner}: {c['before']:.2f} s -> {c['after']:.2f} s "
              f"({c['before'] / c['after']:.2f}x); same search: "
              f"{summary[planner]['same_search']}")  # fmt: skip
    store_timing(
        args.json,
        load.record(),
        before=args.before,
        searches="dcee bench --suite paper: configuration 1, seed 0, each planner",
        threads=ONE_CORE,
        runs=runs,
        summary=summary,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
