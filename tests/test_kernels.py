"""Compiled kernels against independent references: math.exp, the NumPy likelihood, and the
NumPy predicted-posterior statistics in the cases that take the kernels' special paths."""

import math

import numpy as np
import pytest

from dcee.models import Sensor
from dcee.models.sensor_kernels import log_likelihood
from dcee.numeric import vexp, vlog1p
from dcee.planning.predicted_reference import (
    location_kl_reference,
    predicted_posterior_stats_reference,
)
from tests.helpers import _terms_from_concentrations, compiled_location_kl, compiled_predicted_stats


def test_vectorised_exp_matches_math_exp():
    x = np.concatenate([-np.geomspace(1e-12, 700, 20_000), [0.0, -0.5 * math.log(2)]])
    out = np.empty_like(x)
    vexp(x, out)
    ref = np.exp(x)
    np.testing.assert_allclose(out, ref, rtol=1e-14, atol=0)
    below = np.empty(1)
    vexp(np.array([-800.0]), below)
    assert 0.0 <= below[0] <= math.exp(-700)


@pytest.mark.parametrize("pd", [0.7, 1.0])
def test_missed_detection_likelihood_small_and_large_concentrations(pd):
    """The linearised branch (C < 1e-6 σ_min) and the erfc branch agree with scipy to 1e-15
    absolute across the switch, and to 1e-9 relative far from it."""
    sensor = Sensor.paper_exact(pd=pd)
    sp = sensor.params
    c_lin = sp.c_lin
    c = np.concatenate([[0.0], c_lin * np.array([0.01, 0.5, 0.999, 1.001, 2.0]), [1e-4, 5e-4]])
    c = np.concatenate([c, np.geomspace(1e-3, 10, 20)])
    fast = np.array([log_likelihood(0.0, ci, math.inf, sp) for ci in c])
    ref = sensor.log_likelihood(0.0, c)
    np.testing.assert_allclose(fast, ref, rtol=1e-9, atol=1e-15)


def _stats_case(n=2000, seed=3):
    rng = np.random.default_rng(seed)
    source = np.column_stack([rng.uniform(0, 20, n), rng.uniform(0, 20, n), rng.uniform(0, 3, n)])
    weights = rng.random(n)
    weights[::7] = 0.0  # zero-weight particles must not count
    weights /= weights.sum()
    conc = np.ascontiguousarray(rng.lognormal(-8, 2, size=(3, n)))
    return source, weights, conc


def _run(conc, source, weights, task_pos, task_z, sensor, dist=None, **flags):
    return compiled_predicted_stats(conc, source, weights, task_pos, task_z, sensor, dist, **flags)


def test_predicted_stats_unreachable_reading_takes_exact_path():
    """A reading no particle can explain (every log-likelihood below −3000) underflows the
    one-pass sums; the kernel must redo it exactly and still match the reference."""
    source, weights, conc = _stats_case()
    conc[1] = np.random.default_rng(0).uniform(1e-6, 2e-5, conc.shape[1])
    sensor = Sensor.paper_exact()
    task_pos = np.array([[0], [1], [1], [2]])
    task_z = np.array([[0.0], [1e-2], [3e-4], [1e-3]])
    out = _run(conc, source, weights, task_pos, task_z, sensor)
    ref = predicted_posterior_stats_reference(conc, source, weights, task_pos, task_z, sensor)
    for fast, slow in zip(out, ref, strict=True):
        np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-12)
    assert out[0][1] < -3000  # the unreachable reading really is unreachable


