"""Would a 95 % region averaged over the reading models hold the truth where the selected
model's does not? A diagnosis on tuning configurations (issue 42; it decides nothing).

Flies each search as ``studies/precision_variants.py`` does (all eight unknown, fluctuation
likelihood, 10,000 particles, then the variant's overrides) and records, at the end, whether the
truth lies in the 95 % region of the selected member (what every summary reports) and in that of
the members' mixture, each member's particles weighted by its posterior probability (the region
a Bayesian average over the reading models gives; :func:`dcee.estimation.summaries.
in_credible_ellipsoid` on the pooled particles). The planners read the selected member either
way, so the searches are those of the variant, reading for reading.

    .venv/bin/python studies/mixture_region.py --configs random:13-40 --truths puffs filament \\
        --variant 'radius:estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]}' \\
        [--workers 2] [--csv out.csv]
"""

from __future__ import annotations

import argparse
import csv
import os
from multiprocessing import Pool

import numpy as np
from precision_variants import (
    add_variant_arguments,
    append_row,
    pinned_variants,
    variant_scenario,
)

from dcee.scenarios import expand_names


def one(task: tuple) -> dict:
    label, over, name, truth, seed = task
    from dcee.estimation.summaries import in_credible_ellipsoid
    from dcee.planning import get as get_planner
    from dcee.runs.assemble import planner_defaults
    from dcee.runs.simulation import SearchSimulation

    scenario = variant_scenario(name, truth, over)
    planner = get_planner("dcee-cl", **planner_defaults("dcee-cl", scenario, None))
    sim = SearchSimulation(scenario, seed, planner, None)
    # the loop of dcee.runs.run_episode, for one agent: run_episode keeps only the selected
    # member's particles, and the mixture needs every member's
    while True:
        sim.sense()
        waypoint = None if sim.finished else sim.searcher.ask()
        if waypoint is None:
            break
        sim.move(waypoint)
        if sim.over_budget:
            break
    summary = sim.summary("dcee-cl")
    bank, truth_xyz = sim.filter, np.asarray(scenario.truth_theta()[:3])
    members = getattr(bank, "members", [bank])
    probs = getattr(bank, "probabilities", np.ones(1))
    cols = members[0]._loc_block
    pooled = np.vstack([m.theta[:, cols] for m in members])
    weights = np.concatenate([p * m.weights for p, m in zip(probs, members, strict=True)])
    return {
        "variant": label,
        "truth": truth,
        "scenario": name,
        "seed": seed,
        "acquired": summary["source_acquired"],
        "final_rmse": summary["final_rmse"],
        "truth_in_95": summary["truth_in_95"],
        "mixture_in_95": in_credible_ellipsoid(
            pooled, weights / weights.sum(), truth_xyz[cols], 0.95
        ),
        "model": summary.get("model", ""),
        "model_probability": summary.get("model_probability", 1.0),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--configs", nargs="+", default=["random:13-40"])
    ap.add_argument("--truths", nargs="+", default=["puffs", "filament"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--csv", default=None)
    add_variant_arguments(ap)
    args = ap.parse_args()
    variants = pinned_variants(args)
    tasks = [
        (label, over, name, truth, 0)
        for label, over in variants
        for truth in args.truths
        for name in expand_names(args.configs)
    ]
    done: set[tuple[str, ...]] = set()
    if args.csv and os.path.exists(args.csv):  # resumable: finished searches are kept
        with open(args.csv, newline="") as fh:
            done = {(r["variant"], r["truth"], r["scenario"]) for r in csv.DictReader(fh)}
    todo = [t for t in tasks if (t[0], t[3], t[2]) not in done]
    with Pool(args.workers) as pool:
        for row in pool.imap_unordered(one, todo, chunksize=1):
            print(row, flush=True)
            if args.csv:
                append_row(args.csv, row)


if __name__ == "__main__":
    main()
