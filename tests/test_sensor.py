import math

import numpy as np
import pytest
from scipy import integrate

from dcee import DceeInputError, Sensor
from dcee.models.sensor_kernels import log_likelihood


@pytest.mark.parametrize("false_alarm", [0.0, 0.05])
@pytest.mark.parametrize("conc", [0.0, 2e-4, 5e-4, 1e-3, 0.05])
def test_likelihood_is_a_proper_distribution_over_readings(conc, false_alarm):
    s = Sensor.paper_exact(false_alarm=false_alarm)
    p_nd = float(s.likelihood(0.0, conc))
    sigma = s.sigma_frac * conc + s.sigma_min
    upper = max(conc + 40 * sigma, s.threshold + 60 * s.false_alarm_scale)
    points = [conc] if conc > s.threshold else None
    mass, _ = integrate.quad(
        lambda z: float(s.likelihood(z, conc)), s.threshold, upper, points=points, limit=200
    )
    assert p_nd + mass == pytest.approx(1.0, abs=1e-7)


def test_non_detection_probability_limits():
    s = Sensor.paper_exact(pd=0.7)
    # Far from the plume every reading is a non-detection; deep inside only misses are.
    assert float(s.likelihood(0.0, 0.0)) == pytest.approx(1.0, abs=1e-6)
    # Deep inside: misses (0.3) plus noise dipping below the threshold, Φ((thr − C)/σ) ≈ Φ(−2).
    below = 0.5 * math.erfc(-((5e-4 - 1.0) / (0.5 * 1.0 + 1e-4)) / math.sqrt(2))
    assert float(s.likelihood(0.0, 1.0)) == pytest.approx(0.3 + 0.7 * below, rel=1e-12)
    # A sub-threshold raw value counts as a non-detection.
    assert float(s.likelihood(3e-4, 0.01)) == float(s.likelihood(0.0, 0.01))


@pytest.mark.parametrize("false_alarm", [0.0, 0.1])
def test_simulated_readings_follow_the_likelihood(false_alarm):
    s = Sensor.paper_exact(false_alarm=false_alarm)
    rng = np.random.default_rng(11)
    conc = 8e-4
    z = s.simulate(np.full(200_000, conc), rng)
    nd = z < s.threshold
    p_nd = float(s.likelihood(0.0, conc))
    assert nd.mean() == pytest.approx(p_nd, abs=4 * math.sqrt(p_nd * (1 - p_nd) / len(z)))
    # Probability of each bin of detected readings against the integrated density.
    edges = np.array([5e-4, 7e-4, 9e-4, 1.2e-3, 2e-3, 5e-3])
    counts, _ = np.histogram(z[~nd], bins=edges)
    for k in range(len(edges) - 1):
        p, _ = integrate.quad(lambda v: float(s.likelihood(v, conc)), edges[k], edges[k + 1])
        sd = math.sqrt(p * (1 - p) / len(z))
        assert counts[k] / len(z) == pytest.approx(p, abs=5 * sd + 1e-6)


def test_compiled_likelihood_matches_reference():
    rng = np.random.default_rng(5)
    for s in (Sensor.paper_exact(), Sensor.paper_exact(false_alarm=0.02, pd=1.0)):
        c = np.concatenate([[0.0, 1e-9, 5e-4], rng.gamma(0.5, 2e-3, 300), [0.5, 3.0]])
        z = np.concatenate([[0.0, 4e-4], rng.gamma(0.7, 2e-3, 60), [1.0]])
        for zi in z:
            fast = np.array([log_likelihood(zi, ci, math.inf, s.params) for ci in c])
            ref = s.log_likelihood(zi, c)
            np.testing.assert_allclose(fast, ref, rtol=1e-9, atol=1e-12)


def test_simulation_is_reproducible_and_common_noise_is_shared():
    s = Sensor.paper_exact()
    noise = s.draw_noise(np.random.default_rng(1), 5)
    a = s.simulate_from(np.full(5, 2e-3), noise)
    b = s.simulate(np.full(5, 2e-3), np.random.default_rng(1))
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    "field,value", [("pd", 0.0), ("pd", 1.5), ("threshold", -1.0), ("sigma_min", float("nan"))]
)
def test_invalid_sensor_parameters_name_the_field(field, value):
    with pytest.raises(DceeInputError, match=f"sensor.{field}"):
        Sensor(**{field: value})


