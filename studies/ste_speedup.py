"""Our infotaxis decision on Stone Soup's STE workload, two code versions in alternation
(issue 82).

Issue 82 asks for ``infotaxis`` at least 50 times faster than Stone Soup's KL planner on Stone
Soup's STE example (``dcee perf --compare-stonesoup``). This runs that comparison
(:func:`dcee.perf.stonesoup_compare.compare`: 20 decisions a side in alternation with Stone
Soup, ``--repeats`` runs, the median of the runs' medians) with the code of ``--before`` (a git
worktree made for it) and with this checkout's, each in a fresh process, ``--rounds`` times in
alternation, so that both versions meet the same machine and the same Stone Soup; each version
compiles its kernels as it would on its own (:func:`dcee.perf.machine.package_env`), the first
run of each side is not counted. Writes JSON with each run's medians, the machine and the load
beside the run.

    .venv/bin/python studies/ste_speedup.py --before 5cbf2c4 \\
        [--json docs/results/perf/ste-speedup.json] [--rounds 3]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.perf.machine import alternate_code, store_timing

ROOT = Path(__file__).resolve().parent.parent
REPEATS = 4
TIMED = (
    "import json; from dcee.perf.stonesoup_compare import compare; "
    f"r = compare(20, {REPEATS}); "
    "print(json.dumps({'ours': r['dcee_infotaxis_median_ms'], "
    "'stonesoup': r['stonesoup_median_ms'], 'ratio': r['speedup']}))"
)


def main(argv: list[str] | None = None) -> int:
    try:
        args, runs, load = alternate_code(
            ROOT,
            argv,
            __doc__.splitlines()[0],
            TIMED,
            3,
            lambda side, r, t: print(
                f"{side} round {r}: ours {t['ours']:.3f} ms, Stone Soup {t['stonesoup']:.1f} ms,"
                f" {t['ratio']:.1f}x",
                flush=True,
            ),
        )
    except DceeInputError as e:
        print(f"ste_speedup: error: {e}", file=sys.stderr)
        return 2
    summary = {
        side: {
            key: float(np.median([r[key] for r in rs])) for key in ("ours", "stonesoup", "ratio")
        }
        for side, rs in runs.items()
    }
    before, after = summary["before"], summary["after"]
    print(
        f"ours {before['ours']:.3f} -> {after['ours']:.3f} ms a decision "
        f"({before['ours'] / after['ours']:.2f}x faster); against Stone Soup "
        f"{before['ratio']:.1f}x -> {after['ratio']:.1f}x"
    )
    store_timing(
        args.json,
        load,
        before=args.before,
        repeats=REPEATS,
        runs=runs,
        before_ms=before["ours"],
        after_ms=after["ours"],
        speedup=before["ours"] / after["ours"],
        ratio_before=before["ratio"],
        ratio_after=after["ratio"],
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
