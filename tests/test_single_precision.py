"""The planners' ``precision="single"``: float32 exp and log against float64 NumPy, the
one-stage predicted-posterior statistics against the NumPy reference, and the cases that must
fall back to double precision."""

import math

import numpy as np
import pytest

from dcee.errors import DceeInputError
from dcee.models import Sensor
from dcee.numeric import vexp_f32, vlog_f32
from dcee.planning import get as get_planner
from dcee.planning.predicted_reference import predicted_posterior_stats_reference
from tests.helpers import compiled_predicted_stats, run_with_numba_threads


def test_float32_exp_matches_numpy_over_its_range_and_every_power_of_two():
    x = np.concatenate(
        [np.linspace(-87.0, 0.0, 200_001), -np.arange(0, 126) * math.log(2.0), [-1e-30, 0.0]]
    ).astype(np.float32)
    out = np.empty_like(x)
    vexp_f32(x, out)
    assert out.dtype == np.float32
    ref = np.exp(x.astype(np.float64))
    np.testing.assert_allclose(out, ref, rtol=3e-7, atol=0)
    below = np.empty(2, dtype=np.float32)
    vexp_f32(np.array([-200.0, -np.inf], dtype=np.float32), below)
    np.testing.assert_allclose(below, math.exp(-87.0), rtol=3e-7)  # floored, never 0 or NaN


def test_float32_log_matches_numpy_for_every_normal_float32():
    finfo = np.finfo(np.float32)
    x = np.concatenate(
        [np.geomspace(finfo.tiny, finfo.max, 200_001), np.linspace(0.5, 2.0, 20_001), [1.0]]
    ).astype(np.float32)
    out = np.empty_like(x)
    vlog_f32(x, out)
    ref = np.log(x.astype(np.float64))
    assert np.all(np.abs(out - ref) <= 2e-7 * np.maximum(1.0, np.abs(ref)))
    assert out[-1] == 0.0  # log 1 exactly
    tiny = np.empty(2, dtype=np.float32)
    vlog_f32(np.array([0.0, 1e-45], dtype=np.float32), tiny)
    assert np.all(np.isfinite(tiny)) and np.all(tiny < -87.0)  # read as the smallest normal


def _case(n=1500, seed=8):
    rng = np.random.default_rng(seed)
    source = np.column_stack([rng.uniform(0, 20, n), rng.uniform(0, 20, n), rng.uniform(0, 3, n)])
    weights = rng.random(n)
    weights[::7] = 0.0  # zero-weight particles must not count
    weights /= weights.sum()
    conc = np.ascontiguousarray(rng.lognormal(-7, 2, size=(3, n)))
    dist = rng.uniform(0.1, 20.0, conc.shape)
    return conc, source, weights, dist


