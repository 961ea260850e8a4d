"""Adaptive-path replays against the exact grid posterior (issue: a filter that keeps every mode).

For each path a planner flies a real search (x, y unknown, every other parameter known, the
isotropic truth and the paper's sensor, 80 readings); its positions and readings are then
replayed into fresh filters (several seeds, particle counts, move settings) and each filter's
final posterior mean is compared with the exact grid posterior's
(:func:`dcee.estimation.grid.location_grid_posterior`, 0.1 m cells). A filter passes when
|mean − exact mean| ≤ 0.3 exact sd on both coordinates. Also reported: the exact posterior mass
within 3 m of the truth and the filters' mass there.

    .venv/bin/python studies/replay_study.py [--paths 6] [--filters 10] [--out FILE.csv]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from dcee.estimation import ParticleFilter, SourcePrior
from dcee.estimation.grid import location_grid_posterior
from dcee.estimation.priors import Fixed, Uniform
from dcee.planning import get as get_planner
from dcee.scenarios import load_scenario
from dcee.searcher import Searcher
from dcee.simulation import make_truth

CONFIGS = ["paper:1", "paper:5", "paper:7", "paper:12", "paper:3", "paper:9"]


def xy_prior(scenario) -> SourcePrior:
    t = scenario.truth_theta()
    names = ("x", "y", "z", "q", "u", "phi", "zeta1", "zeta2")
    lo, hi = scenario.volume.low, scenario.volume.high
    d = {n: Fixed(float(t[i])) for i, n in enumerate(names)}
    d["x"], d["y"] = Uniform(lo[0], hi[0]), Uniform(lo[1], hi[1])
    return SourcePrior.from_dict(d)


def fly(scenario, strategy: str, seed: int, n_readings: int, particles: int):
    """Positions (K, 3) and readings (K,) of a planner-driven search."""
    rng = np.random.default_rng(seed)
    sensor = scenario.make_sensor()
    pf = ParticleFilter(xy_prior(scenario), sensor, n_particles=particles, seed=seed + 100)
    searcher = Searcher(pf, get_planner(strategy, n_hypotheses=40), scenario.make_agent(), rng)
    truth = make_truth(scenario, seed)
    pos = np.array(scenario.agent.start, dtype=float)
    out_p, out_z = [], []
    for k in range(n_readings):
        z = float(sensor.simulate(truth.concentration(pos, 0.0), rng))
        searcher.tell(pos, z, float(k))
        out_p.append(pos.copy())
        out_z.append(z)
        pos = searcher.ask()
    return np.array(out_p), np.array(out_z)


CHECKPOINTS = (20, 35, 50, 80)
"""readings after which a filter is compared with the exact posterior of the same readings"""


def replay(scenario, positions, readings, particles, seed, global_share):
    """Yields (readings so far, filter) at every checkpoint."""
    pf = ParticleFilter(
        xy_prior(scenario),
        scenario.make_sensor(),
        n_particles=particles,
        seed=seed,
        global_share=global_share,
    )
    for k, (p, z) in enumerate(zip(positions, readings, strict=True)):
        pf.update(p, z)
        if k + 1 in CHECKPOINTS:
            yield k + 1, pf


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--paths", type=int, default=6)
    ap.add_argument("--filters", type=int, default=10)
    ap.add_argument("--readings", type=int, default=80)
    ap.add_argument("--strategy", default="mixed", help="planner, or mixed: dcee and infotaxis")
    ap.add_argument("--out", type=Path, default=Path("docs/results/replay.csv"))
    args = ap.parse_args()
    rows = []
    for k in range(args.paths):
        name = CONFIGS[k % len(CONFIGS)]
        scenario = load_scenario(name)
        seed = k // len(CONFIGS)
        strategy = ("dcee", "infotaxis")[k % 2] if args.strategy == "mixed" else args.strategy
        positions, readings = fly(scenario, strategy, seed, args.readings, 5000)
        theta = scenario.truth_theta()
        lo, hi = scenario.volume.low, scenario.volume.high
        exact = {
            n: location_grid_posterior(
                theta,
                lo[:2],
                hi[:2],
                0.25,
                positions[:n],
                readings[:n],
                scenario.make_sensor(),
                refine=10,
            )
            for n in CHECKPOINTS
            if n <= len(readings)
        }
        for particles in (5000, 20000):
            for global_share in (0.2, 0.0):
                for s in range(args.filters):
                    for n, pf in replay(scenario, positions, readings, particles, s, global_share):
                        ex = exact[n]
                        err = np.abs(pf.mean() - ex.mean) / ex.sd
                        near = np.linalg.norm(pf.particles - theta[None, :2], axis=1) <= 3.0
                        rows.append(
                            {
                                "path": f"{name}/{seed}/{strategy}",
                                "readings": n,
                                "detections": int(
                                    (readings[:n] >= scenario.sensor.threshold).sum()
                                ),
                                "particles": particles,
                                "global_share": global_share,
                                "filter_seed": s,
                                "err_x_sd": err[0],
                                "err_y_sd": err[1],
                                "within_0_3_sd": bool(np.all(err <= 0.3)),
                                "exact_sd_x": ex.sd[0],
                                "exact_sd_y": ex.sd[1],
                                "exact_mass_3m": ex.mass_within(theta[:2], 3.0),
                                "filter_mass_3m": float(pf.weights[near].sum()),
                            }
                        )
        done = pd.DataFrame(rows)
        last = done[done.path == f"{name}/{seed}/{strategy}"]
        print(
            f"{name}/{seed}/{strategy}:",
            last.groupby(["particles", "global_share"]).within_0_3_sd.mean().round(2).to_dict(),
            flush=True,
        )
    df = pd.DataFrame(rows)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(args.out, index=False)
    table = df.groupby(["particles", "global_share", "readings"]).agg(
        filters=("within_0_3_sd", "size"),
        within=("within_0_3_sd", "sum"),
        median_err_sd=("err_x_sd", "median"),
    )
    table["share"] = table.within / table.filters
    print(table.to_string())


if __name__ == "__main__":
    main()
