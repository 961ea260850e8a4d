"""Decision workloads of ``dcee perf``: a real posterior to decide on (a particle filter that
has read along ``paper:1``'s plume, or one stalled where the plume points away), and planners'
decisions timed in alternation with the plain compiled loop and the NumPy reference that
compute the same statistics (:mod:`dcee.perf.floor`), so that every ratio's two sides see the
same machine load. The rest of the standard workloads and their targets:
:mod:`dcee.perf.workloads`."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from dcee.estimation import ParticleFilter
from dcee.models import isotropic_concentration
from dcee.models.plume import isotropic_concentration_reference
from dcee.perf.floor import floor_decision
from dcee.perf.timing import RATIO_TO_FLOOR_TARGETS, Timing, times_ms
from dcee.planning import get as get_planner
from dcee.planning.predicted import PredictionContext
from dcee.planning.predicted_reference import predicted_posterior_stats_reference
from dcee.runs import streams
from dcee.scenarios import load_scenario
from dcee.searcher import Searcher


def posterior_filter(n_particles: int, n_readings: int = 5, seed: int = 0) -> ParticleFilter:
    """A ``paper:1`` filter after ``n_readings`` readings along the plume's axis (y = 12 m)."""
    scenario = load_scenario("paper:1")
    truth_rng, filter_rng, _, _ = streams(seed)
    sensor = scenario.make_sensor()
    pf = ParticleFilter(scenario.make_prior(), sensor, n_particles=n_particles, seed=filter_rng)
    theta = scenario.truth_theta()[None]
    for x in np.linspace(10.0, 26.0, n_readings):
        p = np.array([x, 12.0, 4.0])
        c = isotropic_concentration(theta, p[None])[0, 0]
        pf.update(p, float(sensor.simulate(c, truth_rng)))
    return pf


def searcher_for(pf: ParticleFilter, strategy: str, **options) -> Searcher:
    agent = load_scenario("paper:1").make_agent()
    searcher = Searcher(pf, get_planner(strategy, **options), agent, np.random.default_rng(0))
    searcher.position = np.array([26.0, 12.0, 4.0])
    return searcher


def timed_decision(
    name: str, n: int, strategy: str, target: float | None, repeats: int, **options
) -> Timing:
    pf = posterior_filter(n)
    searcher = searcher_for(pf, strategy, **options)
    hyp = options.get("n_hypotheses", 40)
    extra = f", horizon {options['horizon']}" if "horizon" in options else ""
    desc = f"one {strategy} decision, {n:,} particles, 8 moves × {hyp} readings{extra}"
    if strategy == "mpc":
        desc = f"one mpc decision, {n:,} particles, 8 moves"
    forget = searcher.planning_cache.forget  # every decision computes its own terms
    return Timing(name, desc, target, times_ms(searcher.ask, repeats, forget))