FLUCTUATION = Sensor.paper_exact(family="lognormal", pd=0.5, log_sd=1.0)
ROBUST = Sensor(family="lognormal", pd=0.5, log_sd=1.0, outlier=0.01)
ROBUST_PAPER = Sensor(outlier=0.02, false_alarm=0.03)
NEAR = Sensor(family="lognormal", pd=0.6, log_sd=1.2, outlier=0.01, near_length=5.0)
NEAR_PAPER = Sensor.paper_exact(near_length=3.0, false_alarm=0.01)
# the spread grows near the source: s(r) = 1.0 + 2.0 exp(−r / 3)
SPREAD = Sensor(
    family="lognormal", pd=0.6, log_sd=1.0, log_sd_near=2.0, log_sd_length=3.0, outlier=0.01
)
# detection-only readings: a detection's magnitude carries no weight
DETECTION_ONLY = Sensor(
    family="lognormal", pd=0.6, log_sd=1.2, outlier=0.01, near_length=5.0, magnitude=False
)
# mean-conserving intermittency: a detection's mean is C / Pd(r)
CONSERVING = Sensor(
    family="lognormal", pd=0.6, log_sd=1.2, outlier=0.01, near_length=5.0, conserve_mean=True
)
FAMILIES = [FLUCTUATION, ROBUST, ROBUST_PAPER, NEAR, NEAR_PAPER, SPREAD, CONSERVING]
FAMILY_IDS = ["ln", "ln+out", "gauss+out", "ln+near", "gauss+near", "ln+spread", "ln+conserve"]


@pytest.mark.parametrize(
    "s",
    [FLUCTUATION, ROBUST, ROBUST_PAPER, SPREAD, DETECTION_ONLY, CONSERVING],
    ids=["ln", "ln+out", "gauss+out", "spread", "detection", "conserve"],
)
@pytest.mark.parametrize("conc", [0.0, 2e-4, 5e-4, 3e-3, 0.5])
@pytest.mark.parametrize("r", [0.5, 40.0])
def test_every_family_is_a_proper_distribution_over_readings(s, conc, r):
    """P(non-detection) + ∫ p(z) dz over [threshold, max_reading] = 1, integrated in ln z."""
    p_nd = float(s.likelihood(0.0, conc, r))
    lo, hi = math.log(s.threshold), math.log(s.max_reading)
    points = [math.log(conc)] if conc > s.threshold else None
    mass, _ = integrate.quad(
        lambda u: float(s.likelihood(math.exp(u), conc, r)) * math.exp(u),
        lo,
        hi,
        points=points,
        limit=400,
        epsabs=1e-10,
    )
    assert p_nd + mass == pytest.approx(1.0, abs=2e-6)


def test_lognormal_reading_keeps_the_mean_and_intermittency():
    """Limiting case: a threshold far below C leaves E[z | detected] = C and P(z > 0) = Pd."""
    s = Sensor.paper_exact(family="lognormal", pd=0.4, log_sd=0.8, threshold=1e-9)
    z = s.simulate(np.full(400_000, 2e-2), np.random.default_rng(4))
    assert (z > 0).mean() == pytest.approx(0.4, abs=0.004)
    assert z[z > 0].mean() == pytest.approx(2e-2, rel=0.01)
    assert np.log(z[z > 0]).std() == pytest.approx(0.8, rel=0.01)


def test_mean_conserving_intermittency_keeps_the_time_mean_near_the_source():
    """Limiting case (threshold far below C): with ``conserve_mean`` the share of detections is
    Pd(r) and a detection's mean C / Pd(r), so the mean reading, zeros included, is C at every
    distance; without it the mean reading is Pd(r) · C."""
    kw = dict(family="lognormal", pd=0.9, log_sd=1.0, near_length=2.5, threshold=1e-12, outlier=0.0)
    on, off = Sensor(**kw, conserve_mean=True), Sensor(**kw)
    rng = np.random.default_rng(5)
    conc = np.full(400_000, 3e-2)
    for r in (0.3, 1.0, 6.0):
        pd = 0.9 * (1 - math.exp(-r / 2.5))
        noise = on.draw_noise(rng, conc.shape)
        z_on, z_off = on.simulate_from(conc, noise, r), off.simulate_from(conc, noise, r)
        assert (z_on > 0).mean() == pytest.approx(pd, abs=0.004)
        assert z_on.mean() == pytest.approx(3e-2, rel=0.03)
        assert z_off.mean() == pytest.approx(pd * 3e-2, rel=0.03)
        assert z_on[z_on > 0].mean() == pytest.approx(3e-2 / pd, rel=0.03)


