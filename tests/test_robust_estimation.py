"""Robust estimation on turbulent plumes: hold-averaged readings, the meandering plume model,
outlier safety, the mode-keeping move against an exact grid posterior on adaptive paths, and
calibration of the credible region."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from dcee import DceeInputError, IsotropicPlume, ParticleFilter, Sensor
from dcee.estimation import SourcePrior
from dcee.estimation.filter_kernels import history_log_likelihood, history_log_likelihood_reference
from dcee.estimation.grid import location_grid_posterior
from dcee.estimation.priors import Fixed, Uniform
from dcee.estimation.summaries import in_credible_ellipsoid
from dcee.models.plume import isotropic_concentration, isotropic_concentration_reference
from dcee.planning import get as get_planner
from dcee.runs import run_episode
from dcee.scenarios import REGION_FLOOR_DEFAULT, load_scenario, unset_region_floor
from dcee.searcher import Searcher
from dcee.simulation import InjectedTruth, make_truth
from tests.helpers import random_theta, run_cli, spike_ess_share

PAPER1 = load_scenario("paper:1")  # source (37.5, 12.5, 1), wind from +x at 4 m/s: plume to -x
THETA = PAPER1.truth_theta()


# --- the meandering plume model ---


def test_meander_kernel_matches_reference_and_zero_meander_is_the_paper_plume():
    rng = np.random.default_rng(4)
    theta = random_theta(300, rng)
    pos = np.column_stack([rng.uniform(0, 50, 23), rng.uniform(0, 50, 23), np.full(23, 4.0)])
    for shape in (
        (0.0, 1.0, 0.0, 0.0),
        (0.15, 1.0, 0.0, 0.0),
        (0.6, 1.0, 0.0, 0.0),
        (0.0, 0.5, 0.0, 0.0),
        (0.15, 0.5, 0.0, 0.0),
        (0.15, 1.0, 0.05, 0.0),
        (0.0, 0.5, 0.3, 0.0),
        (0.15, 1.0, 0.05, 1.0),
        (0.0, 1.0, 0.0, 3.0),
    ):
        fast = isotropic_concentration(theta, pos, 0.1, *shape)
        ref = isotropic_concentration_reference(theta, pos, 0.1, *shape)
        np.testing.assert_allclose(fast, ref, rtol=1e-9, atol=0)
    np.testing.assert_array_equal(
        isotropic_concentration(theta, pos, meander=0.0), isotropic_concentration(theta, pos)
    )


def test_meander_widens_the_far_field_but_conserves_the_crosswind_integral():
    """Limiting cases by hand: upwind nothing changes; far downwind the crosswind profile is
    wider by √(1 + i² d u / 2ζ1), its peak lower by the same factor, and its integral across
    the plume (the mass flux) is unchanged."""
    d = 30.0
    ys = np.linspace(-40, 40, 4001)
    pts = np.column_stack([np.full_like(ys, THETA[0] - d), THETA[1] + ys, np.full_like(ys, 1.0)])
    plain = isotropic_concentration(THETA, pts)[0]
    wide = isotropic_concentration(THETA, pts, meander=0.2)[0]
    grow = math.sqrt(1 + 0.2**2 * d * THETA[4] / (2 * THETA[6]))
    assert np.trapezoid(wide, ys) == pytest.approx(np.trapezoid(plain, ys), rel=0.02)
    assert wide.max() == pytest.approx(plain.max() / grow, rel=0.02)
    sd = lambda c: math.sqrt(np.trapezoid(c * ys**2, ys) / np.trapezoid(c, ys))  # noqa: E731
    assert sd(wide) == pytest.approx(sd(plain) * grow, rel=0.03)
    upwind = np.array([[THETA[0] + 2.0, THETA[1] + 1.0, 4.0]])
    assert isotropic_concentration(THETA, upwind, meander=0.5)[0, 0] == pytest.approx(
        isotropic_concentration(THETA, upwind)[0, 0], rel=1e-12
    )


def test_history_kernel_with_meander_and_near_source_intermittency_matches_reference():
    rng = np.random.default_rng(0)
    theta = random_theta(400, rng)
    pos = np.column_stack([rng.uniform(0, 50, (40, 2)), np.full(40, 4.0)])
    z = np.where(rng.random(40) < 0.5, 0.0, rng.gamma(1.0, 5e-3, 40))
    mult = rng.integers(1, 4, 40).astype(float)
    sensor = Sensor(family="lognormal", pd=0.6, log_sd=1.3, near_length=5.4, outlier=0.01)
    for decay, backflow, radius in ((1.0, 0.0, 0.0), (0.5, 0.0, 0.0), (1.0, 0.05, 1.0)):
        plume = IsotropicPlume(meander=0.15, decay=decay, backflow=backflow, radius=radius)
        out = np.empty(400)
        history_log_likelihood(
            theta, np.ones(400, bool), pos, z, mult, 0.1, *plume.shape, sensor.params, out
        )
        ref = history_log_likelihood_reference(theta, pos, z, mult, sensor, plume)
        np.testing.assert_allclose(out, ref, rtol=1e-9)


# --- readings as a holding robot takes them ---


def test_hold_average_is_the_mean_of_the_samples_and_the_isotropic_truth_is_unaffected():
    scenario = PAPER1.with_overrides(**{"truth.model": "filament"})
    truth = make_truth(scenario, 3)
    p = np.array([30.0, 12.5, 4.0])
    t = 40.0
    samples = [truth.concentration(p, t - 0.1 * k) for k in range(49, -1, -1)]
    truth2 = make_truth(scenario, 3)  # a fresh copy: sensed() must not depend on history
    assert truth2.sensed(p, t, 5.0) == pytest.approx(np.mean(samples), rel=1e-12)
    lagged = truth2.sensed(p, t, 5.0, response_time=2.0)
    assert lagged != pytest.approx(np.mean(samples))  # the response changes the reading
    iso = make_truth(PAPER1, 0)
    assert iso.sensed(p, t, 5.0) == iso.concentration(p, t)


def test_turbulent_truth_defaults_to_a_four_second_hold_and_average():
    filament = PAPER1.with_overrides(**{"truth.model": "filament"})
    assert (filament.dwell, filament.average) == (4.0, 4.0)
    assert (PAPER1.dwell, PAPER1.average) == (1.0, 0.0)
    assert filament.make_agent().step_time == pytest.approx(5.0)
    fluct = filament.with_overrides(**{"estimator.likelihood": "fluctuation"})
    s = fluct.make_estimator_sensor()
    assert (s.family, s.pd, s.log_sd, s.near_length, s.outlier) == (
        "lognormal",
        0.93,
        1.3,
        0.5,
        0.01,
    )
    assert fluct.make_plume().meander == 0.15
    # a turbulent plume expected: the grid UAV may climb and descend 1 m (issue 29)
    assert fluct.climb == 1.0 and filament.climb == 0.0
    # readings of a turbulent plume count half (issue 29); the paper's model counts them fully
    assert fluct.reading_weight == 0.5 and filament.reading_weight == 1.0
    assert fluct.with_overrides(**{"estimator.reading_weight": 0.8}).reading_weight == 0.8
    # the paper's model with the default outlier component (0: exactly the paper's)
    assert PAPER1.make_estimator_sensor() == dataclasses.replace(PAPER1.make_sensor(), outlier=0.01)
    exact = PAPER1.with_overrides(**{"estimator.outlier": 0.0})
    assert exact.make_estimator_sensor() == exact.make_sensor()


def test_the_simulated_instrument_misses_readings_only_where_the_truth_is_calm():
    # The paper's Pd stands for turbulent intermittency and missed detections together: the
    # isotropic truth simulates no turbulence, so its instrument misses 1 − Pd; a turbulent
    # truth makes its own gaps, so by default its instrument misses none. The paper's
    # likelihood keeps its Pd either way; sensor.dropout sets the instrument's explicitly.
    filament = PAPER1.with_overrides(**{"truth.model": "filament"})
    assert PAPER1.make_sensor().pd == 0.7 and filament.make_sensor().pd == 1.0
    assert filament.make_estimator_sensor().pd == 0.7
    assert filament.resolved_settings()["dropout"] == 0.0
    assert PAPER1.resolved_settings()["dropout"] == pytest.approx(0.3)
    lossy = filament.with_overrides(**{"sensor.dropout": 0.25})
    assert lossy.make_sensor().pd == 0.75 and lossy.make_estimator_sensor().pd == 0.7
    rng = np.random.default_rng(0)
    c = np.full(40_000, 0.01)  # 20× the threshold: only noise (sd 0.5 C) falls below it
    noise_only = np.mean(filament.make_sensor().simulate(c, rng) < 5e-4)
    assert noise_only < 0.05
    missed = np.mean(lossy.make_sensor().simulate(c, rng) < 5e-4)
    assert missed == pytest.approx(0.25 + 0.75 * noise_only, abs=0.01)
    with pytest.raises(ValueError, match="dropout"):
        filament.with_overrides(**{"sensor.dropout": 1.0})


# --- outlier safety ---


def _xy_prior(scenario=PAPER1) -> SourcePrior:
    names = ("x", "y", "z", "q", "u", "phi", "zeta1", "zeta2")
    t = scenario.truth_theta()
    d = {n: Fixed(float(t[i])) for i, n in enumerate(names)}
    lo, hi = scenario.volume.low, scenario.volume.high
    d["x"], d["y"] = Uniform(lo[0], hi[0]), Uniform(lo[1], hi[1])
    return SourcePrior.from_dict(d)


def test_absurd_readings_are_refused_before_anything_changes():
    pf = ParticleFilter(_xy_prior(), Sensor.paper_exact(), n_particles=2000, seed=0)
    before = pf.theta.copy()
    for bad in (1e200, float("nan"), "12", None, np.array([1.0, 2.0])):
        with pytest.raises(DceeInputError, match="reading"):
            pf.update(np.array([30.0, 12.5, 4.0]), bad)
    assert pf.n_readings == 0 and np.array_equal(pf.theta, before)


FUZZ_SENSORS = {
    "paper": Sensor.paper_exact(),
    "paper+outlier": Sensor(outlier=0.01),
    "fluctuation": Sensor(family="lognormal", pd=0.63, log_sd=1.3, near_length=5.4, outlier=0.01),
}


def fuzz_stream(sensor: Sensor, stream: int, readings: int = 6) -> ParticleFilter:
    """A filter fed random positions and readings from 0 up to the physical maximum
    (log-uniform over eight decades), as ``studies/fuzz_filter.py`` does at scale."""
    rng = np.random.default_rng(stream)
    pf = ParticleFilter(_xy_prior(), sensor, n_particles=100, seed=stream, max_sweeps=2)
    for _ in range(readings):
        pos = np.array([*rng.uniform(0, 50, 2), 4.0])
        z = 0.0 if rng.random() < 0.3 else float(10 ** rng.uniform(-4, 4))
        pf.update(pos, z)
    return pf


def filter_is_alive(pf: ParticleFilter, need_diversity: bool) -> bool:
    """Finite weights, a finite history likelihood for every live particle and (where the model
    can explain every reading) more than one distinct particle."""
    w = pf.weights
    live = w > 0
    ok = bool(np.all(np.isfinite(w)) and np.all(np.isfinite(pf._hist_loglik[live])))
    return ok and (not need_diversity or len(np.unique(pf.theta[live], axis=0)) > 1)


@pytest.mark.parametrize("name", list(FUZZ_SENSORS))
def test_no_fuzzed_stream_kills_the_filter(name):
    """The paper's model (no outlier component) may legitimately collapse onto one point for a
    reading only one location can explain, but never to NaN or −inf; with the outlier component
    every filter also stays diverse. (1,000 streams per model: studies/fuzz_filter.py.)"""
    dead = [
        s
        for s in range(150)
        if not filter_is_alive(fuzz_stream(FUZZ_SENSORS[name], s), name != "paper")
    ]
    assert dead == []


@pytest.mark.parametrize("config", ["paper:1", "random:3"])
def test_one_huge_spike_does_not_decide_a_search_with_default_settings(config):
    """Issue 29: one reading of 10⁶ × the true concentration (at least 10⁶ × the threshold) at
    60 s of a dcee-cl search with the *default* settings (paper likelihood): the search still
    acquires the source. With the outlier component off (the paper's exact likelihood) the same
    spike captures the filter, so the check can fail."""
    scenario = load_scenario(config).with_overrides(
        **{"search.particles": 3000, "search.budget": 300.0}
    )
    threshold = scenario.sensor.threshold

    def spike(true: float) -> float:
        return min(1e6 * max(true, threshold), 5e3)

    ends = {}
    for outlier in (None, 0.0):
        sc = (
            scenario
            if outlier is None
            else scenario.with_overrides(**{"estimator.outlier": outlier})
        )
        clean = run_episode(sc, "dcee-cl", 0).summary["source_acquired"]
        truth = InjectedTruth(make_truth(sc, 0), {60.0: spike})
        spiked = run_episode(sc, "dcee-cl", 0, truth=truth).summary["source_acquired"]
        assert truth.fired and truth.fired[0][2] >= 500.0
        ends[outlier] = (clean, spiked)
    assert ends[None] == (True, True)
    assert ends[0.0] == (True, False)


SPIKE_SCENARIO = PAPER1.with_overrides(**{"search.particles": 2000})


def test_one_outlier_safety_default_for_every_way_of_building_a_filter():
    """Issue 43: one 10⁶ × reading through each entry point that builds a filter — the Python
    classes with their own defaults, a scenario's searcher (the simulation, ``dcee replay`` and
    the ROS node build theirs there; the node itself: tests/ros) and the gym environment —
    leaves most of the particles' weight (the outlier safety, ``OUTLIER_DEFAULT``). The paper's
    exact likelihood, asked for by name, gives all the weight to one particle: the check can
    fail."""
    import gymnasium

    import dcee.gym  # noqa: F401  (registers the environments)
    from dcee.models.sensor import OUTLIER_DEFAULT
    from dcee.runs import make_searcher

    assert Sensor().outlier == SPIKE_SCENARIO.outlier == OUTLIER_DEFAULT > 0
    prior = SPIKE_SCENARIO.make_prior()
    classes = ParticleFilter(prior, Sensor(), n_particles=2000, seed=1)
    rngs = np.random.default_rng(1), np.random.default_rng(2)
    scenario = make_searcher(SPIKE_SCENARIO, None, *rngs).filter
    env = gymnasium.make("dcee/SourceSearch-v0", scenario=SPIKE_SCENARIO, particles=2000)
    env.reset(seed=0)
    gym = env.unwrapped._sim().searcher.filter
    shares = {
        name: spike_ess_share(f, SPIKE_SCENARIO)
        for name, f in (("classes", classes), ("scenario", scenario), ("gym", gym))
    }
    assert all(share > 0.5 for share in shares.values()), shares
    exact = ParticleFilter(prior, Sensor.paper_exact(), n_particles=2000, seed=1)
    assert spike_ess_share(exact, SPIKE_SCENARIO) < 0.01


# --- a filter that keeps every mode ---


def _adaptive_path(config: str, seed: int, n: int = 60):
    scenario = load_scenario(config)
    sensor = scenario.make_sensor()
    rng = np.random.default_rng(seed)
    pf = ParticleFilter(_xy_prior(scenario), sensor, n_particles=3000, seed=seed + 50)
    searcher = Searcher(pf, get_planner("dcee", n_hypotheses=20), scenario.make_agent(), rng)
    truth = make_truth(scenario, seed)
    pos = np.array(scenario.agent.start, dtype=float)
    ps, zs = [], []
    for k in range(n):
        z = float(sensor.simulate(truth.concentration(pos, 0.0), rng))
        searcher.tell(pos, z, float(k))
        ps.append(pos.copy())
        zs.append(z)
        pos = searcher.ask()
    return scenario, np.array(ps), np.array(zs)


@pytest.mark.parametrize("config", ["paper:5", "paper:12"])
def test_filters_on_adaptive_paths_match_the_exact_grid_posterior(config):
    """Readings chosen by a planner (DCEE) on configurations where it searches far from the
    plume; 5,000-particle filters replayed on the same readings end within 0.3 exact sd of the
    exact grid posterior's mean (the study, studies/replay_study.py, runs 20,000 particles)."""
    scenario, ps, zs = _adaptive_path(config, 0)
    sensor = scenario.make_sensor()
    exact = location_grid_posterior(
        scenario.truth_theta(), (0, 0), (50, 50), 0.25, ps, zs, sensor, refine=5
    )
    for seed in range(3):
        pf = ParticleFilter(_xy_prior(scenario), sensor, n_particles=5000, seed=seed)
        for p, z in zip(ps, zs, strict=True):
            pf.update(p, z)
        np.testing.assert_array_less(np.abs(pf.mean() - exact.mean), 0.3 * exact.sd)


