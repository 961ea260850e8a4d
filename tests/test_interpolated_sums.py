"""The planners' ``precision="interpolated"`` (the default for one-reading predictions): the
one-stage predicted-posterior statistics summed over nodes of the predicted concentration,
against the NumPy reference, and the cases that must be computed exactly instead."""

import numpy as np
import pytest

from dcee.models import Sensor
from dcee.planning import get as get_planner
from dcee.planning.predicted_reference import predicted_posterior_stats_reference
from tests.helpers import compiled_predicted_stats, random_theta, run_with_numba_threads


def _late_case(n=4000, seed=11, spread=0.5):
    """A belief late in a search: the particles' concentrations at each position within a
    factor of a few of one another (a few hundred nodes), a seventh of them dead."""
    rng = np.random.default_rng(seed)
    source = np.column_stack([rng.uniform(30, 32, n), rng.uniform(10, 12, n), rng.uniform(0, 2, n)])
    weights = rng.random(n)
    weights[::7] = 0.0
    weights /= weights.sum()
    conc = np.ascontiguousarray(
        np.exp(rng.normal(-6.0, spread, size=(3, n)) + np.array([[0.0], [1.0], [-1.0]]))
    )
    return conc, source, weights


def _tasks(conc, rng, hypotheses=20):
    """Per position: one non-detection and readings drawn around the particles' predictions,
    with one reading no particle explains (the outlier component's, or a task redone)."""
    task_pos = np.repeat(np.arange(conc.shape[0])[:, None], hypotheses, axis=0)
    picked = conc[task_pos[:, 0], rng.integers(0, conc.shape[1], len(task_pos))]
    task_z = (picked * rng.lognormal(0.0, 0.4, len(task_pos)))[:, None]
    task_z[::hypotheses] = 0.0
    task_z[4, 0] = 50.0
    return task_pos, task_z


@pytest.mark.parametrize(
    "sensor", [Sensor.paper_exact(), Sensor(outlier=0.01)], ids=["paper", "gauss+out"]
)
def test_interpolated_stats_match_the_reference(sensor):
    conc, source, weights = _late_case()
    task_pos, task_z = _tasks(conc, np.random.default_rng(4))
    args = (conc, source, weights, task_pos, task_z, sensor)
    interpolated = compiled_predicted_stats(*args, precision="interpolated")
    double = compiled_predicted_stats(*args, precision="double")
    ref = predicted_posterior_stats_reference(*args)
    log_ev, mean, trace, kl = interpolated
    # measured about 1e-8 at the default node spacing (its error falls as step^4); 1e-6 here
    assert np.all(np.abs(log_ev - ref[0]) <= 1e-6 * np.maximum(1.0, np.abs(ref[0])))
    sd = np.sqrt(ref[2])
    assert np.all(np.linalg.norm(mean - ref[1], axis=1) <= 1e-6 * sd + 1e-9)
    np.testing.assert_allclose(trace, ref[2], rtol=1e-6)
    np.testing.assert_allclose(kl, ref[3], rtol=0, atol=1e-6)
    # it is not the exact path under another name
    assert not np.array_equal(log_ev, double[0])


def test_interpolated_sums_converge_as_the_fourth_power_of_the_node_spacing(monkeypatch):
    """Cubic interpolation: halving the spacing divides the error by about 16 (a limiting case
    that a wrong stencil or node placement fails)."""
    import dcee.planning.interpolated_kernels as kernels

    conc, source, weights = _late_case(spread=0.3)
    task_pos, task_z = _tasks(conc, np.random.default_rng(6))
    args = (conc, source, weights, task_pos, task_z, Sensor(outlier=0.01))
    ref = predicted_posterior_stats_reference(*args)
    errors = []
    for step in (0.04, 0.02):
        monkeypatch.setattr(kernels, "INTERPOLATION_STEP", step)
        log_ev = compiled_predicted_stats(*args, precision="interpolated")[0]
        errors.append(np.max(np.abs(log_ev - ref[0])))
    assert 8.0 < errors[0] / errors[1] < 32.0


def test_interpolation_is_exact_where_it_does_not_apply():
    """Other sensor families, several stages, a position with few readings (the spread onto
    the nodes would not pay) and a position whose particles' concentrations span too many nodes
    (an early, wide belief) are computed exactly: bit for bit."""
    conc, source, weights = _late_case()
    rng = np.random.default_rng(3)
    wide = conc.copy()
    wide[1] = rng.lognormal(-7.0, 3.0, conc.shape[1])  # e^-13 .. e^-1: thousands of nodes
    cases = (
        (conc, np.repeat([[0, 1, 2]], 6, axis=0), Sensor(outlier=0.01)),
        (conc, np.repeat([[0], [1]], 4, axis=0), Sensor(family="lognormal", pd=0.6, outlier=0.01)),
        (wide, np.repeat([[1]], 20, axis=0), Sensor(outlier=0.01)),
        (conc, np.repeat([[0], [1]], 9, axis=0), Sensor(outlier=0.01)),
    )
    for c, task_pos, sensor in cases:
        task_z = np.where(
            rng.random(task_pos.shape) < 0.3, 0.0, rng.lognormal(-6, 1, task_pos.shape)
        )
        args = (c, source, weights, task_pos, task_z, sensor)
        interpolated = compiled_predicted_stats(*args, precision="interpolated")
        double = compiled_predicted_stats(*args, precision="double")
        for a, b in zip(interpolated, double, strict=True):
            np.testing.assert_array_equal(a, b)