def test_predicted_stats_optional_outputs_are_skipped_not_wrong():
    source, weights, conc = _stats_case()
    sensor = Sensor.paper_exact()
    task_pos = np.array([[0], [0], [2]])
    task_z = np.array([[0.0], [2e-3], [1e-3]])
    full = _run(conc, source, weights, task_pos, task_z, sensor)
    only_ev = _run(
        conc, source, weights, task_pos, task_z, sensor, want_moments=False, want_kl=False
    )
    # without moments the sums are one column instead of five (another BLAS routine and, on
    # another CPU, another order of the additions): equal to rounding, not bit for bit
    np.testing.assert_allclose(only_ev[0], full[0], rtol=1e-14, atol=0)
    assert np.isnan(only_ev[1]).all() and np.isnan(only_ev[2]).all() and np.isnan(only_ev[3]).all()
    no_kl = _run(conc, source, weights, task_pos, task_z, sensor, want_kl=False)
    np.testing.assert_array_equal(no_kl[1], full[1])
    assert np.isnan(no_kl[3]).all()
    # several stages per task take the other path; without moments it reads no offsets
    task_pos2 = np.array([[0, 1], [0, 1], [2, 0]])
    task_z2 = np.array([[0.0, 2e-3], [1e-3, 0.0], [0.0, 0.0]])
    full2 = _run(conc, source, weights, task_pos2, task_z2, sensor)
    only_kl2 = _run(conc, source, weights, task_pos2, task_z2, sensor, want_moments=False)
    # (without moments the sums are a dot product, not one column of a matrix product: another
    # BLAS routine, so equal to rounding rather than bit for bit)
    np.testing.assert_allclose(only_kl2[0], full2[0], rtol=1e-14, atol=0)
    np.testing.assert_allclose(only_kl2[3], full2[3], rtol=1e-12, atol=1e-15)
    assert np.isnan(only_kl2[1]).all() and np.isnan(only_kl2[2]).all()


def test_predicted_stats_multi_step_sequences_match_reference():
    """Horizon 3 (dcee-ms): several readings per task, mixed detections and non-detections."""
    source, weights, conc = _stats_case(n=1500, seed=8)
    sensor = Sensor.paper_exact()
    rng = np.random.default_rng(1)
    task_pos = np.repeat(np.array([[0, 1, 2], [2, 2, 0]]), 6, axis=0)
    task_z = np.where(rng.random((12, 3)) < 0.4, 0.0, rng.lognormal(-7, 1, (12, 3)))
    out = _run(conc, source, weights, task_pos, task_z, sensor)
    ref = predicted_posterior_stats_reference(conc, source, weights, task_pos, task_z, sensor)
    for fast, slow in zip(out, ref, strict=True):
        np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize(
    "sensor",
    [
        Sensor.paper_exact(family="lognormal", pd=0.5),
        Sensor(family="lognormal", pd=0.5, outlier=0.01),
        Sensor(outlier=0.01),
        Sensor(family="lognormal", pd=0.6, outlier=0.01, false_alarm=0.02),
        Sensor(family="lognormal", pd=0.6, outlier=0.01, near_length=5.0),
        Sensor.paper_exact(near_length=3.0),
        Sensor(family="lognormal", pd=0.6, log_sd_near=2.0, log_sd_length=3.0, outlier=0.01),
        Sensor(family="lognormal", pd=0.6, outlier=0.01, near_length=5.0, conserve_mean=True),
    ],
    ids=[
        "ln",
        "ln+out",
        "gauss+out",
        "ln+out+fa",
        "ln+near",
        "gauss+near",
        "ln+spread",
        "ln+conserve",
    ],
)
def test_predicted_stats_match_reference_for_every_family(sensor):
    """The transformed-frame kernels (vectorised log-sum-exp of the outlier component, the
    Jacobian added to the evidence) against the plain NumPy likelihood, horizons 1 and 3."""
    source, weights, conc = _stats_case(n=1500, seed=8)
    rng = np.random.default_rng(2)
    dist = rng.uniform(0.1, 20.0, conc.shape)
    for task_pos in (np.repeat(np.array([[0], [2]]), 5, axis=0), np.repeat([[0, 1, 2]], 8, axis=0)):
        shape = task_pos.shape
        task_z = np.where(rng.random(shape) < 0.4, 0.0, rng.lognormal(-6, 2, shape))
        task_z[0, 0] = 500.0  # a spike that only the outlier component explains
        args = (conc, source, weights, task_pos, task_z, sensor, dist)
        out = _run(*args)
        ref = predicted_posterior_stats_reference(*args)
        for fast, slow in zip(out, ref, strict=True):
            np.testing.assert_allclose(fast, slow, rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize(
    "sensor", [Sensor(outlier=0.01), Sensor.paper_exact()], ids=["out", "exact"]
)
@pytest.mark.parametrize("stages", [2, 3, 4])
def test_several_stages_share_factors_and_match_reference(sensor, stages):
    """Sequences of 2-3 stages take the product kernel (dcee.planning.stage_products: factors
    shared between sequences that meet at a position with the same reading), 4 stages the
    per-task kernel (multi_stage_kernels); both against the NumPy reference, with sequences
    that share a first position and reading, one that shares a second position, and readings
    that no particle explains (a factor at its floor, the task redone exactly)."""
    source, weights, conc = _stats_case(n=1500, seed=5)
    conc = np.ascontiguousarray(np.vstack([conc, conc[::-1] * 3.0]))  # 6 positions
    rng = np.random.default_rng(stages)
    first = np.array([[0, 1, 2, 3], [0, 4, 2, 5], [3, 1, 0, 2], [0, 1, 5, 4]])[:, :stages]
    task_pos = np.repeat(first, 6, axis=0)
    shape = task_pos.shape
    task_z = np.where(rng.random(shape) < 0.4, 0.0, rng.lognormal(-7, 1.5, shape))
    task_z[6:12, 0] = task_z[0:6, 0]  # the same first reading at the same first position
    task_z[7, -1] = 1e3  # far above every prediction: the outlier term or nothing explains it
    task_z[13, 0] = 1e3
    out = _run(conc, source, weights, task_pos, task_z, sensor)
    ref = predicted_posterior_stats_reference(conc, source, weights, task_pos, task_z, sensor)
    for fast, slow in zip(out, ref, strict=True):
        np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-12)