def test_global_moves_rebalance_separated_modes():
    """Two equally likely separated source locations (a symmetric pair of readings): after a
    collapse onto one of them, the random-walk-only move never brings the other back, while the
    mixture move restores both halves (exact answer: 50/50 by symmetry)."""
    names = ("x", "y", "z", "q", "u", "phi", "zeta1", "zeta2")
    vals = dict(zip(names, (0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 1.0, 8.0), strict=True))
    d = {n: Fixed(v) for n, v in vals.items()}
    d["x"], d["y"] = Uniform(0, 20), Uniform(0, 10)
    prior = SourcePrior.from_dict(d)
    sensor = Sensor.paper_exact(pd=1.0)
    shares = {}
    for share in (0.0, 0.3):
        pf = ParticleFilter(prior, sensor, n_particles=4000, seed=2, global_share=share)
        # every particle starts in the left half: an unlucky earlier history
        pf.theta[:, 0] = np.random.default_rng(0).uniform(0, 10, pf.n)
        for _ in range(6):
            for x in (5.0, 15.0):  # mirror-symmetric: sources at x = 5 and x = 15 equally likely
                pf.update(np.array([x, 5.0, 0.5]), 0.0)
            pf._resample()
            pf._rejuvenate()
        shares[share] = float(pf.weights @ (pf.theta[:, 0] > 10))
    assert shares[0.0] < 0.05
    assert 0.2 < shares[0.3] < 0.8


