import numpy as np
import pytest

from dcee import DceeInputError, IsotropicPlume, ParticleFilter, Sensor
from dcee.estimation import Estimator, ModelBank, systematic_resample
from dcee.estimation.filter_kernels import history_log_likelihood, history_log_likelihood_reference
from dcee.estimation.resampling import systematic_resample_reference
from dcee.models.plume import isotropic_concentration_reference
from tests.helpers import planar_prior, theta_at

TRUE_SOURCE = (6.0, 5.0)
TRUE_Q = 2.0
READ_POSITIONS = [(1.0, 5.5), (3.0, 3.0), (2.0, 8.0), (4.0, 6.0), (8.5, 5.0), (3.0, 5.0)]


def _readings(sensor: Sensor, seed: int = 2) -> list[tuple[np.ndarray, float]]:
    truth = theta_at([(*TRUE_SOURCE, 0.0)], q=TRUE_Q, u=2.0, phi=0.0)
    rng = np.random.default_rng(seed)
    out = []
    for p in READ_POSITIONS:
        pos = np.array([*p, 0.0])
        c = isotropic_concentration_reference(truth, pos[None])[0, 0]
        out.append((pos, float(sensor.simulate(c, rng))))
    return out


def _grid_posterior(sensor, data, power=1.0):
    """Exact posterior on an (x, y, q) grid with NumPy reference models (prior: U × U × Γ(2,1)),
    each reading's likelihood raised to ``power`` (one number, or one per reading).

    Two exact identities keep it a few seconds: readings repeated at one position with one value
    are one reading raised to the sum of their powers (p^a · p^b = p^(a+b)), and the isotropic
    concentration is linear in the release rate, so the reference plume is evaluated once on
    the (x, y) grid at q = 1 and scaled over the q nodes. Results are memoised per data set."""
    powers = np.broadcast_to(np.asarray(power, float), len(data))
    merged: dict[tuple, float] = {}
    for (pos, z), m in zip(data, powers, strict=True):
        key = (*np.asarray(pos, float).tolist(), float(z))
        merged[key] = merged.get(key, 0.0) + float(m)
    return _grid_posterior_merged(sensor, tuple(merged.items()))


_GRID_CACHE: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}


def _grid_posterior_merged(sensor, readings):
    key = (repr(sensor), readings)
    if key in _GRID_CACHE:
        return _GRID_CACHE[key]
    xs = np.linspace(0, 10, 161)
    ys = np.linspace(0, 10, 161)
    qs = np.linspace(0.01, 9.0, 90)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    n_xy = gx.size
    theta_unit = np.column_stack(
        [
            gx.ravel(),
            gy.ravel(),
            np.zeros(n_xy),
            np.ones(n_xy),  # q = 1: scaled over the q nodes below
            np.full(n_xy, 2.0),
            np.zeros(n_xy),
            np.ones(n_xy),
            np.full(n_xy, 8.0),
        ]
    )
    pos = np.array([r[0][:3] for r in readings])
    z = np.array([r[0][3] for r in readings])
    mult = np.array([r[1] for r in readings])
    plume = IsotropicPlume()
    unit = isotropic_concentration_reference(theta_unit, pos, plume.min_distance, *plume.shape)
    d = pos[None, :, :] - theta_unit[:, None, :3]
    dist = np.maximum(np.sqrt(np.einsum("nki,nki->nk", d, d)), plume.min_distance)
    conc = unit[:, None, :] * qs[None, :, None]  # (xy, q, reading)
    ll = sensor.log_likelihood(z[None, None, :], conc, dist[:, None, :])
    logp = (ll * mult).sum(axis=2) + np.log(qs)[None, :] - qs[None, :]  # Γ(2, 1) ∝ q e^{−q}
    w = np.exp(logp - logp.max()).ravel()
    w /= w.sum()
    grid = np.column_stack(
        [np.repeat(gx.ravel(), qs.size), np.repeat(gy.ravel(), qs.size), np.tile(qs, n_xy)]
    )
    mean = w @ grid
    sd = np.sqrt(w @ (grid - mean) ** 2)
    _GRID_CACHE[key] = (mean, sd)
    return mean, sd