def test_vectorised_log1p_matches_math_log1p():
    x = np.concatenate([[0.0], np.geomspace(1e-300, 1.0, 20_000)])
    out = np.empty_like(x)
    vlog1p(x, out)
    np.testing.assert_allclose(out, np.log1p(x), rtol=1e-15, atol=0)


@pytest.mark.parametrize(
    ("meander", "decay", "backflow", "radius", "vertical", "ground", "meander_z"),
    [
        (0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0),
        (0.6, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0),
        (0.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0),
        (0.0, 1.0, 0.1, 0.0, 1.0, 0.0, 0.0),
        (0.15, 1.0, 0.05, 1.0, 1.0, 0.0, 0.0),
        (0.0, 1.0, 0.0, 0.0, 0.66, 1.0, 0.0),
        (0.0, 1.0, 0.05, 1.0, 0.66, 0.5, 0.0),
        (0.15, 1.0, 0.0, 0.0, 1.0, 0.0, 0.1),
    ],
)
@pytest.mark.parametrize(
    "sensor",
    [
        Sensor.paper_exact(pd=0.7),
        Sensor.paper_exact(pd=1.0),
        Sensor.paper_exact(family="lognormal", pd=0.6),
        Sensor.paper_exact(family="lognormal", pd=0.6, near_length=3.0),
        Sensor.paper_exact(family="lognormal", pd=0.6, log_sd_near=2.0, log_sd_length=3.0),
        Sensor.paper_exact(family="lognormal", pd=0.6, near_length=3.0, conserve_mean=True),
    ],
    ids=["gauss", "gauss-pd1", "ln", "ln+near", "ln+spread", "ln+conserve"],
)
def test_position_rows_match_the_numpy_plume_and_likelihood(
    sensor, meander, decay, backflow, radius, vertical, ground, meander_z
):
    """The planners' per-position terms, written into chosen rows, against the NumPy plume and
    the NumPy likelihood of a non-detection and of a reading (which fixes loc, σ and Pd); the
    first and third sensors take the vectorised path (exp, log, erfc of dcee.numeric), the
    others the libm one."""
    from dcee.estimation.priors import Gamma, SourcePrior, Uniform
    from dcee.models.plume import isotropic_concentration_reference
    from dcee.planning.position_kernels import plume_constants, position_rows

    prior = SourcePrior.from_dict(
        {
            "x": Uniform(0, 50),
            "y": Uniform(0, 50),
            "z": Uniform(0, 5),
            "q": Gamma(2, 5),
            "u": Uniform(0, 6),
            "phi": Uniform(0, 2 * np.pi),
            "zeta1": Uniform(0.2, 2),
            "zeta2": Uniform(6, 10),
        }
    )
    theta = np.ascontiguousarray(prior.sample(np.random.default_rng(1), 3000))
    positions = np.array([[10.0, 10.0, 1.0], [30.0, 12.0, 4.0], [45.0, 45.0, 0.0]])
    rows = np.array([4, 0, 2])
    constants = np.empty((10, len(theta)))
    plume_constants(theta, constants)
    out = [np.full((5, len(theta)), np.nan) for _ in range(6)]
    position_rows(
        constants,
        positions,
        rows,
        1e-3,
        meander,
        decay,
        backflow,
        radius,
        vertical,
        ground,
        meander_z,
        sensor.params,
        *out,
    )
    conc, dist, loc, log_nd, inv_sigma, det_offset = (a[rows] for a in out)
    ref_c = isotropic_concentration_reference(
        theta, positions, 1e-3, meander, decay, backflow, radius, vertical, ground, meander_z
    ).T
    np.testing.assert_allclose(conc, ref_c, rtol=1e-10, atol=1e-300)
    ref_r = np.linalg.norm(theta[None, :, :3] - positions[:, None, :], axis=2)
    np.testing.assert_allclose(dist, np.maximum(ref_r, 1e-3), rtol=1e-14)
    np.testing.assert_allclose(
        log_nd, sensor.log_likelihood(0.0, ref_c, ref_r), rtol=1e-9, atol=1e-14
    )
    # a detection z: log p(z | C, r) = det_offset − ½((v − loc)/σ)² − ½ log 2π (+ Jacobian)
    z = 2e-3
    v = math.log(z) if sensor.lognormal else z
    jac = -math.log(z) if sensor.lognormal else 0.0
    x = (v - loc) * inv_sigma
    fast = det_offset - 0.5 * x * x - 0.5 * math.log(2 * math.pi) + jac
    np.testing.assert_allclose(fast, sensor.log_likelihood(z, ref_c, ref_r), rtol=1e-8, atol=1e-8)
    assert np.all(np.isnan(out[0][[1, 3]]))  # rows not asked for are left alone