# --- calibration ---


def test_credible_region_covers_the_truth_at_its_level():
    """Truths drawn from the posterior itself are inside its 95% region 95% of the time."""
    rng = np.random.default_rng(3)
    pf = ParticleFilter(_xy_prior(), Sensor.paper_exact(), n_particles=4000, seed=0)
    pf.theta[:, 0] = 20 + 2.0 * rng.standard_normal(pf.n)
    pf.theta[:, 1] = 20 + rng.standard_t(4, pf.n)  # heavy tails: no Gaussian shortcut
    hits = [pf.in_credible_region(np.array([*pf.theta[i, :2], 1.0])) for i in range(4000)]
    assert np.mean(hits) == pytest.approx(0.95, abs=0.01)


def test_floored_region_is_the_convolved_posteriors_region():
    """Hand calculation: particles N(0, s² I) in 2-D convolved with N(0, σ² I) are N(0, (s² +
    σ²) I), whose 95 % region is the disc of radius √(χ²₂(0.95) (s² + σ²)) = 2.448 √(s² + σ²):
    0.774 m at s = 0.1, σ = 0.3. A truth at 0.70 m lies inside it and outside the particles'
    own region (0.245 m); one at 0.85 m lies outside both. Floor 0 is the unfloored region,
    and the same particles give the same answer twice (a seeded summary)."""
    rng = np.random.default_rng(5)
    pts = 0.1 * rng.standard_normal((20000, 2))
    w = np.full(20000, 1 / 20000)
    inside = np.array([0.70 / np.sqrt(2), 0.70 / np.sqrt(2)])
    outside = np.array([0.85, 0.0])
    assert in_credible_ellipsoid(pts, w, inside, 0.95, floor=0.3)
    assert not in_credible_ellipsoid(pts, w, inside, 0.95)
    assert not in_credible_ellipsoid(pts, w, outside, 0.95, floor=0.3)
    assert in_credible_ellipsoid(pts, w, [0.76, 0.0], floor=0.3)
    assert not in_credible_ellipsoid(pts, w, [0.79, 0.0], floor=0.3)
    assert in_credible_ellipsoid(pts, w, [0.24, 0.0], floor=0.0)
    assert not in_credible_ellipsoid(pts, w, [0.25, 0.0], floor=0.0)