def stall_filter(n_particles: int, seed: int = 1) -> ParticleFilter:
    """A ``paper:12`` filter after 60 non-detections near the start (a 6 × 6 grid of 1 m
    cells at (2..7, 2..7, 4) m): the flat posterior of a search that has not met the plume,
    where detections are rare and the stratified expectation keeps every hypothesis distinct."""
    scenario = load_scenario("paper:12")
    pf = ParticleFilter(
        scenario.make_prior(), scenario.make_sensor(), n_particles=n_particles, seed=seed
    )
    for k in range(60):
        pf.update(np.array([2.0 + k % 6, 2.0 + (k // 6) % 6, 4.0]), 0.0)
    return pf


def reference_inputs(searcher: Searcher, n_hypotheses: int = 40):
    """What a decision of ``searcher`` computes, as inputs to the references: its belief, its
    admissible candidates (M, 3) and J hypothesised readings per candidate (M, J) drawn by the
    planners' own machinery (sampled expectation)."""
    belief = searcher.belief()
    candidates, _ = searcher.agent.candidates(searcher.position)
    ctx = PredictionContext(belief, n_hypotheses, 1, np.random.default_rng(0))
    idx = ctx.position_index(candidates)
    readings = np.stack([ctx.readings(idx[k : k + 1])[0][:, 0] for k in range(len(idx))])
    return belief, candidates, readings


def numpy_decision(belief, candidates: np.ndarray, readings: np.ndarray) -> None:
    """The NumPy reference of the same statistics: the plume and the predicted posteriors
    (:func:`~dcee.planning.predicted_reference.predicted_posterior_stats_reference`)."""
    plume = belief.plume
    conc = isotropic_concentration_reference(
        belief.theta, candidates, plume.min_distance, *plume.shape
    ).T
    dist = np.linalg.norm(belief.source[None, :, :] - candidates[:, None, :], axis=2)
    m_count, j_count = readings.shape
    task_pos = np.repeat(np.arange(m_count), j_count)[:, None]
    predicted_posterior_stats_reference(
        conc,
        belief.source,
        belief.weights,
        task_pos,
        readings.reshape(-1, 1),
        belief.sensor,
        np.maximum(dist, plume.min_distance),
    )


def decisions_interleaved(
    items: list[tuple[str, str, float | None]],
    n: int,
    repeats: int,
    make_filter: Callable[[int], ParticleFilter] = posterior_filter,
    where: str = "",
    position: tuple[float, float, float] | None = None,
    references: bool = False,
) -> list[Timing]:
    """Decisions of several planners timed in alternation (one decision of each per round,
    each planner with its own searcher and filter), so that the ratios between them are
    measured under the same machine load: on this shared machine blocks timed one after the
    other drift apart by 2x and more.

    ``references``: each round also times the plain compiled loop (:mod:`dcee.perf.floor`) and,
    in the first three rounds, the NumPy reference, both on the first searcher's belief,
    candidates and 40 hypothesised readings per candidate; every decision then gets its
    ``ratio_to`` them."""
    searchers = [searcher_for(make_filter(n), strategy) for _, strategy, _ in items]
    if position is not None:
        for searcher in searchers:
            searcher.position = np.array(position)
    for searcher in searchers:
        searcher.ask()  # warm-up: compilation caches, allocator
    calls: list[Callable[[], object]] = [s.ask for s in searchers]
    if references:
        belief, cands, readings = reference_inputs(searchers[0])
        out = np.empty((*readings.shape, 6))
        calls.append(
            lambda: floor_decision(
                belief.theta, belief.weights, cands, readings, belief.sensor, belief.plume, out
            )
        )
        calls[-1]()  # warm-up
    times: list[list[float]] = [[] for _ in calls]
    numpy_times: list[float] = []
    for round_ in range(repeats):
        for k, call in enumerate(calls):
            if k < len(searchers):
                searchers[k].planning_cache.forget()  # every decision computes its own terms
            t0 = time.perf_counter()
            call()
            times[k].append(1e3 * (time.perf_counter() - t0))
        if references and round_ < 3:
            t0 = time.perf_counter()
            numpy_decision(belief, cands, readings)
            numpy_times.append(1e3 * (time.perf_counter() - t0))
    out_timings = [
        Timing(
            name,
            f"one {strategy} decision, {n:,} particles, 8 moves × 40 readings{where} "
            "(timed in alternation with the other decisions of its group)",
            target,
            t,
        )
        for (name, strategy, target), t in zip(items, times, strict=False)
    ]
    if references:
        floor = Timing(
            f"floor-decision-{n // 1000}k",
            f"the plain compiled loop (dcee.perf.floor): the same statistics of "
            f"{readings.size} (move, reading) tasks, {n:,} particles, nothing shared",
            None,
            times[-1],
        )
        numpy_ref = Timing(
            f"numpy-decision-{n // 1000}k",
            "the NumPy reference of the same statistics (3 rounds)",
            None,
            numpy_times,
        )
        for t in out_timings:
            t.ratio_to = {"floor": t.median / floor.median, "numpy": t.median / numpy_ref.median}
            if t.name in RATIO_TO_FLOOR_TARGETS:
                t.ratio_target = ("floor", RATIO_TO_FLOOR_TARGETS[t.name])
            t.note = (
                f"{t.ratio_to['floor']:.2f}× the plain compiled loop, "
                f"{t.ratio_to['numpy']:.3f}× the NumPy reference (same run)"
            )
        out_timings += [floor, numpy_ref]
    return out_timings