@pytest.mark.parametrize("resample_threshold,mcmc_steps", [(0.5, 1), (1.0, 3)])
def test_filter_matches_exact_grid_posterior(sensor, resample_threshold, mcmc_steps):
    data = _readings(sensor)
    assert sum(r >= sensor.threshold for _, r in data) >= 3  # an informative data set
    grid_mean, grid_sd = _grid_posterior(sensor, data)
    pf = ParticleFilter(
        planar_prior(u=2.0),
        sensor,
        n_particles=20_000,
        seed=7,
        resample_threshold=resample_threshold,
        mcmc_steps=mcmc_steps,
    )
    for pos, z in data:
        pf.update(pos, z)
    assert pf.n_resamples > 0
    mean = pf.mean()
    sd = np.sqrt(np.diag(pf.cov()))
    assert pf.parameter_names == ("x", "y", "q")
    np.testing.assert_array_less(np.abs(mean - grid_mean), 0.2 * grid_sd)
    np.testing.assert_allclose(sd, grid_sd, rtol=0.2)


def test_reading_weight_gives_the_exact_power_likelihood_posterior(sensor):
    """estimator.reading_weight = 0.5: each reading counts as half an independent one. The filter
    (resampling, moves and all) matches the exact grid posterior of prior × Π p(z|Θ)^0.5, which
    is wider than the plain posterior."""
    data = _readings(sensor)
    grid_mean, grid_sd = _grid_posterior(sensor, data, power=0.5)
    _, plain_sd = _grid_posterior(sensor, data)
    assert np.all(grid_sd > 1.1 * plain_sd)
    pf = ParticleFilter(planar_prior(u=2.0), sensor, n_particles=20_000, seed=7, reading_weight=0.5)
    for pos, z in data:
        pf.update(pos, z)
    np.testing.assert_array_less(np.abs(pf.mean() - grid_mean), 0.2 * grid_sd)
    np.testing.assert_allclose(np.sqrt(np.diag(pf.cov())), grid_sd, rtol=0.2)
    with pytest.raises(DceeInputError, match="reading_weight"):
        ParticleFilter(planar_prior(u=2.0), sensor, n_particles=100, reading_weight=0.0)


def test_repeat_radius_discounts_a_run_of_readings_at_one_spot(sensor):
    """estimator.repeat_radius: a reading within the radius of an unbroken run of m readings
    just before it weighs reading_weight / (1 + m). Each position read three times in a row
    (1, 1/2, 1/3 at weight 1), with a reading 0.3 m off the spot in the middle of one run:
    the filter matches the exact grid posterior with those powers, and the multiplicities it
    keeps are the hand-computed weights."""
    data = _readings(sensor)
    runs = []
    for k, (pos, z) in enumerate(data):
        runs += [(pos, z), (pos + np.array([0.3, 0.0, 0.0]) if k == 0 else pos, z), (pos, z)]
    powers = np.tile([1.0, 1 / 2, 1 / 3], len(data))
    grid_mean, grid_sd = _grid_posterior(sensor, runs, power=powers)
    pf = ParticleFilter(planar_prior(u=2.0), sensor, n_particles=20_000, seed=5, repeat_radius=0.5)
    weights = []
    for pos, z in runs:
        weights.append(pf.repeat_weight(pos))
        pf.update(pos, z)
    np.testing.assert_allclose(weights, powers)
    _, _, mult = pf.history()
    np.testing.assert_allclose(mult.sum(), powers.sum())
    np.testing.assert_array_less(np.abs(pf.mean() - grid_mean), 0.2 * grid_sd)
    np.testing.assert_allclose(np.sqrt(np.diag(pf.cov())), grid_sd, rtol=0.2)
    # a reading beyond the radius ends the run; radius 0 (the default) weighs every reading alike
    assert pf.repeat_weight(np.array([20.0, 20.0, 0.0])) == 1.0
    plain = ParticleFilter(planar_prior(u=2.0), sensor, n_particles=100, seed=5)
    plain.update(*runs[0])
    assert plain.repeat_weight(runs[1][0]) == 1.0
    with pytest.raises(DceeInputError, match="repeat_radius"):
        ParticleFilter(planar_prior(u=2.0), sensor, n_particles=100, repeat_radius=-1.0)