def test_floored_region_covers_truths_from_the_convolved_posterior():
    """Truths drawn as a particle plus N(0, σ² I) error are inside the floored 95 % region
    95 % of the time, and the particles' own region misses many of them."""
    rng = np.random.default_rng(6)
    pf = ParticleFilter(_xy_prior(), Sensor.paper_exact(), n_particles=4000, seed=0)
    pf.theta[:, 0] = 20 + 0.2 * rng.standard_normal(pf.n)
    pf.theta[:, 1] = 20 + 0.1 * rng.standard_t(4, pf.n)
    idx = rng.integers(0, pf.n, 1500)
    truths = pf.theta[idx, :2] + 0.4 * rng.standard_normal((1500, 2))
    hits = [pf.in_credible_region(np.array([*t, 1.0]), 0.95, floor=0.4) for t in truths]
    plain = [pf.in_credible_region(np.array([*t, 1.0])) for t in truths[:300]]
    assert np.mean(hits) == pytest.approx(0.95, abs=0.015)
    assert np.mean(plain) < 0.6


def test_region_floor_changes_the_reported_region_and_no_decision():
    """The floor is read by the summary alone: the same search at floor 0 and at 1 m takes the
    same readings at the same places; only ``truth_in_95`` may differ, and it is the
    summary's entry for that floor of the grid."""
    sc = load_scenario("paper:1").with_overrides(
        **{"search.particles": 500, "search.budget": 40, "estimator.likelihood": "fluctuation"}
    )
    plain = run_episode(sc.with_overrides(**{"estimator.region_floor": 0.0}), "dcee-cl", 0)
    wide = run_episode(sc.with_overrides(**{"estimator.region_floor": 0.5}), "dcee-cl", 0)
    for a, b in zip(plain.records, wide.records, strict=True):
        assert (a["x"], a["y"], a["z"], a["reading"]) == (b["x"], b["y"], b["z"], b["reading"])
    assert plain.summary["truth_in_95_floor"] == wide.summary["truth_in_95_floor"]
    assert wide.summary["truth_in_95"] == wide.summary["truth_in_95_floor"]["0.50"]
    assert plain.summary["truth_in_95"] == plain.summary["truth_in_95_floor"]["0.00"]