def test_vectorised_erfc_and_log_match_scipy_and_numpy():
    from scipy.special import erfc

    from dcee.numeric import verfc, vlog

    y = np.concatenate([np.linspace(0, 8, 20_001), np.linspace(8, 27, 2_001)])
    out = np.empty_like(y)
    verfc(y, out)
    ref = erfc(y)
    normal = ref > 1e-300
    np.testing.assert_allclose(out[normal], ref[normal], rtol=1e-13, atol=0)
    assert np.all(out[~normal] <= 1e-300)
    # the kernel evaluates the Chebyshev series of studies/fit_erfcx.py as the same polynomial
    # in powers of t (Horner's rule); the literals in _verfc_pos are _ERFCX_POWERS'
    from numpy.polynomial import chebyshev

    from dcee.numeric import _ERFCX_CHEB, _ERFCX_POWERS

    assert np.array_equal(chebyshev.cheb2poly(np.array(_ERFCX_CHEB)), np.array(_ERFCX_POWERS))
    t = np.linspace(-1.0, 1.0, 4001)
    horner = np.zeros_like(t)
    for c in _ERFCX_POWERS[::-1]:
        horner = c + t * horner
    np.testing.assert_allclose(horner, chebyshev.chebval(t, _ERFCX_CHEB), rtol=2e-15, atol=0)
    # and the kernel's unrolled literals are those: erfc(y) = e^(−y²) · series(t) / (y + 3)
    # with this Horner sum, to the last bits of the two exp implementations
    y = np.linspace(0.0, 6.0, 3001)
    series = np.zeros_like(y)
    for c in _ERFCX_POWERS[::-1]:
        series = c + (y - 3.0) / (y + 3.0) * series
    kernel = np.empty_like(y)
    verfc(y, kernel)
    np.testing.assert_allclose(kernel, np.exp(-y * y) * series / (y + 3.0), rtol=1e-14, atol=0)
    # every normal float: the exponent is read from the bits (2^−1022 … 2^1023)
    tiny, huge = np.finfo(float).tiny, np.finfo(float).max
    x = np.concatenate(
        [np.geomspace(tiny, huge, 40_001), np.linspace(0.5, 2.0, 2_001), [tiny, huge, 1.0]]
    )
    lg = np.empty_like(x)
    vlog(x, lg)
    np.testing.assert_allclose(lg, np.log(x), rtol=1e-15, atol=3e-16)
    assert lg[-1] == 0.0  # log 1 exactly


