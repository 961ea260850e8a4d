"""Assemble a search from a configuration: the scenario's estimator (one filter, a bank of
them when several reading models compete, or one per source count when the count is unknown)
and a planner's constructor defaults, in a :class:`~dcee.searcher.Searcher`. The simulation, the
ROS node and ``dcee replay`` all build their searches here, so one scenario gives the same search
wherever it runs."""

from __future__ import annotations

from typing import Any

import numpy as np

from dcee.estimation.model_bank import ModelBank
from dcee.estimation.multi_source import MultiSourceFilter
from dcee.estimation.particle_filter import ParticleFilter
from dcee.estimation.source_count import FOUND_SHARE, SourceCountBank
from dcee.planning.base import Planner, planner_class
from dcee.runs.identity import scenario_key
from dcee.scenarios import Scenario
from dcee.scenarios.schema.truth import MIN_SOURCE_SEPARATION
from dcee.searcher import Searcher
from dcee.stopping import DEFAULT_STOP_SHARE


def make_searcher(
    scenario: Scenario,
    planner: Planner | None,
    filter_rng: np.random.Generator,
    planner_rng: np.random.Generator,
    on_robot: bool = True,
) -> Searcher:
    """The scenario's filter (prior, estimator reading model, plume model, scale) and
    ``planner`` in a :class:`~dcee.searcher.Searcher`; the simulation, the ROS node and
    ``dcee replay`` build theirs here (with the generators of :func:`streams`). ``on_robot``:
    the scenario's stop rule as a robot applies it (:meth:`Scenario.stop_rule`: the default
    rule unless ``search.stop_spread`` says otherwise) and one altitude unless ``agent.climb`` is
    set (:meth:`Scenario.resolved_climb`); False, as a simulated study does."""
    search = scenario.search
    models = scenario.reading_models
    # the first (preferred) model draws from filter_rng itself, as a lone filter does; the others
    # from children of it (spawning does not move filter_rng). So a second model changes nothing
    # while it is not selected, and comparisons with and without it are paired exactly.
    rngs = [filter_rng, *filter_rng.spawn(len(models) - 1)]
    settings = {
        "n_particles": search.particles,
        "resample_threshold": search.resample_threshold,
        "mcmc_steps": search.mcmc_steps,
        "global_share": search.global_share,
        "diversify": search.diversify,
        "max_sweeps": search.max_sweeps,
        "move_history": search.move_history,
        "reading_weight": scenario.reading_weight,
        "repeat_radius": scenario.repeat_radius,
        "repeat_power": scenario.repeat_power,
        "anemometer": scenario.make_anemometer(),
    }
    filters = [
        ParticleFilter(
            scenario.make_prior(),
            scenario.make_estimator_sensor(model),  # the reading model of filter and planners
            scenario.make_plume(model),
            seed=rng,
            **settings,
        )
        for model, rng in zip(models, rngs, strict=True)
    ]
    estimator: ParticleFilter | ModelBank | SourceCountBank
    if len(filters) > 1:
        estimator = ModelBank(filters, models, scenario.reading_model_priors)
    elif scenario.estimator.max_sources > 1:
        # one filter per count; K >= 2 draw from children of filter_rng (spawning does not move
        # it), so the one-release filter is the lone filter's, draw for draw
        kmax = scenario.estimator.max_sources
        children = filter_rng.spawn(kmax)  # the last one: the bank's bridge sampling
        more = [
            MultiSourceFilter(
                k,
                scenario.make_prior(),
                filters[0].sensor,
                filters[0].plume,
                seed=rng,
                min_separation=MIN_SOURCE_SEPARATION,
                **settings,
            )
            for k, rng in zip(range(2, kmax + 1), children[:-1], strict=True)
        ]
        estimator = SourceCountBank(
            [filters[0], *more],
            scenario.estimator.count_prior,
            localised=DEFAULT_STOP_SHARE * search.acquired_rmse,
            found=FOUND_SHARE * search.acquired_rmse,
            seed=children[-1],
        )
    else:
        estimator = filters[0]
    searcher = Searcher(
        estimator,
        planner,
        scenario.make_agent(on_robot=on_robot),
        planner_rng,
        stall_guard=search.stall_guard,
        guard_spread=search.guard_share * search.acquired_rmse,
        stop_rule=scenario.stop_rule(on_robot),
        explore_guard=scenario.explore_guard,
    )
    searcher.scenario_key = scenario_key(scenario)
    return searcher


def planner_defaults(
    strategy: str, scenario: Scenario, options: dict[str, Any] | None
) -> dict[str, Any]:
    """Constructor defaults: the scenario's hypothesis count and, for a planner that follows it
    (``dcee-cl``), its look-ahead :attr:`Scenario.lookahead` (a spec's own, ``dcee:hypotheses=25``
    or ``dcee-cl:horizon=1``, overrides either in :func:`dcee.planning.get`)."""
    opts = dict(options or {})
    cls = planner_class(strategy)
    if cls.uses_hypotheses:
        opts.setdefault("n_hypotheses", scenario.search.hypotheses)
    if cls.follows_lookahead:
        # the scenario's look-ahead (Scenario.lookahead: 2 in a turbulent plume in open terrain)
        opts.setdefault("horizon", scenario.lookahead)
    return opts