def test_interpolated_stats_do_not_depend_on_the_thread_count():
    run_with_numba_threads(2, "tests.test_interpolated_sums", "_same_with_one_and_two_threads()")


def _same_with_one_and_two_threads() -> None:
    import numba

    assert numba.config.NUMBA_NUM_THREADS >= 2, "needs two numba threads (CI has 2 cores)"
    conc, source, weights = _late_case()
    task_pos, task_z = _tasks(conc, np.random.default_rng(5))
    args = (conc, source, weights, task_pos, task_z, Sensor(outlier=0.01))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = compiled_predicted_stats(*args, precision="interpolated")
        numba.set_num_threads(2)
        two = compiled_predicted_stats(*args, precision="interpolated")
    finally:
        numba.set_num_threads(before)
    for a, b in zip(one, two, strict=True):
        np.testing.assert_array_equal(a, b)


def test_interpolation_is_the_default_of_one_reading_predictions_only():
    for name in ("dcee", "dcee-cl", "dcee-cl-tree", "infotaxis", "entrotaxis", "dcee-ms"):
        assert get_planner(name).options()["precision"] == "interpolated"
        assert get_planner(name, precision="double").options()["precision"] == "double"
    assert get_planner("dcee-mcts").cost.precision == "double"
    # dcee-ms's default only touches its first stage: sequences of several readings are
    # computed exactly under every precision (the same kernel, bit for bit)
    conc, source, weights = _late_case()
    task_pos = np.repeat(np.array([[0, 1], [1, 0]]), 20, axis=0)
    rng = np.random.default_rng(5)
    task_z = np.where(rng.random(task_pos.shape) < 0.5, 0.0, rng.lognormal(-6, 1, task_pos.shape))
    sensor = Sensor(outlier=0.01)
    exact = compiled_predicted_stats(conc, source, weights, task_pos, task_z, sensor)
    default = compiled_predicted_stats(
        conc, source, weights, task_pos, task_z, sensor, precision="interpolated"
    )
    for a, b in zip(exact, default, strict=True):
        np.testing.assert_array_equal(a, b)


def test_interpolated_decisions_agree_with_the_exact_ones():
    """The agreement check (the reference exact, in double precision) on a short search."""
    from dcee.perf.agreement import search_agreement

    a = search_agreement("paper:1", "dcee-cl", 0, 2000, 12, precision="interpolated")
    assert a.precision == "interpolated" and a.decisions == 12
    assert a.same_choice == a.decisions
    assert a.max_cost_diff_over_spread < 1e-4


@pytest.mark.parametrize(
    "sensor", [Sensor.paper_exact(), Sensor(outlier=0.01)], ids=["paper", "gauss+out"]
)
def test_node_terms_are_the_position_rows_formulas_bit_for_bit(sensor):
    """The interpolation evaluates the likelihood terms at its nodes with gaussian_terms; a
    particle at a node's concentration must get the very same terms from position_rows (one
    formula, not two that drift apart)."""
    from dcee.planning.interpolated_kernels import gaussian_terms
    from dcee.planning.position_kernels import plume_constants, position_rows

    theta = np.ascontiguousarray(random_theta(2000, np.random.default_rng(2)))
    constants = np.empty((10, len(theta)))
    plume_constants(theta, constants)
    out = [np.empty((1, len(theta))) for _ in range(6)]
    shape = (0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0)  # the paper's plume: IsotropicPlume().shape
    position_rows(constants, np.array([[20.0, 15.0, 1.0]]), np.array([0]), 1e-3, *shape,
                  sensor.params, *out)  # fmt: skip
    conc, _, loc, log_nd, inv_sigma, det_offset = (a[0] for a in out)
    assert np.array_equal(loc, conc)  # the location is the concentration itself
    terms = np.array([gaussian_terms(c, sensor.params) for c in conc])
    assert (conc < sensor.params.c_lin).any() and (conc > 1e-3).any()  # both branches
    np.testing.assert_array_equal(terms[:, 0], log_nd)
    np.testing.assert_array_equal(terms[:, 1], inv_sigma)
    np.testing.assert_array_equal(terms[:, 2], det_offset)