def test_vectorised_exp_matches_math_exp_at_every_power_of_two():
    from dcee.numeric import vexp

    # 2^−m is assembled from its bits: every exponent of −700 ≤ x ≤ 0 (below, −700 is used)
    x = np.concatenate([-np.arange(0, 1010) * math.log(2.0), np.linspace(-700.0, 0.0, 50_001)])
    out = np.empty_like(x)
    vexp(x, out)
    np.testing.assert_allclose(out, np.exp(x), rtol=2e-15, atol=0)


@pytest.mark.parametrize(
    "sensor",
    [Sensor.paper_exact(), Sensor(family="lognormal", pd=0.6, outlier=0.01, near_length=5.0)],
    ids=["paper", "fluctuation"],
)
def test_location_kl_matches_reference_and_its_limits(sensor):
    """The KL divergence of the source location over cells (infotaxis:about=location) against
    the NumPy reference, and its limiting cases: one cell holds no location information (0);
    cells so small that every particle has its own equal the joint KL over the particles; and
    any cells lie between (marginalising cannot add information)."""
    source, weights, conc = _stats_case(n=1500, seed=8)
    rng = np.random.default_rng(5)
    dist = rng.uniform(0.1, 20.0, conc.shape)
    for task_pos in (np.repeat(np.array([[0], [2]]), 5, axis=0), np.repeat([[0, 1, 2]], 8, axis=0)):
        shape = task_pos.shape
        task_z = np.where(rng.random(shape) < 0.4, 0.0, rng.lognormal(-6, 2, shape))
        args = (conc, source, weights, task_pos, task_z, sensor)
        joint = _run(*args, dist)[3]
        for cell in (2.0, 5.0):
            fast = compiled_location_kl(*args, cell, dist)
            np.testing.assert_allclose(fast, location_kl_reference(*args, cell, dist), rtol=1e-9)
            assert np.all(fast <= joint * (1 + 1e-9) + 1e-12) and np.all(fast >= 0)
        np.testing.assert_allclose(compiled_location_kl(*args, 1e-6, dist), joint, rtol=1e-9)
        np.testing.assert_allclose(compiled_location_kl(*args, 1e3, dist), 0.0, atol=1e-12)


@pytest.mark.parametrize("stages", [1, 2, 3])
def test_compiled_task_list_equals_the_numpy_reference(stages):
    from dcee.planning.predicted_reference import unique_per_sequence_reference
    from dcee.planning.reading_terms import task_layout, unique_tasks

    rng = np.random.default_rng(stages)
    for j_count in (1, 4, 40, 65, 500):  # 65 and 500: the merge-sort path (INSERTION_SORT_MAX)
        # few distinct values: many equal hypotheses (the non-detections) and equal prefixes
        readings = rng.choice([0.0, 0.0, 0.0, 1e-3, 2.5e-3, 7.0], size=(9, j_count, stages))
        got = unique_tasks(readings)
        want = unique_per_sequence_reference(readings)
        for a, b in zip(got, want, strict=True):
            np.testing.assert_array_equal(a, b)
        # every hypothesis maps back to its own readings
        np.testing.assert_array_equal(got[0][got[2]], readings)
        positions = np.repeat(np.arange(9), [len(np.unique(r, axis=0)) for r in readings])
        starts, used = task_layout(np.tile(positions[:, None], (1, stages)), 12)
        np.testing.assert_array_equal(
            starts, np.append(np.flatnonzero(np.diff(positions, prepend=-1)), len(positions))
        )
        np.testing.assert_array_equal(used, np.arange(9))


