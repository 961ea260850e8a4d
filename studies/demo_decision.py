"""The demo's decision time on one pinned core, two code versions in alternation (issue 46).

Runs the README's demo search (``dcee run --scenario paper:1 --strategy dcee-cl --seed 0``,
20,000 particles) with one numba, OpenMP and BLAS thread, pinned to one core (``taskset``),
once with the code of ``--before`` (a git worktree made for it) and once with this checkout's,
``--rounds`` times in alternation so that both sides see the same machine; the kernels are
compiled by a first run of each side that is not counted. Writes JSON with each run's mean
decision (the search's ``decision_seconds_mean``), the final RMSE (the two sides must fly the
same search), the machine and the load beside the run (docs/results/perf/, the table on
docs/performance.md is generated from it).

    .venv/bin/python studies/demo_decision.py --before cae7e4f \\
        [--json docs/results/perf/demo-decision.json] [--rounds 3]
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.perf.machine import LoadMonitor, alternation_args, code_at, package_env, store_timing

ROOT = Path(__file__).resolve().parent.parent
DEMO = ["run", "--scenario", "paper:1", "--strategy", "dcee-cl", "--seed", "0"]
ONE_CORE = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def _search(src: Path, out: Path) -> dict:
    """One demo search with the package under ``src`` on one pinned core; its summary."""
    env = package_env(src, **ONE_CORE)
    command = ["taskset", "-c", "0", sys.executable, "-m", "dcee.cli", *DEMO, "--out", str(out)]
    subprocess.run(command, env=env, check=True, capture_output=True, cwd=ROOT)
    return json.loads((out / "summary.json").read_text(encoding="utf-8"))


def main(argv: list[str] | None = None) -> int:
    try:
        args = alternation_args(argv, __doc__.splitlines()[0], 3)
    except DceeInputError as e:
        print(f"demo_decision: error: {e}", file=sys.stderr)
        return 2
    if shutil.which("taskset") is None:
        print(
            "demo_decision: error: taskset (util-linux) is needed to pin one core", file=sys.stderr
        )
        return 2
    work = Path(tempfile.mkdtemp())
    runs: dict[str, list[dict]] = {"before": [], "after": []}
    try:
        with code_at(ROOT, args.before) as before_src:
            sides = {"before": before_src, "after": ROOT / "src"}
            for side, src in sides.items():  # compile each side's kernels (not counted)
                _search(src, work / f"warm-{side}")
            with LoadMonitor() as load:
                for r in range(args.rounds):
                    for side, src in sides.items():
                        summary = _search(src, work / f"{side}-{r}")
                        runs[side].append(
                            {
                                "decision_ms_mean": 1e3 * summary["decision_seconds_mean"],
                                "final_rmse": summary["final_rmse"],
                                "steps": summary["steps"],
                            }
                        )
                        print(f"{side} round {r}: {runs[side][-1]['decision_ms_mean']:.1f} ms",
                              flush=True)  # fmt: skip
    except DceeInputError as e:
        print(f"demo_decision: error: {e}", file=sys.stderr)
        return 2
    finally:
        shutil.rmtree(work, ignore_errors=True)
    before = float(np.median([r["decision_ms_mean"] for r in runs["before"]]))
    after = float(np.median([r["decision_ms_mean"] for r in runs["after"]]))
    same = all(
        b["final_rmse"] == a["final_rmse"] and b["steps"] == a["steps"]
        for b, a in zip(runs["before"], runs["after"], strict=True)
    )
    print(f"mean decision: {before:.1f} ms -> {after:.1f} ms ({before / after:.2f}x); "
          f"same search: {same}")  # fmt: skip
    store_timing(
        args.json,
        load.record(),
        before=args.before,
        command="dcee " + " ".join(DEMO),
        threads=ONE_CORE,
        runs=runs,
        before_ms=before,
        after_ms=after,
        speedup=before / after,
        same_search=same,
        target_ms=15.0,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
