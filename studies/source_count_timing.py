"""Decision and update time with the count unknown against one release (issue 45: "the decision
time with K ≤ 3 at most 3× today's at the same particle count"), in one run on one pinned core.

The same searches (``dcee-cl``, seed 0, 10,000 particles, the paper's 900 s) over the same
truths, once with today's one-release filter and once with ``estimator.max_sources`` = 2 and 3;
each in its own process pinned to core 0 with one thread (``taskset -c 0``, NUMBA/OMP/OPENBLAS
threads 1), the kernels compiled by a first warm-up search of each count. Run it with nothing
else on the machine; the machine's load is recorded beside the times.

    python studies/source_count_timing.py --out docs/results/source-count/timing.csv
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parent.parent
DCEE = ROOT / ".venv" / "bin" / "dcee"
TRUTHS = {
    "paper:1, one release": ["--scenario", "paper:1"],
    "random2:1 (tuning), two releases": ["--scenario", "random2:1"],
}
COUNTS = (1, 2, 3)


def pinned_search(args: list[str], folder: Path) -> dict:
    """The summary of ``dcee run ARGS --strategy dcee-cl --seed 0 --no-figure --out FOLDER``
    run on core 0 with one thread (taskset, NUMBA/OMP/OPENBLAS threads 1)."""
    env = {
        **os.environ,
        "NUMBA_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
    }
    cmd = ["taskset", "-c", "0", str(DCEE), "run", *args, "--strategy", "dcee-cl"]
    cmd += ["--seed", "0", "--no-figure", "--out", str(folder)]
    subprocess.run(cmd, check=True, env=env, capture_output=True)
    return json.loads((folder / "summary.json").read_text())


def one(args: list[str], count: int, folder: Path) -> dict:
    extra = ["--set", "search.particles=10000", "--set", f"estimator.max_sources={count}"]
    return pinned_search([*args, *extra], folder)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # compile the kernels of every count first: the count bank's and the exploration
        # guard's compile on their first call, which a machine without the compiled cache
        # (a fresh checkout) otherwise counts in the first count-unknown search's decisions
        # (2026-12-02, a fresh machine: paper:1 with max_sources 2 timed 38.8 ms a decision
        # after a warm-up of one release only; the same search again, beside a campaign,
        # 14.3 ms)
        for count in COUNTS:
            one(TRUTHS["paper:1, one release"], count, Path(tmp) / f"warm-up-{count}")
        for label, truth in TRUTHS.items():
            for count in COUNTS:
                load = os.getloadavg()[0]
                s = one(truth, count, Path(tmp) / f"{len(rows)}")
                rows.append(
                    {
                        "truth": label,
                        "max_sources": count,
                        "decision_ms_mean": 1e3 * s["decision_seconds_mean"],
                        "update_ms_mean": 1e3 * s["update_seconds_total"] / s["readings"],
                        "steps": s["steps"],
                        "load_before": round(load, 2),
                        "commit": s["code"]["commit"],
                    }
                )
                print(rows[-1], flush=True)
    frame = pd.DataFrame(rows)
    base = frame[frame.max_sources == 1].set_index("truth")
    frame["decision_ratio"] = frame.apply(
        lambda r: r.decision_ms_mean / base.loc[r.truth, "decision_ms_mean"], axis=1
    )
    frame["update_ratio"] = frame.apply(
        lambda r: r.update_ms_mean / base.loc[r.truth, "update_ms_mean"], axis=1
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(args.out, index=False)
    print(frame.to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