def test_repeat_power_gentles_the_discount(sensor):
    """estimator.repeat_power p: the m-th reading of a run weighs 1 / (1 + m)^p; p = 1/2 gives
    1, 1/√2, 1/√3 (hand values), and the filter matches the exact grid posterior with them."""
    data = _readings(sensor)
    runs = [(pos, z) for pos, z in data for _ in range(3)]
    powers = np.tile([1.0, 2**-0.5, 3**-0.5], len(data))
    grid_mean, grid_sd = _grid_posterior(sensor, runs, power=powers)
    pf = ParticleFilter(
        planar_prior(u=2.0),
        sensor,
        n_particles=20_000,
        seed=5,
        repeat_radius=0.5,
        repeat_power=0.5,
    )
    weights = []
    for pos, z in runs:
        weights.append(pf.repeat_weight(pos))
        pf.update(pos, z)
    np.testing.assert_allclose(weights, powers)
    np.testing.assert_array_less(np.abs(pf.mean() - grid_mean), 0.2 * grid_sd)
    np.testing.assert_allclose(np.sqrt(np.diag(pf.cov())), grid_sd, rtol=0.2)
    with pytest.raises(DceeInputError, match="repeat_power"):
        ParticleFilter(planar_prior(u=2.0), sensor, n_particles=100, repeat_power=0.0)


def test_collapse_is_recovered_by_tempering_and_still_matches_the_posterior(sensor):
    data = _readings(sensor)
    grid_mean, grid_sd = _grid_posterior(sensor, data)
    # Assimilate the most informative (largest) reading first, so the flat prior collapses.
    order = sorted(data, key=lambda d: -d[1])
    pf = ParticleFilter(
        planar_prior(u=2.0), sensor, n_particles=20_000, seed=3, collapse_threshold=0.2
    )
    infos = [pf.update(pos, z) for pos, z in order]
    assert pf.recoveries, "a collapsing reading must be recorded as a recovery"
    assert max(i.tempering_stages for i in infos) > 1
    assert np.all(np.isfinite(pf.weights)) and pf.ess > 100
    np.testing.assert_array_less(np.abs(pf.mean() - grid_mean), 0.25 * grid_sd)


@pytest.mark.parametrize(
    "plume",
    [
        IsotropicPlume(),
        IsotropicPlume(meander_z=0.3),  # alone: the kernel must leave its fast path
        IsotropicPlume(meander=0.15, meander_z=0.1, ground=1.0),
    ],
)
def test_history_kernel_matches_reference(sensor, plume):
    rng = np.random.default_rng(0)
    theta = theta_at(np.column_stack([rng.uniform(0, 10, (500, 2)), np.zeros(500)]), q=2.0, u=2.0)
    pos = np.column_stack([rng.uniform(0, 10, (30, 2)), np.zeros(30)])
    pos[:, 2] = rng.uniform(0.0, 3.0, 30)  # off the sources' height: the vertical terms count
    z = np.where(rng.random(30) < 0.5, 0.0, rng.gamma(1.0, 5e-3, 30))
    mult = rng.integers(1, 4, 30).astype(float)
    out = np.empty(500)
    history_log_likelihood(
        theta, np.ones(500, bool), pos, z, mult, 0.1, *plume.shape, sensor.params, out
    )
    ref = history_log_likelihood_reference(theta, pos, z, mult, sensor, plume)
    np.testing.assert_allclose(out, ref, rtol=1e-9)


def test_constraints_hold_after_many_moves(sensor):
    pf = ParticleFilter(
        planar_prior(u=2.0), sensor, n_particles=3000, seed=1, resample_threshold=1.0, mcmc_steps=5
    )
    for pos, z in _readings(sensor):
        pf.update(pos, z)
    p = pf.particles
    assert np.all(p[:, 2] > 0)  # q > 0
    assert np.all((p[:, :2] >= 0) & (p[:, :2] <= 10))  # inside the volume
    assert np.all(pf.theta[:, 2] == 0.0) and np.all(pf.theta[:, 4] == 2.0)  # known stay known


def test_same_seed_same_particles(sensor):
    runs = []
    for _ in range(2):
        pf = ParticleFilter(planar_prior(u=2.0), sensor, n_particles=2000, seed=42)
        for pos, z in _readings(sensor):
            pf.update(pos, z)
        runs.append((pf.particles.copy(), pf.weights.copy()))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    np.testing.assert_array_equal(runs[0][1], runs[1][1])


def test_repeated_non_detections_are_merged_but_counted(sensor):
    pf = ParticleFilter(planar_prior(u=2.0), sensor, n_particles=500, seed=0)
    for _ in range(3):
        pf.update(np.array([1.0, 1.0, 0.0]), 0.0)
    _, z, mult = pf.history()
    assert len(z) == 1 and mult[0] == 3.0 and pf.n_readings == 3


