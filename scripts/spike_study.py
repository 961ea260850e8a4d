"""One absurd reading inside a search: does it change the outcome? (issue 12, outlier safety)

For each seed, an Infotaxis search on the isotropic truth is flown twice with common random
numbers: as is, and with the reading at t = 40 s (reading 20) replaced by 500 g/m³, 10⁶ × the
threshold. Reports both outcomes per seed and reading model.

    .venv/bin/python scripts/spike_study.py [--seeds 10] [--particles 10000]
"""

from __future__ import annotations

import argparse

from dcee.scenarios import load_scenario
from dcee.simulation import InjectedTruth, make_truth, run_episode

SPIKE = 500.0  # g/m³ = 1e6 × the 5e-4 g/m³ threshold
SPIKE_TIME = 40.0  # s: reading 20 with the 1 s dwell and 2 s moves of the isotropic truth


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--particles", type=int, default=10000)
    ap.add_argument("--scenario", default="paper:1")
    args = ap.parse_args()
    models = {
        "fluctuation (with the calm model)": {"estimator.likelihood": "fluctuation"},
        "fluctuation alone": {"estimator.likelihood": "fluctuation", "estimator.calm_prior": 0},
        "paper + outlier 0.01": {"estimator.outlier": 0.01},
        "paper (no outlier)": {},
    }
    for label, over in models.items():
        scenario = load_scenario(args.scenario).with_overrides(
            **{"search.particles": args.particles, **over}
        )
        same = 0
        for seed in range(args.seeds):
            ends = []
            for spiked in (False, True):
                truth = make_truth(scenario, seed)
                truth = InjectedTruth(truth, {SPIKE_TIME: SPIKE}) if spiked else truth
                s = run_episode(scenario, "infotaxis", seed, truth=truth).summary
                ends.append((s["source_acquired"], round(s["final_rmse"], 2)))
            same += ends[0][0] == ends[1][0]
            print(f"{label}: seed {seed}: without {ends[0]}, with spike {ends[1]}", flush=True)
        print(f"{label}: outcome unchanged in {same}/{args.seeds}", flush=True)


if __name__ == "__main__":
    main()
