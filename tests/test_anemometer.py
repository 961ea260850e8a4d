"""The anemometer: its density, its sufficient statistics, the filter's posterior on the wind
against the exact one, the simulated instrument's statistics, and bad readings."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, stats

from dcee.errors import DceeInputError
from dcee.estimation.particle_filter import ParticleFilter
from dcee.models.anemometer import Anemometer, WindEvidence, wind_from_vector
from dcee.runs import make_searcher, run_episode, streams
from dcee.scenarios import load_scenario

MODEL = Anemometer(speed_sd=0.5, direction_sd=math.radians(10.0))


def _theta(u: float, phi: float) -> np.ndarray:
    theta = np.zeros((1, 8))
    theta[0, 4], theta[0, 5] = u, phi
    return theta


def test_the_density_is_normalised_and_matches_scipy():
    theta = _theta(4.0, 0.3)
    # Normal × von Mises, against scipy's densities
    speed, direction = 3.6, 0.45
    expected = stats.norm.logpdf(speed, 4.0, 0.5) + stats.vonmises.logpdf(
        direction, MODEL.kappa, loc=0.3
    )
    assert MODEL.log_likelihood(theta, speed, direction)[0] == pytest.approx(expected, rel=1e-12)
    total, _ = integrate.dblquad(
        lambda d, s: math.exp(MODEL.log_likelihood(theta, s, d)[0]),
        4.0 - 8 * 0.5,
        4.0 + 8 * 0.5,
        0.3 - math.pi,
        0.3 + math.pi,
    )
    assert total == pytest.approx(1.0, abs=1e-6)


def test_sufficient_statistics_sum_the_single_readings():
    rng = np.random.default_rng(0)
    readings = [MODEL.simulate(4.0, 1.0, rng) for _ in range(25)]
    theta = np.column_stack(
        [np.zeros((50, 4)), rng.uniform(2, 6, 50), rng.uniform(0, 2, 50), np.zeros((50, 2))]
    )
    total = WindEvidence()
    for s, d in readings:
        total = total + WindEvidence.of(s, d)
    by_hand = sum(MODEL.log_likelihood(theta, s, d) for s, d in readings)
    np.testing.assert_allclose(total.log_likelihood(theta, MODEL), by_hand, rtol=1e-10)


def test_the_simulated_instrument_has_the_model_statistics():
    rng = np.random.default_rng(1)
    draws = np.array([MODEL.simulate(4.0, 3.0, rng) for _ in range(20_000)])
    assert draws[:, 0].mean() == pytest.approx(4.0, abs=0.02)
    assert draws[:, 0].std() == pytest.approx(0.5, rel=0.03)
    # circular mean and spread of the direction about 3 rad (near the ±π seam)
    mean_dir = math.atan2(np.sin(draws[:, 1]).mean(), np.cos(draws[:, 1]).mean())
    assert mean_dir == pytest.approx(3.0, abs=0.01)
    assert stats.circstd(draws[:, 1]) == pytest.approx(math.radians(10.0), rel=0.05)


def test_the_filter_posterior_on_the_wind_is_the_exact_one():
    """Only wind readings: the prior on u is Normal(4, √2²) and the speed readings Normal,
    so the posterior of u is Normal with the conjugate mean and variance; the particle
    filter's weighted moments agree within Monte-Carlo error (20,000 particles), also after
    its resample-move steps (whose target includes the wind readings)."""
    sc = load_scenario("paper:1").with_overrides(
        **{"unknown": "full", "anemometer.enabled": True, "search.particles": 20_000}
    )
    searcher = make_searcher(sc, None, *streams(3)[1:3])
    pf = searcher.filter
    assert isinstance(pf, ParticleFilter)
    rng = np.random.default_rng(7)
    speeds = []
    for _ in range(6):
        s, d = MODEL.simulate(5.0, 0.0, rng)
        speeds.append(s)
        searcher.tell_wind(s, d)
    assert pf.n_resamples > 0  # the resample-move step ran with the wind in its target
    prior_var, like_var = 2.0, 0.25
    post_var = 1.0 / (1.0 / prior_var + len(speeds) / like_var)
    post_mean = post_var * (4.0 / prior_var + sum(speeds) / like_var)
    u = pf.theta[:, 4]
    mean = float(pf.weights @ u)
    var = float(pf.weights @ (u - mean) ** 2)
    assert mean == pytest.approx(post_mean, abs=0.03)
    assert var == pytest.approx(post_var, rel=0.1)


def test_bad_wind_readings_are_refused_in_one_line():
    sc = load_scenario("paper:1").with_overrides(**{"unknown": "full", "anemometer.enabled": True})
    searcher = make_searcher(sc, None, *streams(0)[1:3])
    for speed, direction in ((math.nan, 0.0), (-1.0, 0.0), (3.0, math.inf), ("x", 0.0)):
        with pytest.raises(DceeInputError, match="wind"):
            searcher.tell_wind(speed, direction)
    without = make_searcher(load_scenario("paper:1"), None, *streams(0)[1:3])
    with pytest.raises(DceeInputError, match="anemometer"):
        without.tell_wind(3.0, 0.0)


def test_wind_vectors_become_the_direction_the_wind_comes_from():
    # air moving towards -x (west) comes from +x: phi = 0
    assert wind_from_vector(-4.0, 0.0) == pytest.approx((4.0, 0.0))
    # air moving towards +y (north) comes from -y: phi = -90 deg
    assert wind_from_vector(0.0, 2.0) == pytest.approx((2.0, -math.pi / 2))


def test_a_search_with_an_anemometer_counts_its_readings_and_is_off_by_default():
    base = load_scenario("paper:4").with_overrides(
        **{"search.particles": 500, "search.budget": 30.0, "unknown": "full"}
    )
    assert base.make_anemometer() is None
    on = base.with_overrides(**{"anemometer.enabled": True, "anemometer.period": 0.5})
    res = run_episode(on, "mpc", seed=0)
    assert res.summary["wind_readings"] == pytest.approx(res.records[-1]["time"] / 0.5, abs=1)