def test_systematic_resampling_counts_are_within_one_of_expectation():
    w = np.random.default_rng(0).dirichlet(np.ones(50))
    idx = systematic_resample(w, np.random.default_rng(1), 1000)
    counts = np.bincount(idx, minlength=50)
    assert np.all(np.abs(counts - 1000 * w) < 1.0 + 1e-9)


def test_the_compiled_systematic_resampling_draws_the_numpy_references_indices():
    rng = np.random.default_rng(3)
    for _ in range(200):
        n = int(rng.integers(1, 3000))
        w = rng.random(n) ** 8  # many tiny weights, a few large: ties of the running sum
        w /= w.sum()
        m, seed = int(rng.integers(1, 200)), int(rng.integers(2**31))
        fast = systematic_resample(w, np.random.default_rng(seed), m)
        reference = systematic_resample_reference(w, np.random.default_rng(seed), m)
        assert np.array_equal(fast, reference)


def test_public_shapes(sensor):
    pf = ParticleFilter(planar_prior(), sensor, n_particles=100, seed=0)
    assert pf.particles.shape == (100, 3)
    assert pf.weights.shape == (100,) and pf.weights.sum() == pytest.approx(1.0)
    assert pf.mean().shape == (3,) and pf.cov().shape == (3, 3)


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_nan_reading_is_rejected(sensor, bad):
    pf = ParticleFilter(planar_prior(), sensor, n_particles=100, seed=0)
    with pytest.raises(DceeInputError, match="reading"):
        pf.update(np.array([1.0, 1.0, 0.0]), bad)
    with pytest.raises(DceeInputError, match="position"):
        pf.update(np.array([1.0, 1.0]), 0.0)
    with pytest.raises(DceeInputError, match="particles"):
        ParticleFilter(planar_prior(), sensor, n_particles=-5)
    for seed in (-1, 1.5, "7", None):  # numpy's own ValueError or a fresh entropy seed before
        with pytest.raises(DceeInputError, match="seed"):
            ParticleFilter(planar_prior(), sensor, n_particles=10, seed=seed)
    for seed in (3, np.int64(3), np.random.SeedSequence(3), np.random.default_rng(3)):
        ParticleFilter(planar_prior(), sensor, n_particles=10, seed=seed)


# --- the history likelihood kernel and its exact early rejection (issue 17) ---


@pytest.mark.parametrize(
    "sensor",
    [
        Sensor.paper_exact(),  # the paper's: vectorised non-detections
        Sensor.paper_exact(pd=1.0),
        Sensor(false_alarm=0.02, outlier=0.01),
        Sensor(family="lognormal", pd=0.6, log_sd=1.3, outlier=0.01),
        Sensor.paper_exact(
            family="lognormal", pd=0.6, log_sd=1.0, log_sd_near=2.0, log_sd_length=3.0
        ),
        Sensor.paper_exact(
            family="lognormal", pd=0.9, log_sd=1.3, near_length=5.0, magnitude=False
        ),
    ],
    ids=["paper", "pd1", "fa+outlier", "lognormal", "lognormal+spread", "detection-only"],
)
def test_history_likelihood_and_reading_bounds_against_numpy(sensor):
    from dcee.estimation.filter_kernels import (
        history_log_likelihood,
        history_log_likelihood_reference,
        reading_upper_bounds,
    )
    from dcee.models import IsotropicPlume
    from tests.helpers import random_theta

    rng = np.random.default_rng(3)
    theta = random_theta(700, rng)  # 700: two full blocks and a partial one
    pos = np.column_stack([rng.uniform(0, 50, (60, 2)), np.full(60, 4.0)])
    z = np.where(rng.random(60) < 0.6, 0.0, rng.gamma(1.0, 5e-3, 60) + 5e-4)
    mult = rng.integers(1, 4, 60).astype(float)
    plume = IsotropicPlume()
    out = np.empty(700)
    active = rng.random(700) < 0.9
    history_log_likelihood(
        theta, active, pos, z, mult, 1e-3, *IsotropicPlume().shape, sensor.params, out
    )
    ref = history_log_likelihood_reference(theta, pos, z, mult, sensor, plume)
    np.testing.assert_allclose(out[active], ref[active], rtol=1e-9)
    assert np.all(out[~active] == -np.inf)
    # every reading's bound lies above its log-likelihood for every particle
    from dcee.models.plume import isotropic_concentration_reference

    conc = isotropic_concentration_reference(theta, pos)
    dist = np.linalg.norm(theta[:, None, :3] - pos[None], axis=2)
    per = sensor.log_likelihood(z[None, :], conc, dist)
    bounds = reading_upper_bounds(z, sensor)
    assert np.all(per <= bounds[None, :] + 1e-12)
    # early rejection: exactly the particles whose full sum lies below their threshold are
    # abandoned, never one above it; the others keep their full sums
    threshold = ref + rng.normal(0.0, 30.0, 700)
    early = np.empty(700)
    history_log_likelihood(
        theta,
        active,
        pos,
        z,
        mult,
        1e-3,
        *IsotropicPlume().shape,
        sensor.params,
        early,
        threshold,
        bounds,
    )
    kept = np.isfinite(early)
    np.testing.assert_array_equal(early[kept], out[kept])
    assert np.all(ref[~kept & active] < threshold[~kept & active])
    assert np.all(kept[active & (ref > threshold)])
    assert (~kept & active).sum() > 50  # it does abandon hopeless ones


