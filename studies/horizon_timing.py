"""The decision time of `dcee-cl` one, two and three moves ahead (docs/plumes.md, issue 42): the
same lbm search (`random:13`, all eight unknown, the fluctuation likelihood, 10,000 particles,
seed 0) flown with `dcee-cl:horizon=1`, `=2` and `=3`, ``--rounds`` times in alternation, each a
`dcee run` of its own on one pinned core with one numba, OpenMP and BLAS thread. Writes JSON
with each search's mean decision time, the machine and the load beside the run
(docs/results/perf/horizon-timing.json); run it with nothing else on the machine.

    .venv/bin/python studies/horizon_timing.py [--json docs/results/perf/horizon-timing.json] \\
        [--rounds 2]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from demo_decision import ONE_CORE, ROOT

from dcee.perf.machine import LoadMonitor, store_timing

PLANNERS = ("dcee-cl:horizon=1", "dcee-cl:horizon=2", "dcee-cl:horizon=3")
SEARCH = [
    "run", "--scenario", "random:13", "--unknown", "full", "--likelihood", "fluctuation",
    "--truth", "lbm", "--particles", "10000", "--set", "truth.z=4.0", "--seed", "0",
    "-q", "--no-figure",
]  # fmt: skip


def _decision_ms(planner: str, out: Path) -> float:
    """One search with ``planner`` on one pinned core; its mean decision time in ms."""
    env = {**os.environ, **ONE_CORE}
    summary = out / "summary.json"
    command = ["taskset", "-c", "0", sys.executable, "-m", "dcee.cli", *SEARCH]
    command += ["--strategy", planner, "--out", str(out), "--json", str(summary)]
    subprocess.run(command, check=True, env=env, cwd=ROOT, stdout=subprocess.DEVNULL)
    return 1000.0 * json.loads(summary.read_text())["decision_seconds_mean"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, default=ROOT / "docs/results/perf/horizon-timing.json")
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args()
    times: dict[str, list[float]] = {p: [] for p in PLANNERS}
    with tempfile.TemporaryDirectory() as scratch, LoadMonitor() as load:
        for k in range(args.rounds):
            for planner in PLANNERS:
                out = Path(scratch) / f"{k}-{planner.replace(':', '_')}"
                times[planner].append(_decision_ms(planner, out))
    one, two, three = (float(np.mean(times[p])) for p in PLANNERS)
    print(
        f"mean decision: one move {one:.1f} ms, two moves {two:.1f} ms ({two / one:.2f}x), "
        f"three moves {three:.1f} ms ({three / one:.2f}x, {three / two:.2f}x two moves)"
    )
    store_timing(
        args.json,
        load.record(),
        search=" ".join(SEARCH),
        decision_ms=times,
        ratio=two / one,
        ratio_three=three / one,
        ratio_three_to_two=three / two,
    )


if __name__ == "__main__":
    main()
