"""Decision agreement: do the speed-ups change what the planners choose? (issue 17)

Each search is flown with the fast path (a :class:`~dcee.searcher.Searcher` keeps
:class:`~dcee.planning.particle_terms.ParticleTerms` across decisions and merges identical
particles). Before every decision the same belief, position and random numbers (a copy of the
planner's generator) also go through the reference path: no merging and a fresh cache. The two
choices are compared, and so are their costs. The search then follows the fast choice, so the
beliefs compared are the ones a real search meets (recorded beliefs, not synthetic ones).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from dcee.planning import get as get_planner
from dcee.planning.base import Belief, constructor_options, planner_class
from dcee.planning.particle_terms import ParticleTerms
from dcee.runs import SearchSimulation, planner_defaults
from dcee.scenarios import load_scenario


@dataclass
class Agreement:
    """One search's comparison: decisions made, identical choices, and the largest cost
    difference between the two paths relative to the spread of that decision's costs over its
    candidates (over every candidate of every decision)."""

    scenario: str
    strategy: str
    seed: int
    decisions: int
    same_choice: int
    max_cost_diff_over_spread: float
    precision: str = "double"
    guard_fired: int = 0
    """decisions taken while the stall guard restricted the moves"""

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def search_agreement(
    scenario_name: str,
    strategy: str,
    seed: int,
    particles: int,
    steps: int,
    precision: str = "double",
) -> Agreement:
    """Fly ``steps`` decisions of one search and compare fast and reference decisions. With
    ``precision="single"`` or ``"interpolated"`` the search flies the planner with that option
    and the reference stays exact in double precision (today's full computation)."""
    scenario = load_scenario(scenario_name).with_overrides(**{"search.particles": particles})
    options = planner_defaults(strategy, scenario, None)
    # the reference is today's full computation: exact sums in double precision
    exact = (
        {"precision": "double"}
        if "precision" in constructor_options(planner_class(strategy))
        else {}
    )
    reference_planner = get_planner(strategy, **{**options, **exact})
    planner = (
        reference_planner
        if precision == "double"
        else get_planner(strategy, **{**options, "precision": precision})
    )
    sim = SearchSimulation(scenario, seed, planner)
    searcher = sim.searcher
    same = 0
    worst = 0.0
    decisions = 0
    for _ in range(steps):
        sim.sense()
        if sim.finished:
            break
        f = searcher.filter
        reference = Belief(f.theta, f.weights, f.sensor, f.plume, ParticleTerms(merge=False))
        rng = copy.deepcopy(searcher.rng)
        # the agent the searcher plans with (the stall guard's when it fires)
        agent = searcher.decision_agent()
        ref = reference_planner.decide(reference, searcher.position, agent, rng)
        waypoint = searcher.ask()
        fast = searcher.last_decision
        decisions += 1
        same += int(fast.index == ref.index)
        finite = np.isfinite(ref.costs) & np.isfinite(fast.costs)
        if finite.any():
            # relative to the spread of the costs over the candidates: what the choice sees
            scale = max(float(np.ptp(ref.costs[finite])), 1e-300)
            diff = np.abs(fast.costs[finite] - ref.costs[finite]) / scale
            worst = max(worst, float(diff.max()))
        sim.move(waypoint)
    return Agreement(
        scenario_name, strategy, seed, decisions, same, worst, precision, searcher.guard_fired
    )
