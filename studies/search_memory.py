"""Peak memory of a search by planner and particle count: the measurement behind
:data:`dcee.search_memory.BYTES_PER_PARTICLE` and :data:`~dcee.search_memory.BASE_BYTES`.

Each row is one ``dcee run --scenario paper:1`` in its own process (a 6 s budget: three
decisions; at 10⁶ particles 40 decisions peaked 4 % higher, the position terms being capped),
its peak resident memory read from the kernel (``os.wait4``'s ``ru_maxrss``). Writes a JSON
that ``tests/test_search_memory.py`` checks the estimate against.

    python studies/search_memory.py --json docs/results/perf/search-memory.json
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RUNS = (
    ("mpc", ()),
    ("dcee-cl", ()),
    ("infotaxis", ()),
    ("dcee-mcts", ()),
    ("dcee-cl", ("--likelihood", "fluctuation", "--truth", "filament")),
    ("dcee-cl", ("--set", "estimator.max_sources=2")),
)


def peak_bytes(args: list[str]) -> int:
    """Peak resident bytes of ``dcee run ARGS`` in a child process."""
    exe = Path(sys.executable).parent / "dcee"
    proc = subprocess.Popen(
        [str(exe), "run", *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"dcee run {' '.join(args)} failed: {proc.stderr.read().decode()}")
    return int(usage.ru_maxrss) * 1024  # kB on Linux


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, required=True)
    ap.add_argument("--particles", type=int, nargs="+", default=[20_000, 1_000_000])
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT / "src"))
    from dcee.perf.machine import machine_record
    from dcee.provenance import code_version
    from dcee.search_memory import BASE_BYTES, BYTES_PER_PARTICLE

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for strategy, extra in RUNS:
            for n in args.particles:
                out = Path(tmp) / f"{strategy}-{len(rows)}"
                run = ["--scenario", "paper:1", "--strategy", strategy, "--particles", str(n)]
                run += ["--budget", "6", "--no-figure", "-q", "--out", str(out), *extra]
                peak = peak_bytes(run)
                sources = 2 if "estimator.max_sources=2" in extra else 1
                rows.append(
                    {"strategy": strategy, "options": list(extra), "particles": n,
                     "sources": sources, "peak_bytes": peak}
                )  # fmt: skip
                print(f"{strategy} {' '.join(extra)} {n:,}: {peak / 2**30:.2f} GiB", flush=True)
    doc = {
        "code_version": code_version(),
        "machine": machine_record(),
        "estimate": {"base_bytes": BASE_BYTES, "bytes_per_particle": BYTES_PER_PARTICLE},
        "runs": rows,
    }
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(doc, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