@pytest.mark.parametrize(
    "s",
    [FLUCTUATION, ROBUST, ROBUST_PAPER, SPREAD, CONSERVING],
    ids=["ln", "ln+out", "gauss+out", "spread", "conserve"],
)
def test_simulated_readings_follow_every_family(s):
    rng = np.random.default_rng(12)
    conc, r = 2e-3, 4.0
    z = s.simulate_from(np.full(300_000, conc), s.draw_noise(rng, 300_000), r)
    nd = z < s.threshold
    p_nd = float(s.likelihood(0.0, conc, r))
    assert nd.mean() == pytest.approx(p_nd, abs=4 * math.sqrt(p_nd * (1 - p_nd) / len(z)))
    edges = np.array([5e-4, 1e-3, 2e-3, 4e-3, 1e-2, 1.0, 1e4])
    counts, _ = np.histogram(z[~nd], bins=edges)
    for k in range(len(edges) - 1):
        lo, hi = math.log(edges[k]), math.log(edges[k + 1])
        p, _ = integrate.quad(
            lambda u: float(s.likelihood(math.exp(u), conc, r)) * math.exp(u), lo, hi
        )
        sd = math.sqrt(p * (1 - p) / len(z))
        assert counts[k] / len(z) == pytest.approx(p, abs=5 * sd + 1e-6)


@pytest.mark.parametrize(
    "s",
    [FLUCTUATION, ROBUST, ROBUST_PAPER, SPREAD, DETECTION_ONLY],
    ids=["ln", "ln+out", "gauss+out", "spread", "detection"],
)
def test_compiled_likelihood_matches_reference_for_every_family(s):
    rng = np.random.default_rng(6)
    c = np.concatenate([[0.0, 1e-12, 1e-7, 5e-4], rng.gamma(0.5, 2e-3, 200), [0.5, 30.0]])
    z = np.concatenate([[0.0, 4e-4, 5e-4], rng.gamma(0.7, 2e-3, 40), [1.0, 500.0, 1e4]])
    for zi in z:
        r = rng.uniform(0.1, 30.0, len(c))
        fast = np.array([log_likelihood(zi, ci, ri, s.params) for ci, ri in zip(c, r, strict=True)])
        np.testing.assert_allclose(fast, s.log_likelihood(zi, c, r), rtol=1e-9, atol=1e-12)


def test_spread_near_the_source_by_hand():
    """s(r) = s∞ + log_sd_near · exp(−r / log_sd_length): its limits, one value by hand, the
    compiled kernel's, and the mean kept at every distance (E[z | true detection] = C with a
    threshold far below C)."""
    from dcee.models.sensor_kernels import log_sd_at

    assert float(SPREAD.log_sd_at(0.0)) == pytest.approx(3.0)
    assert float(SPREAD.log_sd_at(1e6)) == pytest.approx(1.0)
    assert float(SPREAD.log_sd_at(3.0)) == pytest.approx(1.0 + 2.0 / math.e)
    for r in (0.0, 0.7, 3.0, 30.0):
        assert log_sd_at(r, SPREAD.params) == pytest.approx(float(SPREAD.log_sd_at(r)), rel=1e-15)
    assert float(FLUCTUATION.log_sd_at(0.0)) == 1.0  # log_sd_length 0: constant
    low = Sensor.paper_exact(
        family="lognormal", pd=1.0, log_sd=0.5, log_sd_near=0.5, log_sd_length=2.0, threshold=1e-12
    )
    noise = low.draw_noise(np.random.default_rng(5), 400_000)
    for r, s_r in ((0.0, 1.0), (50.0, 0.5)):
        z = low.simulate_from(np.full(400_000, 2e-2), noise, r)
        assert np.log(z).std() == pytest.approx(s_r, rel=0.01)
        assert z.mean() == pytest.approx(2e-2, rel=0.02)


