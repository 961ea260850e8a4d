"""The floor reference of ``dcee perf`` (issue 17) computes what the planners' kernel computes:
checked against the NumPy reference of the predicted-posterior statistics."""

import numpy as np
import pytest

from dcee.estimation import ParticleFilter
from dcee.models import IsotropicPlume, Sensor
from dcee.models.plume import isotropic_concentration
from dcee.perf.floor import floor_decision
from dcee.planning.predicted_reference import predicted_posterior_stats_reference
from dcee.scenarios import load_scenario


@pytest.mark.parametrize(
    "sensor", [Sensor.paper_exact(), Sensor(family="lognormal", pd=0.6, outlier=0.01)]
)
def test_floor_decision_matches_numpy_reference(sensor):
    scenario = load_scenario("paper:1")
    pf = ParticleFilter(scenario.make_prior(), sensor, n_particles=3000, seed=4)
    rng = np.random.default_rng(0)
    theta = scenario.truth_theta()[None]
    for x in (10.0, 18.0, 26.0):
        p = np.array([x, 12.0, 4.0])
        pf.update(p, float(sensor.simulate(isotropic_concentration(theta, p[None])[0, 0], rng)))
    positions = np.array([[26.0, 12.0, 4.0], [28.0, 12.0, 4.0], [26.0, 14.0, 4.0]])
    readings = np.where(rng.random((3, 5)) < 0.4, 0.0, rng.lognormal(-6, 1.5, (3, 5)))
    out = floor_decision(pf.theta, pf.weights, positions, readings, sensor, IsotropicPlume())
    plume = IsotropicPlume()
    conc = isotropic_concentration(pf.theta, positions).T  # (M, N)
    dist = np.linalg.norm(pf.theta[None, :, :3] - positions[:, None, :], axis=2)
    dist = np.maximum(dist, plume.min_distance)
    task_pos = np.repeat(np.arange(3), 5)[:, None]
    ref = predicted_posterior_stats_reference(
        conc, pf.theta[:, :3], pf.weights, task_pos, readings.reshape(-1, 1), sensor, dist
    )
    flat = out.reshape(-1, 6)
    np.testing.assert_allclose(flat[:, 0], ref[0], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(flat[:, 1:4], ref[1], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(flat[:, 4], ref[2], rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(flat[:, 5], ref[3], rtol=1e-7, atol=1e-9)