def test_region_floor_defaults_follow_the_likelihood():
    paper = load_scenario("paper:1")
    fluct = paper.with_overrides(**{"estimator.likelihood": "fluctuation"})
    assert paper.region_floor == 0.0
    assert fluct.region_floor == REGION_FLOOR_DEFAULT["fluctuation"]
    assert fluct.with_overrides(**{"estimator.region_floor": 0.25}).region_floor == 0.25
    assert fluct.resolved_settings()["region_floor"] == fluct.region_floor
    assert unset_region_floor("fluctuation", "walls") == 0.0  # no floor chosen there
    with pytest.raises(DceeInputError, match="region_floor"):
        paper.with_overrides(**{"estimator.region_floor": -0.1})


# --- command line ---


def test_run_with_fluctuation_likelihood_records_the_resolved_settings(tmp_path, capsys):
    out = tmp_path / "r"
    argv = ["run", "--scenario", "paper:1", "--particles", "500", "--budget", "30", "--truth"]
    argv += ["filament", "--likelihood", "fluctuation", "--set", "estimator.log_sd=1.1"]
    code, printed, err = run_cli([*argv, "--out", str(out), "-q", "--no-figure"], capsys)
    assert code == 0, err
    import json

    summary = json.loads((out / "summary.json").read_text())
    assert summary["likelihood"] == "fluctuation" and summary["dwell"] == 4.0
    assert summary["average"] == 4.0 and summary["meander"] == 0.15
    assert isinstance(summary["truth_in_95"], bool)
    config = json.loads((out / "config.json").read_text())
    assert config["scenario"]["estimator"]["log_sd"] == 1.1
    # the backflow and disc members and the calm model run beside it: the summary and the
    # printed table name the chosen model
    members = (
        "fluctuation",
        "fluctuation[backflow=0,source_radius=1]",
        "fluctuation[backflow=0.05,source_radius=0]",
        "fluctuation[backflow=0.05,source_radius=1]",
        "paper",
    )
    assert summary["reading_models"] == "+".join(members)
    assert summary["model"] in members
    row = next(line for line in printed.splitlines() if "reading model" in line)
    assert summary["model"] in row and f"{summary['model_probability']:.3f}" in row


@pytest.mark.parametrize(
    "position,reading,time",
    [
        (["a", "b", "c"], 0.0, 1.0),
        ([1.0, 2.0], 0.0, 1.0),
        ([1.0, 2.0, 4.0], None, 1.0),
        ([1.0, 2.0, 4.0], 1j, 1.0),
        ([1.0, 2.0, 4.0], "abc", 1.0),
        ([1.0, 2.0, 4.0], np.array([1.0]), 1.0),
        ([1.0, 2.0, 4.0], np.zeros(0), 1.0),
        ([1.0, 2.0, 4.0], 0.0, "10"),
        ([1.0, 2.0, 4.0], 0.0, np.array([1.0])),
    ],
)
def test_searcher_tell_names_the_bad_field(position, reading, time):
    pf = ParticleFilter(_xy_prior(), Sensor.paper_exact(), n_particles=100, seed=0)
    searcher = Searcher(pf, get_planner("mpc"), PAPER1.make_agent(), np.random.default_rng(0))
    with pytest.raises(DceeInputError):
        searcher.tell(position, reading, time)
    assert pf.n_readings == 0
