"""One absurd reading inside a search: does it change the outcome? (issues 12 and 29)

Each (configuration, seed) is flown once as is and once per spike time with common random
numbers; in a spiked flight the first reading at or after the spike time reads
``factor`` × the true concentration there (floored at the sensor threshold, so a spike in clean
air is ``factor`` × threshold; capped below ``sensor.max_reading``, above which a reading is
refused as a fault rather than assimilated). A search "captured" by the spike is one acquired
without it and not with it.

    .venv/bin/python studies/spike_study.py --strategy dcee-cl --scenarios random:1-10 \\
        --seeds 2 --at 60 200 --outlier 0 0.01 [--particles 10000] [--csv out.csv]

Prints one line per flight and a table per outlier weight (``--outlier default`` uses the
configuration's own default). Every random draw comes from the episode seed.
"""

from __future__ import annotations

import argparse
import csv
import sys

from dcee.runs import run_episode
from dcee.scenarios import expand_names, load_scenario
from dcee.simulation import InjectedTruth, make_truth


def spike(factor: float, floor: float, cap: float):
    def inject(true: float) -> float:
        return min(factor * max(true, floor), cap)

    return inject


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--strategy", default="dcee-cl")
    ap.add_argument("--scenarios", nargs="+", default=["paper:1"])
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--particles", type=int, default=10000)
    ap.add_argument("--at", type=float, nargs="+", default=[60.0, 200.0])
    ap.add_argument("--factor", type=float, default=1e6)
    ap.add_argument("--outlier", nargs="+", default=["default"])
    ap.add_argument("--set", nargs="*", default=[], help="extra key=value overrides")
    ap.add_argument("--csv", default=None)
    args = ap.parse_args()
    extra = dict(kv.split("=", 1) for kv in args.set)
    rows = []
    for weight in args.outlier:
        over = {} if weight == "default" else {"estimator.outlier": float(weight)}
        for name in expand_names(args.scenarios):
            scenario = load_scenario(name).with_overrides(
                **{"search.particles": args.particles, **over, **extra}
            )
            s = scenario.sensor
            for seed in range(args.seeds):
                clean = run_episode(scenario, args.strategy, seed).summary
                for at in args.at:
                    truth = InjectedTruth(
                        make_truth(scenario, seed),
                        {at: spike(args.factor, s.threshold, 0.5 * s.max_reading)},
                    )
                    spiked = run_episode(scenario, args.strategy, seed, truth=truth).summary
                    when, true, value = truth.fired[0]
                    row = {
                        "outlier": weight,
                        "scenario": name,
                        "seed": seed,
                        "spike_time": when,
                        "true": true,
                        "spike": value,
                        "acquired": clean["source_acquired"],
                        "acquired_spiked": spiked["source_acquired"],
                        "rmse": clean["final_rmse"],
                        "rmse_spiked": spiked["final_rmse"],
                    }
                    rows.append(row)
                    print(
                        f"outlier {weight} {name} seed {seed} spike {value:.3g} at {when:g} s: "
                        f"acquired {row['acquired']} -> {row['acquired_spiked']}, RMSE "
                        f"{row['rmse']:.2f} -> {row['rmse_spiked']:.2f} m",
                        flush=True,
                    )
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    print("\n| outlier weight | flights | acquired without | captured by the spike | rescued |")
    print("|---|---|---|---|---|")
    for weight in args.outlier:
        rs = [r for r in rows if r["outlier"] == weight]
        base = sum(r["acquired"] for r in rs)
        lost = sum(r["acquired"] and not r["acquired_spiked"] for r in rs)
        gained = sum(r["acquired_spiked"] and not r["acquired"] for r in rs)
        print(f"| {weight} | {len(rs)} | {base} | {lost} | {gained} |")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