def test_outlier_component_bounds_the_influence_of_one_reading():
    """With outliers every particle keeps at least outlier · g(z): the likelihood ratio of a
    spike between any two concentrations is bounded; without them it is astronomically large."""
    c = np.geomspace(1e-6, 1e3, 200)
    for s, bound in ((ROBUST, 1e4), (Sensor(outlier=0.01), 1e4)):
        ll = s.log_likelihood(500.0, c)
        assert ll.max() - ll.min() < math.log(bound)
    ll = FLUCTUATION.log_likelihood(500.0, c)
    assert ll.max() - ll.min() > 50


@pytest.mark.parametrize("bad", [1e5, 1e200, float("inf"), float("nan"), "abc", None, 1j, True])
def test_readings_outside_the_physical_range_are_refused(bad):
    with pytest.raises(DceeInputError, match="reading"):
        Sensor.paper_exact().check_reading(bad)
    assert Sensor.paper_exact().check_reading(np.float32(2e-3)) == pytest.approx(2e-3)


@pytest.mark.parametrize(
    "s",
    [Sensor.paper_exact(), Sensor.paper_exact(false_alarm=0.05), *FAMILIES],
    ids=["paper", "gauss+fa", *FAMILY_IDS],
)
@pytest.mark.parametrize("conc", [1e-5, 2e-3])
def test_detection_draws_follow_the_likelihood_given_a_detection(s, conc):
    """Readings drawn conditioned on a detection (the planners' stratified expectation) have the
    likelihood's density above the threshold divided by P(detection), bin by bin; C = 1e-5 puts
    the threshold 4.7 σ into the Gaussian tail."""
    n, r = 200_000, 2.0
    z = s.simulate_detection(np.full(n, conc), np.random.default_rng(3).random((n, 2)), r)
    p_detect = 1.0 - float(s.likelihood(0.0, conc, r))
    if p_detect < 1e-12:  # no way to detect: the draw says "no detection"
        assert np.all(z == 0.0)
        return
    assert np.all(z >= s.threshold)
    edges = np.array([5e-4, 5.5e-4, 7e-4, 1e-3, 2e-3, 4e-3, 1e-2, 1.0, 1e4])
    counts, _ = np.histogram(z, bins=edges)
    for k in range(len(edges) - 1):
        lo, hi = math.log(edges[k]), math.log(edges[k + 1])
        mass, _ = integrate.quad(
            lambda u: float(s.likelihood(math.exp(u), conc, r)) * math.exp(u), lo, hi, limit=200
        )
        p = mass / p_detect
        assert counts[k] / n == pytest.approx(p, abs=5 * math.sqrt(p * (1 - p) / n) + 1e-5)


def test_detection_only_readings_by_hand():
    """Detection only: p(z | C, r) = Pd(r) · P(ln z ≥ ln thr) · g(z) for a detection, g the
    log-uniform density on [threshold, max_reading]; the non-detection is the magnitude model's.
    So two detections of different sizes weigh every hypothesis alike."""
    s = Sensor.paper_exact(family="lognormal", pd=0.8, log_sd=1.5, near_length=4.0, magnitude=False)
    full = Sensor.paper_exact(family="lognormal", pd=0.8, log_sd=1.5, near_length=4.0)
    c, r, z = 2e-3, 3.0, 7e-3
    pd = 0.8 * (1.0 - math.exp(-3.0 / 4.0))
    x = (math.log(c) - 0.5 * 1.5**2 - math.log(5e-4)) / 1.5
    p_above = 0.5 * math.erfc(-x / math.sqrt(2.0))
    g = 1.0 / (z * math.log(1e4 / 5e-4))
    assert float(s.likelihood(z, c, r)) == pytest.approx(pd * p_above * g, rel=1e-12)
    assert float(s.likelihood(0.0, c, r)) == pytest.approx(float(full.likelihood(0.0, c, r)))
    conc = np.array([1e-4, 1e-3, 5e-2])  # three hypotheses
    ratio_small = s.log_likelihood(6e-4, conc, r) - s.log_likelihood(6e-4, conc[0], r)
    ratio_large = s.log_likelihood(3.0, conc, r) - s.log_likelihood(3.0, conc[0], r)
    np.testing.assert_allclose(ratio_small, ratio_large, atol=1e-12)
    with_size = full.log_likelihood(3.0, conc, r) - full.log_likelihood(3.0, conc[0], r)
    assert not np.allclose(with_size, ratio_large)  # the magnitude model does tell them apart
