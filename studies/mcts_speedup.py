"""Our tree search on Stone Soup's published MCTS example, two code versions in alternation
(issue 82).

Issue 82 asks for ``dcee-mcts`` at least 50 times faster than Stone Soup's
``MCTSRolloutSensorManager`` on its published example (``studies/stonesoup_mcts_study.py``).
This times our side alone, the search of :func:`dcee.perf.stonesoup_mcts.dcee_search` (seed 1,
57 moves: the length of Stone Soup's search on that seed), with the code of ``--before`` (a git
worktree made for it) and with this checkout's, each side in a fresh process, ``--rounds``
times in alternation; the kernels are compiled by a first search of each side that is not
counted. It checks that both sides fly the same search (every x-y RMSE within 1e-9 m) and
writes JSON with each run's median ms per decision, the machine and the load beside the run.

    .venv/bin/python studies/mcts_speedup.py --before c1d6e84 \\
        [--json docs/results/perf/mcts-speedup.json] [--rounds 3]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.perf.machine import alternate_code, store_timing

ROOT = Path(__file__).resolve().parent.parent
TIMED = (
    "import json, numpy as np; from dcee.perf.stonesoup_mcts import dcee_search; "
    "r = dcee_search('dcee-mcts', 1, 57); "
    "print(json.dumps({'ms': float(np.median(r['decision_ms'])), 'rmse': r['rmse']}))"
)


def main(argv: list[str] | None = None) -> int:
    try:
        args, runs, load = alternate_code(
            ROOT, argv, __doc__.splitlines()[0], TIMED, 3,
            lambda side, r, t: print(f"{side} round {r}: {t['ms']:.2f} ms", flush=True),
        )  # fmt: skip
    except DceeInputError as e:
        print(f"mcts_speedup: error: {e}", file=sys.stderr)
        return 2
    # the same search: every x-y RMSE within 1e-9 m (a change of the arithmetic's last bits,
    # erfc by Horner's rule say, moves them by ~1e-15 m without moving the searcher)
    same = all(
        np.allclose(a["rmse"], b["rmse"], rtol=0.0, atol=1e-9)
        for a, b in zip(runs["before"], runs["after"], strict=True)
    )
    before_ms = float(np.median([r["ms"] for r in runs["before"]]))
    after_ms = float(np.median([r["ms"] for r in runs["after"]]))
    print(f"{before_ms:.2f} -> {after_ms:.2f} ms a decision ({before_ms / after_ms:.2f}× faster);"
          f" the same searches: {same}")  # fmt: skip
    store_timing(
        args.json,
        load,
        before=args.before,
        runs={side: [r["ms"] for r in rs] for side, rs in runs.items()},
        before_ms=before_ms,
        after_ms=after_ms,
        speedup=before_ms / after_ms,
        same_searches=same,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
