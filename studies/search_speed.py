"""Whole searches of the public study's five planners on one pinned core, two code versions in
alternation (issue 46: the 600-search study's cost per search).

For each planner of ``dcee bench``'s default set (mpc, dcee, infotaxis, entrotaxis, dcee-ms)
runs ``dcee run --scenario paper:1 --strategy NAME --seed 0`` (20,000 particles, 900 s) with one
numba, OpenMP and BLAS thread pinned to one core, with the code of ``--before`` (a git worktree)
and with this checkout's, ``--rounds`` times in alternation; each side's kernels are compiled by
a first run that is not counted. Writes JSON with each run's compute time (decisions and filter
updates, the summary's ``compute_seconds_total``), its decision and update parts, the final RMSE
(the two sides should fly the same search), the machine and the load beside the run
(docs/results/perf/search-speed.json; the table on docs/performance.md is generated from it).

    .venv/bin/python studies/search_speed.py --before 31f49fd \\
        [--json docs/results/perf/search-speed.json] [--rounds 2]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from demo_decision import DEMO, ONE_CORE, ROOT, _search

from dcee.io import write_json
from dcee.perf.machine import LoadMonitor, load_warning, machine_record

PLANNERS = ("mpc", "dcee", "infotaxis", "entrotaxis", "dcee-ms")


def _fail(message: str) -> int:
    print(f"search_speed: error: {message}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", required=True, help="the commit to compare with")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    if shutil.which("taskset") is None:
        return _fail("taskset (util-linux) is needed to pin one core")
    if args.json is not None and not args.json.parent.is_dir():
        return _fail(f"--json: no folder {args.json.parent}")
    if args.rounds < 1:
        return _fail(f"--rounds must be ≥ 1, got {args.rounds}")
    work = Path(tempfile.mkdtemp())
    tree = work / "before"
    made = subprocess.run(
        ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), args.before],
        capture_output=True,
        text=True,
    )
    if made.returncode != 0:
        first = (made.stderr.strip().splitlines() or ["git worktree add failed"])[0]
        return _fail(f"--before {args.before}: {first}")
    sides = {"before": tree / "src", "after": ROOT / "src"}
    runs: dict[str, dict[str, list[dict]]] = {side: {p: [] for p in PLANNERS} for side in sides}
    try:
        for side, src in sides.items():  # compile each side's kernels (not counted)
            for planner in PLANNERS:
                _search(src, work / f"warm-{side}-{planner}", planner)
        with LoadMonitor() as load:
            for r in range(args.rounds):
                for planner in PLANNERS:
                    for side, src in sides.items():
                        s = _search(src, work / f"{side}-{planner}-{r}", planner)
                        runs[side][planner].append(
                            {
                                "compute_s": s["compute_seconds_total"],
                                "decision_s": s["decision_seconds_total"],
                                "update_s": s["update_seconds_total"],
                                "final_rmse": s["final_rmse"],
                                "steps": s["steps"],
                            }
                        )
                        print(f"{side} {planner} round {r}: {s['compute_seconds_total']:.2f} s",
                              flush=True)  # fmt: skip
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)],
                       capture_output=True)  # fmt: skip
        shutil.rmtree(work, ignore_errors=True)
    summary = {}
    for planner in PLANNERS:
        b, a = runs["before"][planner], runs["after"][planner]
        summary[planner] = {
            key: {
                "before": float(np.median([x[key] for x in b])),
                "after": float(np.median([x[key] for x in a])),
            }
            for key in ("compute_s", "decision_s", "update_s")
        }
        summary[planner]["same_search"] = all(
            x["final_rmse"] == y["final_rmse"] and x["steps"] == y["steps"]
            for x, y in zip(b, a, strict=True)
        )
        c = summary[planner]["compute_s"]
        print(f"{planner}: {c['before']:.2f} s -> {c['after']:.2f} s "
              f"({c['before'] / c['after']:.2f}x); same search: "
              f"{summary[planner]['same_search']}")  # fmt: skip
    record = load.record()
    if warning := load_warning(record):
        print(warning)
    if args.json:
        write_json(
            args.json,
            {
                "machine": machine_record(),
                "load": record,
                "before": args.before,
                "command": "dcee " + " ".join(DEMO).replace("dcee-cl", "NAME"),
                "threads": ONE_CORE,
                "runs": runs,
                "summary": summary,
            },
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