def test_mcmc_move_is_unchanged_by_early_rejection(monkeypatch):
    """The same filter run with and without the early exit of the MCMC move gives identical
    particles."""
    import dcee.estimation.resample_move as rmm
    from dcee.scenarios import load_scenario

    scenario = load_scenario("paper:1")
    truth = scenario.truth_theta()[None]

    def run() -> np.ndarray:
        pf = ParticleFilter(scenario.make_prior(), scenario.make_sensor(), n_particles=3000, seed=2)
        rng = np.random.default_rng(9)
        for k in range(40):
            p = np.array([5.0 + k, 12.0 + (k % 5), 4.0])
            c = isotropic_concentration_reference(truth, p[None])[0, 0]
            pf.update(p, float(pf.sensor.simulate(c, rng)))
        return pf.theta.copy()

    with_exit = run()
    plain = rmm.history_log_likelihood
    calls = []

    def no_exit(*args):
        calls.append(len(args))
        return plain(*args[:15])

    monkeypatch.setattr(rmm, "history_log_likelihood", no_exit)
    np.testing.assert_array_equal(run(), with_exit)
    assert 17 in calls  # the move's calls, with a threshold and bounds, ran without them


def test_both_estimators_implement_the_estimator_interface_and_resample_on_demand():
    """The particle filter and the model bank answer the same interface (no caller asks which
    one it holds); resample() keeps the belief (same mean within Monte-Carlo error) and makes
    the weights uniform."""

    def filt(seed: int) -> ParticleFilter:
        return ParticleFilter(
            planar_prior(), Sensor.paper_exact(), IsotropicPlume(), n_particles=4000, seed=seed
        )

    lone, bank = filt(0), ModelBank([filt(1), filt(2)], ["a", "b"])
    for est in (lone, bank):
        assert isinstance(est, Estimator)
        for x, y in READ_POSITIONS:
            est.update(np.array([x, y, 1.0]), 0.01)
        before = est.source_mean().copy()
        resamples = est.n_resamples
        est.resample()
        assert est.n_resamples == resamples + 1
        np.testing.assert_allclose(est.weights, 1.0 / est.n)
        assert np.linalg.norm(est.source_mean() - before) < 1.0
    assert lone.reading_model() is None
    choice = bank.reading_model()
    assert choice.name in ("a", "b") and 0.0 < choice.probability <= 1.0


