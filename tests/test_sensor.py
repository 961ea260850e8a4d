import math

import numpy as np
import pytest
from scipy import integrate

from dcee import DceeInputError, Sensor, kernels


@pytest.mark.parametrize("false_alarm", [0.0, 0.05])
@pytest.mark.parametrize("conc", [0.0, 2e-4, 5e-4, 1e-3, 0.05])
def test_likelihood_is_a_proper_distribution_over_readings(conc, false_alarm):
    s = Sensor(false_alarm=false_alarm)
    p_nd = float(s.likelihood(0.0, conc))
    sigma = s.sigma_frac * conc + s.sigma_min
    upper = max(conc + 40 * sigma, s.threshold + 60 * s.false_alarm_scale)
    points = [conc] if conc > s.threshold else None
    mass, _ = integrate.quad(
        lambda z: float(s.likelihood(z, conc)), s.threshold, upper, points=points, limit=200
    )
    assert p_nd + mass == pytest.approx(1.0, abs=1e-7)


def test_non_detection_probability_limits():
    s = Sensor(pd=0.7)
    # Far from the plume every reading is a non-detection; deep inside only misses are.
    assert float(s.likelihood(0.0, 0.0)) == pytest.approx(1.0, abs=1e-6)
    # Deep inside: misses (0.3) plus noise dipping below the threshold, Φ((thr − C)/σ) ≈ Φ(−2).
    below = 0.5 * math.erfc(-((5e-4 - 1.0) / (0.5 * 1.0 + 1e-4)) / math.sqrt(2))
    assert float(s.likelihood(0.0, 1.0)) == pytest.approx(0.3 + 0.7 * below, rel=1e-12)
    # A sub-threshold raw value counts as a non-detection.
    assert float(s.likelihood(3e-4, 0.01)) == float(s.likelihood(0.0, 0.01))


@pytest.mark.parametrize("false_alarm", [0.0, 0.1])
def test_simulated_readings_follow_the_likelihood(false_alarm):
    s = Sensor(false_alarm=false_alarm)
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
    for s in (Sensor(), Sensor(false_alarm=0.02, pd=1.0)):
        c = np.concatenate([[0.0, 1e-9, 5e-4], rng.gamma(0.5, 2e-3, 300), [0.5, 3.0]])
        z = np.concatenate([[0.0, 4e-4], rng.gamma(0.7, 2e-3, 60), [1.0]])
        for zi in z:
            fast = np.array([kernels.log_likelihood(zi, ci, s.params) for ci in c])
            ref = s.log_likelihood(zi, c)
            np.testing.assert_allclose(fast, ref, rtol=1e-9, atol=1e-12)


def test_simulation_is_reproducible_and_common_noise_is_shared():
    s = Sensor()
    noise = Sensor.draw_noise(np.random.default_rng(1), 5)
    a = s.simulate_from(np.full(5, 2e-3), noise)
    b = s.simulate(np.full(5, 2e-3), np.random.default_rng(1))
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    "field,value", [("pd", 0.0), ("pd", 1.5), ("threshold", -1.0), ("sigma_min", float("nan"))]
)
def test_invalid_sensor_parameters_name_the_field(field, value):
    with pytest.raises(DceeInputError, match=f"sensor.{field}"):
        Sensor(**{field: value})
