"""What a reading costs the simulated sensor: the GADEN playback's concentration query against
the lbm solver plume's (issue 84: at most as much per reading), both timed in one run,
alternating, on the 40 hypothesised positions a planner scores per move (in each truth's own
plume: the GADEN room's release row 0.5-6 m downwind, the lbm plume's 2-20 m), 200 rounds, each
at a new second. Each GADEN result file is read once, when first needed, and kept (the lbm
recording is loaded whole): the rounds time the queries with the files in memory, and the first
read of a file is timed apart.

    python studies/gaden_timing.py --json docs/results/gaden/timing.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
ROUNDS, READINGS = 200, 40


def _positions(
    rng: np.random.Generator, source: np.ndarray, reach: float, height: float
) -> np.ndarray:
    """READINGS points downwind (+x) of ``source`` within ``reach`` m, ±1 m across."""
    along = rng.uniform(0.5, reach, READINGS)
    across = rng.uniform(-1.0, 1.0, READINGS)
    return np.column_stack([source[0] + along, source[1] + across, np.full(READINGS, height)])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", required=True)
    args = ap.parse_args(argv)
    import numba

    from dcee.perf.machine import machine_record
    from dcee.provenance import code_version
    from dcee.scenarios import load_scenario
    from dcee.simulation import make_truth

    numba.set_num_threads(1)
    room = load_scenario(str(ROOT / "tests/data/gaden/empty-room"))
    gaden = make_truth(room, 0)
    # the lbm plume as the studies fly it: wind along +x (phi = 180°), the source in the plane
    plane = load_scenario("paper:1").with_overrides(
        **{
            "truth.model": "lbm",
            "truth.z": 4.0,
            "truth.phi": 180.0,
            "truth.x": 5.0,
            "truth.y": 25.0,
        }
    )
    lbm = make_truth(plane, 0)
    rng = np.random.default_rng(0)
    sides = {
        "gaden": (gaden, lambda: _positions(rng, np.array([2.0, 3.0]), 6.0, 0.5)),
        "lbm": (lbm, lambda: _positions(rng, np.array([5.0, 25.0]), 20.0, 4.0)),
    }
    times: dict[str, list[float]] = {k: [] for k in sides}
    # warm both: kernels compiled, and every file the rounds read loaded once (GADEN's result
    # files are read when first needed and kept, as the lbm recording is loaded whole); the
    # loading is timed apart, per file
    loads = []
    for r in range(ROUNDS):
        for name, (truth, points) in sides.items():
            t0 = time.perf_counter()
            truth.field(points(), 30.0 + r)
            if name == "gaden":
                loads.append(time.perf_counter() - t0)
    for r in range(ROUNDS):
        t = 30.0 + r  # a new time each round: GADEN reads another file, lbm another frame
        for name, (truth, points) in sides.items():
            p = points()
            t0 = time.perf_counter()
            values = truth.field(p, t)
            times[name].append((time.perf_counter() - t0) / READINGS)
            assert values.shape == (READINGS,)
    per = {k: float(np.median(v)) * 1e6 for k, v in times.items()}
    out = {
        "what": f"median µs per reading of {READINGS} positions, {ROUNDS} alternating rounds",
        "gaden_us_per_reading": per["gaden"],
        "lbm_us_per_reading": per["lbm"],
        "ratio_gaden_to_lbm": per["gaden"] / per["lbm"],
        "gaden_first_read_ms_per_file": float(np.median(loads)) * 1e3,
        "machine": machine_record(),
        "code": code_version(),
    }
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(out, indent=1))
    print(json.dumps({k: v for k, v in out.items() if k not in ("machine", "code")}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
