"""Do the one-pass sums (dcee.planning.one_stage_sums, issue 46) change what infotaxis and
entrotaxis choose? Flies whole searches with them and, before every decision, decides again on
the same belief, with the same random numbers, through the general kernel (the matrix-product
sums of ``_grouped_stats``, and no terms kept across decisions); counts the decisions that
agree and the largest cost difference relative to the spread of the candidates' costs.

Usage: .venv/bin/python studies/one_pass_agreement.py [--particles N] [--json PATH]
"""

from __future__ import annotations

import argparse
import copy
import sys
import tempfile
from pathlib import Path

import numpy as np

import dcee.planning.hypothesis as hypothesis
import dcee.planning.predicted_kernels as kernels
from dcee.io import write_json
from dcee.perf.machine import machine_record
from dcee.planning.base import Belief
from dcee.planning.particle_terms import ParticleTerms

CONFIGS = ("paper:1", "paper:5", "paper:12")
STRATEGIES = ("infotaxis", "entrotaxis")


def _general(loc, log_nd, inv_sigma, det_offset, weights, groups, positions, v, out, bound, sp,
             want_kl, partial):  # fmt: skip
    """The one-pass kernel's arguments sent through the general kernel instead."""
    kernels._grouped_stats(
        loc, log_nd, inv_sigma, det_offset, np.zeros((4, 0)), weights, np.zeros((0, 5)), groups,
        positions, v, np.full_like(v, -np.inf), out, bound, sp, False, want_kl, partial,
    )  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=20_000)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    one_pass = kernels.one_stage_sums
    current: dict = {}
    costs = hypothesis.HypothesisPlanner.costs

    def both(self, belief, position, candidates, agent, rng):
        reference_rng = copy.deepcopy(rng)
        kernels.one_stage_sums = _general
        plain = Belief(belief.theta, belief.weights, belief.sensor, belief.plume, ParticleTerms(),
                       site=belief.site)  # fmt: skip
        try:
            ref, _ = costs(self, plain, position, candidates, agent, reference_rng)
        finally:
            kernels.one_stage_sums = one_pass
        got, info = costs(self, belief, position, candidates, agent, rng)
        spread = float(np.ptp(ref)) or 1.0
        current["decisions"] += 1
        current["same_choice"] += int(np.argmin(got) == np.argmin(ref))
        diff = float(np.max(np.abs(got - ref))) / spread
        current["max_cost_diff_over_spread"] = max(current["max_cost_diff_over_spread"], diff)
        return got, info

    hypothesis.HypothesisPlanner.costs = both
    from dcee.cli import cli

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for strategy in STRATEGIES:
            for config in CONFIGS:
                current.update(decisions=0, same_choice=0, max_cost_diff_over_spread=0.0)
                out = Path(tmp) / f"{strategy}-{config.replace(':', '')}"
                cli.main(["run", "--scenario", config, "--strategy", strategy, "--seed", "0",
                          "--particles", str(args.particles), "--out", str(out), "--no-figure"],
                         standalone_mode=False)  # fmt: skip
                rows.append({"config": config, "strategy": strategy, **current})
                print(rows[-1], flush=True)
    total = sum(r["decisions"] for r in rows)
    same = sum(r["same_choice"] for r in rows)
    print(f"same choice in {same}/{total} decisions")
    if args.json:
        write_json(
            args.json,
            {"machine": machine_record(), "particles": args.particles, "searches": rows,
             "decisions": total, "same_choice": same},
        )  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