@pytest.mark.parametrize(
    "sensor",
    [
        Sensor.paper_exact(),
        Sensor(outlier=0.01),
        Sensor(family="lognormal", pd=0.6, outlier=0.01),
        Sensor.paper_exact(near_length=3.0),
    ],
    ids=["exact", "gauss+out", "ln+out", "exact+near"],
)
def test_one_pass_sums_without_moments_match_the_matrix_product_path(sensor):
    """Without the moments (infotaxis, entrotaxis) one-stage tasks are summed while their
    weights are computed (dcee.planning.one_stage_sums): the evidence and KL divergence of the
    general path (moments on) and of the NumPy reference, to rounding."""
    source, weights, conc = _stats_case(n=2100, seed=4)  # four blocks and a partial one
    rng = np.random.default_rng(6)
    task_pos = np.repeat(np.array([[0], [1], [2]]), 6, axis=0)
    task_z = np.where(rng.random(task_pos.shape) < 0.4, 0.0, rng.lognormal(-6, 1.5, task_pos.shape))
    task_z[1, 0] = 500.0  # a spike: with outliers only their component explains it
    one_pass = _run(conc, source, weights, task_pos, task_z, sensor, want_moments=False)
    general = _run(conc, source, weights, task_pos, task_z, sensor)
    ref = predicted_posterior_stats_reference(conc, source, weights, task_pos, task_z, sensor)
    for k in (0, 3):  # log evidence, KL divergence
        # (KL = Σwe·ll/Σwe − log evidence cancels: its rounding is absolute, ~1e-15 · |ll|)
        np.testing.assert_allclose(one_pass[k], general[k], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(one_pass[k], ref[k], rtol=1e-8, atol=1e-10)
    assert np.isnan(one_pass[1]).all() and np.isnan(one_pass[2]).all()
    assert np.ptp(one_pass[3]) > 0.01  # the readings teach different amounts: not a vacuous check


@pytest.mark.parametrize(
    "sensor", [Sensor.paper_exact(), Sensor.paper_exact(false_alarm=0.1)], ids=["exact", "fa"]
)
def test_compiled_sampled_readings_are_the_sensors_bit_for_bit(sensor):
    from dcee.planning.reading_terms import gaussian_sampled_readings

    rng = np.random.default_rng(9)
    conc = rng.lognormal(-8, 2, (7, 300))
    indices = rng.integers(0, 300, 40)
    pos_idx = rng.integers(0, 7, (9, 2))
    noise = sensor.draw_noise(rng, (40, 3))
    got = gaussian_sampled_readings(conc, indices, pos_idx, noise, sensor.params)
    want = sensor.simulate_from(
        conc[:, indices][pos_idx].transpose(0, 2, 1), noise[None, :, :2], np.inf
    )
    assert np.array_equal(got, want)
    assert 0 < np.mean(got > 0) < 1  # detections and non-detections both present
    from dcee.planning.reading_terms import gaussian_transformed

    tz = got.reshape(-1, 2)
    assert np.array_equal(
        gaussian_transformed(tz, sensor.threshold), sensor.transformed_readings(tz)[0]
    )
    if sensor.false_alarm == 0:  # the other terms the planners then pass: −inf, −inf and 0
        _, fa, out, jac = sensor.transformed_readings(tz)
        assert np.all(fa == -np.inf) and np.all(out == -np.inf) and np.all(jac == 0)


def test_one_stage_task_sums_in_one_call_equal_the_kernels_it_replaces():
    """predicted_posterior_stats without moments sends one-stage tasks to one compiled call
    (bounds, one-pass sums, their totals): its sums equal task_setup + one_stage_sums +
    partial.sum(axis=0) bit for bit; an unreachable reading is still redone exactly; the
    interpolated precision still interpolates a group of 16 readings or more and takes the
    one call (the same numbers as double precision) below that."""
    from dcee.planning.block_sums import BLOCK
    from dcee.planning.one_stage_sums import one_stage_sums, one_stage_task_sums
    from dcee.planning.reading_terms import model_ceilings, task_bounds, task_setup

    source, weights, conc = _stats_case(n=2100, seed=4)
    conc[1] = np.random.default_rng(0).uniform(1e-6, 2e-5, conc.shape[1])
    sensor = Sensor.paper_exact()
    task_pos = np.array([[0], [0], [1], [1], [2]])
    task_z = np.array([[0.0], [2e-3], [0.0], [1e-2], [1e-3]])  # task 3: unreachable
    loc, log_nd, inv_sigma, det_offset = _terms_from_concentrations(conc, None, sensor)
    v, fa, out, _ = sensor.transformed_readings(task_z)
    args = (loc, log_nd, inv_sigma, det_offset, weights, task_pos, v, fa, out, sensor.params)
    done, setup, sums = one_stage_task_sums(*args, True, len(task_pos) + 1)
    assert done
    group_start, live_bound, *_ = task_setup(
        task_pos, v, fa, out, log_nd, det_offset, weights, sensor.params
    )
    # the bounds from the model's ceilings: above those from the largest live terms (the sum
    # of a bound too low would be clipped), and within a few nats of them here
    ceiling_nd, ceiling_det = model_ceilings(sensor.params)
    assert ceiling_nd >= log_nd.max() and ceiling_det >= det_offset.max()
    bound = np.empty(len(task_pos))
    rows = log_nd.shape[0]
    task_bounds(
        task_pos, v, fa, out, np.full(rows, ceiling_nd), np.full(rows, ceiling_det),
        sensor.params, bound,
    )  # fmt: skip
    assert np.array_equal(setup[1], bound) and np.array_equal(setup[0], group_start)
    assert np.all(bound >= live_bound) and np.all(bound - live_bound < 12.0)
    partial = np.empty(((len(weights) + BLOCK - 1) // BLOCK, len(task_pos), 6))
    one_stage_sums(
        loc, log_nd, inv_sigma, det_offset, weights, group_start, task_pos, v, out, bound,
        sensor.params, True, partial,
    )  # fmt: skip
    assert np.array_equal(sums, partial.sum(axis=0))
    assert not one_stage_task_sums(*args, True, 2)[0]  # a group of two: "interpolate it"

    ref = predicted_posterior_stats_reference(conc, source, weights, task_pos, task_z, sensor)
    fast = _run(conc, source, weights, task_pos, task_z, sensor, want_moments=False)
    assert fast[0][3] < -3000  # redone exactly, not lost to underflow
    for k in (0, 3):
        np.testing.assert_allclose(fast[k], ref[k], rtol=1e-8, atol=1e-10)
    small = _run(
        conc,
        source,
        weights,
        task_pos,
        task_z,
        sensor,
        want_moments=False,
        precision="interpolated",
    )
    for a, b in zip(small, fast, strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    # late in a search (concentrations within a factor of a few): 20 readings at one position
    # (4,000 particles: with fewer the nodes would not be fewer than the particles)
    rng = np.random.default_rng(3)
    n = 4000
    narrow = np.exp(rng.normal(-6.0, 0.5, size=(1, n)))
    many_pos = np.zeros((20, 1), dtype=np.int64)
    many_z = narrow[0, rng.integers(0, n, 20)][:, None]
    late = (narrow, rng.uniform(0, 50, (n, 3)), np.full(n, 1.0 / n), many_pos, many_z, sensor)
    interp, exact = (
        _run(*late, want_moments=False, precision=p) for p in ("interpolated", "double")
    )
    assert not np.array_equal(interp[0], exact[0])  # interpolated: within 1e-8, not equal
    np.testing.assert_allclose(interp[0], exact[0], rtol=1e-7)