@pytest.mark.parametrize(
    "sensor",
    [
        Sensor.paper_exact(),
        Sensor(outlier=0.01),
        Sensor(family="lognormal", pd=0.5, outlier=0.01),
        Sensor.paper_exact(family="lognormal", pd=0.5),
        Sensor(family="lognormal", pd=0.6, outlier=0.01, near_length=5.0),
    ],
    ids=["paper", "gauss+out", "ln+out", "ln", "ln+near"],
)
def test_single_precision_one_stage_stats_match_the_reference(sensor):
    conc, source, weights, dist = _case()
    rng = np.random.default_rng(2)
    task_pos = np.repeat(np.array([[0], [2], [1]]), 7, axis=0)
    task_z = np.where(rng.random(task_pos.shape) < 0.3, 0.0, rng.lognormal(-6, 2, task_pos.shape))
    task_z[3, 0] = 500.0  # a spike: the outlier component, or an unreachable reading
    args = (conc, source, weights, task_pos, task_z, sensor, dist)
    single = compiled_predicted_stats(*args, precision="single")
    double = compiled_predicted_stats(*args)
    ref = predicted_posterior_stats_reference(*args)
    log_ev, mean, trace, kl = single
    # about 1e-6 relative (float32 weights, float64 sums); 5e-6 leaves a margin of 5
    assert np.all(np.abs(log_ev - ref[0]) <= 5e-6 * np.maximum(1.0, np.abs(ref[0])))
    np.testing.assert_allclose(mean, ref[1], rtol=0, atol=5e-6)
    np.testing.assert_allclose(trace, ref[2], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(kl, ref[3], rtol=0, atol=5e-6)
    # it is not the double-precision path under another name
    assert not np.array_equal(kl, double[3])


def test_single_precision_falls_back_to_double_where_it_does_not_apply():
    """Tasks of several stages and sensors with false alarms are computed in double
    precision: the same numbers bit for bit."""
    conc, source, weights, dist = _case()
    rng = np.random.default_rng(3)
    several = (np.repeat([[0, 1, 2]], 6, axis=0), Sensor(outlier=0.01))
    false_alarms = (
        np.repeat([[0], [1]], 4, axis=0),
        Sensor(family="lognormal", pd=0.6, outlier=0.01, false_alarm=0.02),
    )
    for task_pos, sensor in (several, false_alarms):
        task_z = np.where(
            rng.random(task_pos.shape) < 0.4, 0.0, rng.lognormal(-6, 2, task_pos.shape)
        )
        args = (conc, source, weights, task_pos, task_z, sensor, dist)
        single = compiled_predicted_stats(*args, precision="single")
        double = compiled_predicted_stats(*args)
        for a, b in zip(single, double, strict=True):
            np.testing.assert_array_equal(a, b)


def test_single_precision_redoes_an_unreachable_reading_exactly():
    conc, source, weights, _ = _case()
    conc[1] = np.random.default_rng(0).uniform(1e-6, 2e-5, conc.shape[1])
    sensor = Sensor.paper_exact()
    task_pos = np.array([[0], [1], [1], [2]])
    task_z = np.array([[0.0], [1e-2], [3e-4], [1e-3]])
    args = (conc, source, weights, task_pos, task_z, sensor)
    single = compiled_predicted_stats(*args, precision="single")
    ref = predicted_posterior_stats_reference(*args)
    assert single[0][1] < -3000  # the reading no particle explains
    np.testing.assert_allclose(single[0][1], ref[0][1], rtol=1e-9)  # redone in double


@pytest.mark.parametrize("bad", ["half", "float32", "", 32])
def test_precision_option_is_checked(bad):
    with pytest.raises(DceeInputError, match="precision"):
        get_planner("dcee-cl", precision=bad)


def test_the_tree_search_refuses_single_precision_it_would_not_use():
    """Its sequences have `depth` readings (multi-stage tasks: double precision), so the option
    would do nothing; one line says so. With depth 1 it applies."""
    with pytest.raises(DceeInputError, match=r"precision.*depth=4"):
        get_planner("dcee-mcts:precision=single")
    assert get_planner("dcee-mcts:depth=1:precision=single").options()["precision"] == "single"


def test_single_precision_is_a_planner_option_everywhere_it_is_used():
    for name in ("dcee", "dcee-cl", "dcee-cl-tree", "dcee-ms", "infotaxis", "entrotaxis"):
        planner = get_planner(name, precision="single")
        assert planner.options()["precision"] == "single"
        # the default: interpolated sums for one reading (dcee-ms's first stage too)
        assert get_planner(name).options()["precision"] == "interpolated"


@pytest.mark.parametrize("precision", ["double", "single"])
def test_predicted_stats_do_not_depend_on_the_thread_count(precision):
    run_with_numba_threads(
        2, "tests.test_single_precision", f"_same_with_one_and_two_threads({precision!r})"
    )


def _same_with_one_and_two_threads(precision: str) -> None:
    import numba

    assert numba.config.NUMBA_NUM_THREADS >= 2, "needs two numba threads (CI has 2 cores)"
    conc, source, weights, dist = _case(n=5000)
    rng = np.random.default_rng(5)
    task_pos = np.repeat(np.array([[0], [1], [2]]), 9, axis=0)
    task_z = np.where(rng.random(task_pos.shape) < 0.3, 0.0, rng.lognormal(-6, 2, task_pos.shape))
    args = (conc, source, weights, task_pos, task_z, Sensor(outlier=0.01), dist)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = compiled_predicted_stats(*args, precision=precision)
        numba.set_num_threads(2)
        two = compiled_predicted_stats(*args, precision=precision)
    finally:
        numba.set_num_threads(before)
    for a, b in zip(one, two, strict=True):
        np.testing.assert_array_equal(a, b)


def test_agreement_check_compares_like_with_like_while_the_stall_guard_fires():
    """The agreement check decides again with the agent the searcher planned with: while the
    stall guard fires that is the guard's restricted agent (it used to compare 8 costs with 3
    and stop). Double against double must then agree on every decision."""
    from dcee.perf.agreement import search_agreement

    a = search_agreement("paper:1", "dcee", 0, 2000, 40)
    assert a.decisions == 40 and a.guard_fired > 0
    assert a.same_choice == a.decisions and a.max_cost_diff_over_spread < 1e-9
    single = search_agreement("paper:1", "dcee-cl", 0, 2000, 10, precision="single")
    assert single.precision == "single" and single.decisions == 10
    assert single.max_cost_diff_over_spread < 1e-4  # float32 weights, about 1e-6 of the spread
