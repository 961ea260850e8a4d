"""The fluctuation likelihood's along-wind bias without a planner (issue 29, lab note for
docs/turbulent.md; tuning configurations only).

Readings are taken at a fixed pattern round each true source (distances 1, 2, 3 and 5 m in eight
directions, at the source's height and 1 m above and below, ``--repeats`` hold-averaged readings
per point in a seeded random order, starting 60 s into the plume) and given to the filter alone
(all eight unknown, fluctuation likelihood, 10,000 particles). Prints per variant and truth the
median along-wind error of the posterior mean (m, positive downwind), the crosswind and vertical
errors and the share with the truth in the 95 % region.

    .venv/bin/python studies/fixed_design_bias.py --configs random:13-24 --variant base: \\
        --variant nsl0:estimator.near_source_length=0 [--truths puffs filament] [--workers 2]
"""

from __future__ import annotations

import argparse
import math
from multiprocessing import Pool

import numpy as np
import pandas as pd
from precision_variants import parse_variant, variant_scenario

from dcee.runs.assemble import make_searcher
from dcee.scenarios import expand_names
from dcee.simulation import make_truth

DISTANCES = (1.0, 2.0, 3.0, 5.0)  # m from the source
BEARINGS = np.deg2rad(np.arange(0, 360, 45))  # from the downwind direction


def one(task: tuple) -> dict:
    label, over, name, truth_kind, seed, repeats = task
    sc = variant_scenario(name, truth_kind, over)
    th = sc.truth_theta()
    down = -np.array([math.cos(th[5]), math.sin(th[5])])
    normal = np.array([-down[1], down[0]])
    heights = sorted({min(max(th[2] + dz, 0.2), 4.8) for dz in (-1.0, 0.0, 1.0)})
    pts = np.array(
        [
            [*(th[:2] + r * (math.cos(a) * down + math.sin(a) * normal)), z]
            for r in DISTANCES
            for a in BEARINGS
            for z in heights
        ]
    )
    lo, hi = np.array(sc.volume.low), np.array(sc.volume.high)
    pts = pts[np.all((pts >= lo) & (pts <= hi), axis=1)]  # inside the area
    truth, sensor = make_truth(sc, seed), sc.make_sensor()
    rng = np.random.default_rng(seed + 1000)
    pf = make_searcher(
        sc, None, np.random.default_rng(seed), np.random.default_rng(seed + 1), on_robot=False
    ).filter
    t = 60.0
    for k in rng.permutation(np.repeat(np.arange(len(pts)), repeats)):
        t += sc.dwell
        c = truth.sensed(pts[k], t, sc.average, sc.sensor.response_time)
        pf.update(pts[k], float(sensor.simulate(c, rng)))
    mean = pf.mean()[:3]
    err = mean[:2] - th[:2]
    return {
        "variant": label,
        "truth": truth_kind,
        "scenario": name,
        "along": float(err @ down),
        "cross": float(err @ normal),
        "vertical": float(mean[2] - th[2]),
        "truth_in_95": pf.in_credible_region(th[:3], 0.95),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--configs", nargs="+", default=["random:13-24"])
    ap.add_argument("--truths", nargs="+", default=["puffs", "filament"])
    ap.add_argument("--variant", action="append", default=[])
    ap.add_argument("--repeats", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    variants = [parse_variant(v) for v in (args.variant or ["base:"])]
    tasks = [
        (label, over, name, truth, 0, args.repeats)
        for label, over in variants
        for truth in args.truths
        for name in expand_names(args.configs)
    ]
    with Pool(args.workers) as pool:
        df = pd.DataFrame(pool.map(one, tasks, chunksize=1))
    print(
        df.groupby(["variant", "truth"])
        .agg(
            along=("along", "median"),
            cross=("cross", lambda x: x.abs().median()),
            vertical=("vertical", "median"),
            truth_in_95=("truth_in_95", "mean"),
            n=("along", "size"),
        )
        .round(2)
        .to_string()
    )


if __name__ == "__main__":
    main()