def test_compiled_summaries_match_numpy_and_a_hand_calculation():
    """weighted_moments is np.cov(aweights, ddof=0) and the weighted mean; weighted_rmse the
    einsum form; reweighted the log evidence and ESS of the NumPy/SciPy formulas; and two
    points with weights 1 and 3 give the hand values."""
    from scipy.special import logsumexp

    from dcee.estimation.resampling import effective_sample_size, reweighted
    from dcee.estimation.summaries import weighted_moments, weighted_rmse

    mean, cov = weighted_moments(np.array([[0.0, 0.0, 0.0], [4.0, 0.0, 2.0]]), np.array([1, 3.0]))
    np.testing.assert_allclose(mean, [3.0, 0.0, 1.5])
    # Var x = (1·9 + 3·1) / 4 = 3, Var z = (1·2.25 + 3·0.25) / 4 = 0.75, Cov xz = 1.5
    np.testing.assert_allclose(cov, [[3.0, 0, 1.5], [0, 0, 0], [1.5, 0, 0.75]])
    rng = np.random.default_rng(4)
    points = rng.normal(size=(5000, 3)) * [1.0, 2.0, 0.3] + [10.0, -4.0, 1.0]
    w = rng.random(5000)
    w /= w.sum()
    mean, cov = weighted_moments(points, w)
    np.testing.assert_allclose(mean, w @ points, rtol=1e-13)
    np.testing.assert_allclose(cov, np.cov(points, rowvar=False, aweights=w, ddof=0), rtol=1e-12)
    wide = np.column_stack([points, rng.normal(size=(5000, 2))])  # the general (not 3-column) loop
    mean5, cov5 = weighted_moments(wide, w)
    np.testing.assert_allclose(mean5, w @ wide, rtol=1e-13)
    np.testing.assert_allclose(cov5, np.cov(wide, rowvar=False, aweights=w, ddof=0), atol=1e-13)
    truth = np.array([9.0, -3.0, 1.2])
    d = points - truth
    assert weighted_rmse(points, w, truth) == pytest.approx(
        np.sqrt(w @ np.einsum("ij,ij->i", d, d)), rel=1e-13
    )
    logw = np.log(w) + 3.0
    logw[7] = -np.inf  # a dead particle
    ll = rng.normal(size=5000) * 4.0
    ll[11] = -1000.0  # far below the rest: a weight of 0, not a subnormal
    new, log_ev, ess, weights = reweighted(logw, ll)
    np.testing.assert_array_equal(new, logw + ll)
    assert log_ev == pytest.approx(logsumexp(logw + ll) - logsumexp(logw), rel=1e-12)
    scaled = np.exp(new - new.max())
    assert ess == pytest.approx(effective_sample_size(scaled / scaled.sum()), rel=1e-12)
    # the normalised weights, from the same exponentials: NumPy's to the last bits
    np.testing.assert_allclose(weights, scaled / scaled.sum(), rtol=1e-14, atol=0)
    assert weights[7] == 0.0 and weights[11] == 0.0 and weights.sum() == pytest.approx(1.0)


def test_a_move_budget_keeps_the_exact_grid_posterior(sensor):
    """search.move_history: with a history longer than the budget a sweep moves a random share
    budget / entries of the particles. Each particle is still a draw of the posterior: the
    filter with a budget of 2 entries (a share of 1/3 once all six readings are in) matches the
    exact grid posterior as the full sweep does, and proposes only that share each sweep."""
    data = _readings(sensor)
    grid_mean, grid_sd = _grid_posterior(sensor, data)
    pf = ParticleFilter(
        planar_prior(u=2.0),
        sensor,
        n_particles=20_000,
        seed=7,
        resample_threshold=1.0,
        mcmc_steps=3,
        move_history=2,
    )
    for pos, z in data:
        pf.update(pos, z)
    assert pf._move_share() == pytest.approx(2 / 6)
    np.testing.assert_array_less(np.abs(pf.mean() - grid_mean), 0.2 * grid_sd)
    np.testing.assert_allclose(np.sqrt(np.diag(pf.cov())), grid_sd, rtol=0.2)
    _, proposed = pf._mh_sweep(pf._move_share())
    assert abs(proposed - pf.n / 3) < 5 * np.sqrt(pf.n * (1 / 3) * (2 / 3))


def test_a_move_budget_above_the_history_changes_nothing(sensor):
    """Below the budget the sweeps and the random stream are the unbudgeted filter's, draw for
    draw: no study's search (at most a few hundred readings) changes with the default."""
    data = _readings(sensor)
    runs = []
    for budget in (None, len(data), 10_000):
        pf = ParticleFilter(planar_prior(u=2.0), sensor, n_particles=2_000, seed=3,
                            resample_threshold=1.0, move_history=budget)  # fmt: skip
        for pos, z in data:
            pf.update(pos, z)
        runs.append(pf.theta.copy())
    for theta in runs[1:]:
        np.testing.assert_array_equal(theta, runs[0])
    with pytest.raises(DceeInputError, match=r"search\.move_history"):
        ParticleFilter(planar_prior(u=2.0), sensor, n_particles=100, move_history=0)
