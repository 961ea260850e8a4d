"""Planner variants on a few named configurations, seed 0, 10,000 particles, two processes: a
lab-note check before a campaign (docs/held-out.md). Prints, per variant, how many acquired the
source, the median time to RMSE < 1 m (9999: never), the longest stall and the mean decision
time, then per configuration ``K:final RMSE/longest stall``.

    .venv/bin/python studies/quick_variants.py 'SPEC1;SPEC2' random:1,random:3 \\
        [source|full] [isotropic|filament] [paper|fluctuation]
"""

from __future__ import annotations

import sys
from multiprocessing import Pool


def one(args: tuple[str, str, str, str, str]) -> tuple:
    spec, name, unknown, truth, likelihood = args
    from dcee.runs import run_episode
    from dcee.scenarios import load_scenario

    overrides: dict[str, object] = {"search.particles": 10000, "unknown": unknown}
    if truth != "isotropic":
        overrides["truth.model"] = truth
    if likelihood:
        overrides["estimator.likelihood"] = likelihood
    scenario = load_scenario(name).with_overrides(**overrides)
    s = run_episode(scenario, spec, 0).summary
    return (
        spec,
        name,
        s["source_acquired"],
        s["final_rmse"],
        s["time_to_rmse_1m"],
        s["longest_stall"],
        s["decision_seconds_mean"],
    )


def main() -> None:
    specs, names = sys.argv[1].split(";"), sys.argv[2].split(",")
    unknown = sys.argv[3] if len(sys.argv) > 3 else "source"
    truth = sys.argv[4] if len(sys.argv) > 4 else "isotropic"
    likelihood = sys.argv[5] if len(sys.argv) > 5 else ""
    jobs = [(s, n, unknown, truth, likelihood) for s in specs for n in names]
    with Pool(2) as pool:
        results = pool.map(one, jobs, chunksize=1)
    for spec in specs:
        rows = [r for r in results if r[0] == spec]
        t1 = sorted((r[4] or 9999) for r in rows)
        print(
            f"{spec:50s} acq {sum(r[2] for r in rows)}/{len(rows)} medT1 {t1[len(t1) // 2]} "
            f"maxstall {max(r[5] for r in rows):.0f} "
            f"dec {1e3 * sum(r[6] for r in rows) / len(rows):.1f}ms"
        )
        print("    ", " ".join(f"{r[1].split(':')[1]}:{r[3]:.1f}/{r[5]:.0f}" for r in rows))


if __name__ == "__main__":
    main()
