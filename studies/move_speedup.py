"""The resample-move step and the filter update, two code versions in alternation (issue 17).

`dcee perf` judges the resample + MCMC move over 500 readings (20,000 particles) by its ratio to
one filter update in the same run (target ≤ 76×, a third of the 227× of when issue 17 was
filed). A ratio moves when either side does: a faster update raises it with the move unchanged.
This study times both workloads of :mod:`dcee.perf.workloads` (``_filter_update``,
``_resample_move``) with the code of ``--before`` (a git worktree made for it) and with this
checkout's, each side in a fresh process, ``--rounds`` times in alternation so that both see the
same machine; the kernels are compiled by a first run of each side that is not counted. Writes
JSON with each run's medians, the machine and the load beside the run (docs/results/perf/; the
speed table on docs/performance.md is generated from it).

    .venv/bin/python studies/move_speedup.py --before 825da4d \\
        [--json docs/results/perf/move-speedup.json] [--rounds 3]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.perf.machine import alternate_versions, alternation_args, json_from_package, store_timing

ROOT = Path(__file__).resolve().parent.parent
TIMED = (
    "import json; from dcee.perf import workloads as w; "
    "u = w._filter_update(15); m = w._resample_move(5); "
    "print(json.dumps({'update_ms': u.median, 'move_ms': m.median}))"
)


def _timed(src: Path) -> dict[str, float]:
    """Median ms of one filter update and of one resample + move, the package under ``src``,
    and their ratio."""
    t = json_from_package(src, TIMED)
    return {**t, "ratio": t["move_ms"] / t["update_ms"]}


def main(argv: list[str] | None = None) -> int:
    def report(side: str, r: int, t: dict[str, float]) -> None:
        print(f"{side} round {r}: move {t['move_ms']:.1f} ms, update {t['update_ms']:.3f} ms, "
              f"{t['ratio']:.0f}×", flush=True)  # fmt: skip

    try:
        args = alternation_args(argv, __doc__.splitlines()[0], 3)
        runs, load = alternate_versions(ROOT, args.before, _timed, args.rounds, report)
    except DceeInputError as e:
        print(f"move_speedup: error: {e}", file=sys.stderr)
        return 2

    def median(side: str, key: str) -> float:
        return float(np.median([run[key] for run in runs[side]]))

    summary = {
        f"{side}_{key}": median(side, key)
        for side in runs
        for key in ("move_ms", "update_ms", "ratio")
    }
    summary["move_speedup"] = summary["before_move_ms"] / summary["after_move_ms"]
    summary["update_speedup"] = summary["before_update_ms"] / summary["after_update_ms"]
    ratios = f"{summary['before_ratio']:.0f}× -> {summary['after_ratio']:.0f}×"
    print(f"move {summary['move_speedup']:.2f}× faster, update {summary['update_speedup']:.2f}× "
          f"faster; move / update {ratios}")  # fmt: skip
    store_timing(args.json, load, before=args.before, runs=runs, **summary,
                 ratio_target=76.0)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
