"""Median decision and filter-update times at paper scale.

Run: .venv/bin/python benchmarks/decision_times.py [N_PARTICLES]

The belief is a real posterior after readings along the plume of paper:1 (not the flat prior),
so most hypothesised readings are detections — the expensive case. Timings are medians of
repeated calls measured in one process; the machine is shared, so compare ratios within a run.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time

import numpy as np

from dcee import Searcher, planners
from dcee.estimation import ParticleFilter
from dcee.models import isotropic_concentration
from dcee.scenarios import load_scenario
from dcee.simulation import streams


def _median_ms(fn, repeats: int) -> float:
    fn()  # warm-up (compilation, caches)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20_000
    scenario = load_scenario("paper:1")
    truth_rng, filter_rng, _, _ = streams(0)
    sensor = scenario.make_sensor()
    pf = ParticleFilter(scenario.make_prior(), sensor, n_particles=n, seed=filter_rng)
    theta = scenario.truth_theta()[None]
    for x in (10, 14, 18, 22, 26):
        p = np.array([x, 12.0, 4.0])
        pf.update(
            p, float(sensor.simulate(isotropic_concentration(theta, p[None])[0, 0], truth_rng))
        )
    agent = scenario.make_agent()
    rows = {}
    for name, opts in [
        ("dcee", {}),
        ("entrotaxis", {}),
        ("infotaxis", {}),
        ("mpc", {}),
        ("dcee-ms", {"horizon": 2}),
    ]:
        searcher = Searcher(pf, planners.get(name, **opts), agent, np.random.default_rng(0))
        searcher.position = np.array([26.0, 12.0, 4.0])
        rows[f"{name}-decision"] = _median_ms(searcher.ask, 5 if name == "dcee-ms" else 15)
    pos = np.array([26.0, 12.0, 4.0])
    rows["filter-likelihood-one-reading"] = _median_ms(
        lambda: pf.log_likelihood(pf.theta, pos, 0.0), 30
    )
    # Grow the history to 500 readings at distinct positions, then time one full-history sweep.
    rng = np.random.default_rng(5)
    while pf.n_readings < 500:
        p = np.array([*rng.uniform(0, 50, 2), 4.0])
        pf.update(p, float(sensor.simulate(isotropic_concentration(theta, p[None])[0, 0], rng)))
    rows["mcmc-sweep-500-readings"] = _median_ms(pf._mh_sweep, 5)
    info = {
        "particles": n,
        "history_readings": int(pf.n_readings),
        "cpus": os.cpu_count(),
        "machine": platform.machine(),
        "python": platform.python_version(),
    }
    print(
        json.dumps({"info": info, "median_ms": {k: round(v, 2) for k, v in rows.items()}}, indent=2)
    )


if __name__ == "__main__":
    main()
