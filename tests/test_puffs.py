"""The puff truth (Farrell et al. 2002) against its reference statistics: the Gaussian plume of a
continuous point source when the wind does not meander, a wider and intermittent plume when it
does, a spatially correlated wind, and reproducibility."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcee.scenarios import load_scenario
from dcee.simulation import make_truth


def _scenario(**model):
    base = load_scenario("paper:1").with_overrides(**{"truth.model": "puffs"})
    return base.with_overrides(**{f"truth.model.{k}": v for k, v in model.items()})


def _axes(scenario):
    theta = scenario.truth_theta()
    along = -np.array([math.cos(theta[5]), math.sin(theta[5])])
    cross = np.array([-along[1], along[0]])
    return theta, along, cross


def _samples(truth, scenario, x, ys, times):
    """(T, Y) concentrations at ``x`` m downwind, crosswind offsets ``ys``, source height."""
    theta, along, cross = _axes(scenario)
    pts = np.array([[*(theta[:2] + x * along + y * cross), theta[2]] for y in ys])
    return np.array([truth.field(pts, t) for t in times])


def test_shorthand_resolves_every_parameter_and_ignores_zeta():
    scenario = load_scenario("paper:1").with_overrides(**{"truth.model": "puffs"})
    spec = scenario.truth.model
    assert spec.kind == "puffs" and spec.puff_rate == 10.0 and spec.centre_diffusivity == 0.6
    assert scenario.truth.model_name == "puffs"
    a = make_truth(scenario, 3)
    b = make_truth(scenario.with_overrides(**{"truth.zeta1": 3.0, "truth.zeta2": 20.0}), 3)
    pts = np.array([[20.0, 20.0, 1.0], [30.0, 10.0, 1.0]])
    assert np.array_equal(a.field(pts, 42.0), b.field(pts, 42.0))


def test_deterministic_per_seed_and_looking_back_replays_the_same_field():
    scenario = _scenario()
    pts = np.random.default_rng(0).uniform([0, 0, 0], [50, 50, 3], (40, 3))
    a, b = make_truth(scenario, 7), make_truth(scenario, 7)
    late = a.field(pts, 95.0)
    early = a.field(pts, 12.3)  # back in time: from a checkpoint
    assert np.array_equal(early, b.field(pts, 12.3))
    assert np.array_equal(late, b.field(pts, 95.0))
    assert not np.array_equal(late, make_truth(scenario, 8).field(pts, 95.0))


def test_without_meander_the_mean_field_is_the_gaussian_plume_of_a_point_source():
    """Reference: a continuous point source q in a uniform wind u whose puffs spread with total
    diffusivity K = puff_diffusivity + centre_diffusivity has the mean field
    c = q / (2π u σ²) exp(−y² / 2σ²), σ² = r0² + 2 K x / u (slender plume, no ground)."""
    scenario = _scenario(meander_intensity=0.0)
    truth = make_truth(scenario, 0)
    spec, theta = scenario.truth.model, scenario.truth_theta()
    # the wind field stays the mean wind exactly
    grid_wind = truth.wind_at(np.array([[0.0, 0.0], [25.0, 25.0], [50.0, 10.0]]), 10.0)
    expected = -theta[4] * np.array([math.cos(theta[5]), math.sin(theta[5])])
    assert np.allclose(grid_wind, expected, atol=1e-12)
    q, u = theta[3], theta[4]
    ys = np.linspace(-6.0, 6.0, 13)
    x = 12.0
    mean = _samples(truth, scenario, x, ys, np.arange(0.0, 400.0, 0.25)).mean(0)
    var = spec.puff_radius**2 + 2.0 * (spec.puff_diffusivity + spec.centre_diffusivity) * x / u
    ref = q / (2 * math.pi * u * var) * np.exp(-(ys**2) / (2 * var))
    assert mean[6] == pytest.approx(ref[6], rel=0.12)
    sigma = math.sqrt((mean * ys**2).sum() / mean.sum())
    assert sigma == pytest.approx(math.sqrt(var), rel=0.1)


def test_meander_widens_the_mean_plume_and_makes_readings_intermittent():
    """Field plumes: the mean plume is wider than the instantaneous one, the share of time above
    the threshold falls across the plume, and peaks are many times the mean."""
    calm, windy = _scenario(meander_intensity=0.0), _scenario()
    ys = np.linspace(-16.0, 16.0, 17)
    times = np.arange(0.0, 400.0, 0.5)
    widths, shares = [], None
    for scenario in (calm, windy):
        c = _samples(make_truth(scenario, 1), scenario, 15.0, ys, times)
        m = c.mean(0)
        widths.append(math.sqrt((m * ys**2).sum() / m.sum()))
        shares = (c > scenario.sensor.threshold).mean(0)
        peak_to_mean = c[:, 8].max() / m[8]
    assert widths[1] > 1.2 * widths[0]
    assert shares[8] > shares[10] > shares[12]  # centre, 4 m, 8 m across
    assert shares[8] < 0.9  # intermittent even on the centreline
    assert peak_to_mean > 10.0


def test_wind_is_correlated_nearby_and_less_so_far_apart():
    scenario = _scenario()
    truth = make_truth(scenario, 2)
    points = np.array([[10.0, 25.0], [14.0, 25.0], [45.0, 25.0]])
    series = np.array([truth.wind_at(points, t)[:, 1] for t in np.arange(0.0, 600.0, 1.0)])
    r = np.corrcoef(series.T)
    assert r[0, 1] > 0.8
    assert r[0, 2] < r[0, 1] - 0.2
    # the noise has about the configured size: sd of the crosswind-ish component
    sd = scenario.truth.model.meander_intensity * scenario.truth_theta()[4]
    assert 0.3 * sd < series[:, 0].std() < 1.5 * sd


def test_release_is_poisson_with_the_configured_mean_rate():
    """Puffs released over 200 s: the count is Poisson(rate · T). A clockwork release would give
    exactly rate · T in every run; a Poisson one varies by about its square root across seeds."""
    scenario = _scenario()
    expected = scenario.truth.model.puff_rate * 200.0
    counts = []
    for seed in range(6):
        truth = make_truth(scenario, seed)
        counts.append(truth.released(200.0) - truth.released(0.0))
    counts = np.array(counts)
    assert np.all(np.abs(counts - expected) < 4.0 * math.sqrt(expected))
    assert counts.std() > 0.2 * math.sqrt(expected)
