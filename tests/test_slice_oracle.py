"""The slice oracle (studies/slice_oracle.py, issue 78): its held averages against a hand
calculation, its mixture over phases against the single-field likelihood where every phase is
the same, and the release found from readings simulated on a known field."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np

from dcee.models import Sensor
from dcee.simulation.lbm3d import SolverPlume3dTruth
from dcee.simulation.playback import PlaybackTruth

ROOT = Path(__file__).resolve().parent.parent


def _oracle():
    spec = importlib.util.spec_from_file_location("slice_oracle", ROOT / "studies/slice_oracle.py")
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(module)
    return module


def _truth(values: np.ndarray, q: float = 2.0) -> SolverPlume3dTruth:
    """A canonical recording (T, ny, nx, nz) on x ∈ [-10, 30], y ∈ [-10, 10], z ∈ {0, 2, 4, 6}
    m, frames 1 s apart, moved to a source at (20, 25, 0) with the wind from −x (blowing +x)
    at the reference speed, read on the plane z = 3 m."""
    t = np.arange(values.shape[0], dtype=float)
    x = np.linspace(-10.0, 30.0, values.shape[2])
    y = np.linspace(-10.0, 10.0, values.shape[1])
    z = np.array([0.0, 2.0, 4.0, 6.0])
    rec = PlaybackTruth(values, t, x, y, z, "linear", loop=True)
    return SolverPlume3dTruth(rec, np.array([20.0, 25.0, 0.0]), 0.0, q, 1.0, math.pi, 0.0, 0.0, 3.0)


def test_held_averages_are_the_window_means_of_the_plane_times_the_rate():
    oracle = _oracle()
    frames = 6
    values = np.broadcast_to(
        np.arange(frames, dtype=float)[:, None, None, None] * np.array([1.0, 1.0, 3.0, 5.0]),
        (frames, 5, 9, 4),
    ).copy()  # the plane z = 3 m lies halfway between the levels 2 m (×1) and 4 m (×3): ×2
    truth = _truth(values, q=2.0)
    got = oracle.held_averages(truth, average=3.0, response_time=0.0)
    # frame t averages frames t-2, t-1, t (looped), times 2 (height) times q = 2
    expected = [np.mean([(t - k) % frames for k in range(3)]) * 2.0 * 2.0 for t in range(frames)]
    np.testing.assert_allclose(got[:, 0, 0], expected)
    np.testing.assert_allclose(got, got[:, :1, :1] * np.ones((1, 5, 9)))


def _bump(frames: int) -> np.ndarray:
    """A stationary plume: Gaussian across the wind, rising downwind of the source, every frame
    the same, g/m³ for the unit rate."""
    x = np.linspace(-10.0, 30.0, 81)[None, :, None]
    y = np.linspace(-10.0, 10.0, 41)[:, None, None]
    z = np.array([0.0, 2.0, 4.0, 6.0])[None, None, :]
    sigma = 0.5 + 0.15 * np.maximum(x, 0.0)
    field = np.where(x > 0, 0.02 / sigma**2 * np.exp(-0.5 * (y**2 + (z - 1) ** 2) / sigma**2), 0.0)
    return np.broadcast_to(field, (frames, *field.shape)).copy()


def _readings(
    truth: SolverPlume3dTruth, sensor: Sensor, seed: int
) -> tuple[np.ndarray, np.ndarray]:
    """Readings of ``sensor`` over a lawnmower 4-16 m downwind of the source on the plane."""
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(24.0, 37.0, 1.0), np.arange(21.0, 30.0, 1.0))
    positions = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, 3.0)])
    conc = truth.field(positions, 0.0)
    return positions, sensor.simulate(conc, rng)


def test_the_mixture_of_identical_phases_is_the_likelihood_of_the_one_field():
    oracle = _oracle()
    truth = _truth(_bump(8))
    sensor = Sensor(threshold=5e-4, pd=1.0)
    fields = oracle.held_averages(truth, 0.0, 0.0)
    positions, readings = _readings(truth, sensor, 1)
    low, high = np.zeros(3), np.array([50.0, 50.0, 5.0])
    args = (sensor, fields, positions, readings, low, high, 0.5, (6.0, 4.0, 3.0))
    mixture = oracle.oracle_posterior(truth, *args, 8)
    single = oracle.oracle_posterior(truth, *args, 0)
    for key in ("rmse", "error_along", "error_across", "sd_along", "sd_across"):
        assert math.isclose(mixture[key], single[key], rel_tol=1e-9, abs_tol=1e-12), key


def test_the_oracle_finds_the_release_from_readings_of_a_known_field():
    """Readings simulated from the field itself: the posterior holds the truth and lies within
    a metre of it, for every one of five seeds (statistics of simulated data)."""
    oracle = _oracle()
    truth = _truth(_bump(4))
    sensor = Sensor(threshold=5e-4, pd=1.0)
    fields = oracle.held_averages(truth, 0.0, 0.0)
    low, high = np.zeros(3), np.array([50.0, 50.0, 5.0])
    for seed in range(5):
        positions, readings = _readings(truth, sensor, seed)
        post = oracle.oracle_posterior(
            truth, sensor, fields, positions, readings, low, high, 0.25, (6.0, 4.0, 3.0), 4
        )
        assert post["truth_in_95"], (seed, post)
        assert post["rmse"] < 1.0, (seed, post)


def test_an_offset_release_is_placed_where_the_readings_came_from():
    """Readings of the source at (20, 25); the oracle told the release is 2 m further downwind
    and 1 m to the wind's left: its posterior puts it back, 2 m upwind and 1 m right (the sign
    of every offset it reports)."""
    oracle = _oracle()
    field = _bump(4)
    truth = _truth(field)
    sensor = Sensor(threshold=5e-4, pd=1.0)
    positions, readings = _readings(truth, sensor, 7)
    told = _truth(field)
    told.source = np.array([22.0, 26.0, 0.0])  # downwind is +x, the wind's left +y
    fields = oracle.held_averages(told, 0.0, 0.0)
    post = oracle.oracle_posterior(
        told, sensor, fields, positions, readings, np.zeros(3), np.array([50.0, 50.0, 5.0]),
        0.25, (6.0, 4.0, 3.0), 4,
    )  # fmt: skip
    assert abs(post["error_along"] + 2.0) < 0.5 and abs(post["error_across"] + 1.0) < 0.5, post


def test_the_gaussian_plume_probe_carries_the_release_rate_and_is_zero_upwind():
    """Through a crosswind plane above the ground the reflected Gaussian plume carries q / u
    (mass conserved); on its axis at the release height it is the textbook value; upwind 0."""
    import sys

    sys.path.insert(0, str(ROOT))
    from studies.slice_models import GAUSSIAN_SIGMA0, gaussian_plume

    theta = np.array([[0.0, 0.0, 1.0, 2.0, 4.0, 0.0, 1.0, 8.0]])  # q 2 g/s, u 4 m/s
    downwind = np.array([1.0, 0.0])
    ys, zs = np.meshgrid(np.linspace(-20, 20, 401), np.linspace(0, 30, 601))
    plane = np.column_stack([np.full(ys.size, 10.0), ys.ravel(), zs.ravel()])
    c = gaussian_plume(theta, plane, downwind, 0.2, 0.1)[0].reshape(ys.shape)
    flux = np.trapezoid(np.trapezoid(c, zs[:, 0], axis=0), ys[0])
    assert math.isclose(flux, 2.0 / 4.0, rel_tol=1e-3)
    sy, sz = math.hypot(GAUSSIAN_SIGMA0, 2.0), math.hypot(GAUSSIAN_SIGMA0, 1.0)
    axis = gaussian_plume(theta, np.array([[10.0, 0.0, 1.0]]), downwind, 0.2, 0.1)[0, 0]
    expected = 2.0 / (2 * math.pi * 4.0 * sy * sz) * (1.0 + math.exp(-2.0 / sz**2))
    assert math.isclose(axis, expected, rel_tol=1e-12)
    assert gaussian_plume(theta, np.array([[-3.0, 0.0, 1.0]]), downwind, 0.2, 0.1)[0, 0] == 0.0


def test_the_gamma_fluctuations_have_unit_mean_and_the_asked_intensity():
    """Equal-probability nodes of the unit-mean gamma: at intensity 1 the exponential's
    quantiles −ln(1 − q) exactly; mean 1 and standard deviation the intensity within what 48
    nodes hold of the tail (1.5 % and 7 %)."""
    import sys

    sys.path.insert(0, str(ROOT))
    from studies.slice_models import GAMMA_NODES, gamma_multipliers

    w, m = gamma_multipliers(1.0)
    q = (np.arange(GAMMA_NODES) + 0.5) / GAMMA_NODES
    np.testing.assert_allclose(m, -np.log1p(-q), rtol=1e-10)
    for intensity in (0.7, 1.0, 1.5):
        w, m = gamma_multipliers(intensity)
        assert math.isclose(w.sum(), 1.0) and np.all(np.diff(m) > 0)
        assert abs(w @ m - 1.0) < 0.015, intensity
        assert abs(math.sqrt(w @ (m - 1.0) ** 2) / intensity - 1.0) < 0.07, intensity


def _profile_truth(profile) -> SolverPlume3dTruth:  # type: ignore[no-untyped-def]
    """A stationary recording on a 0.1 m vertical grid whose column at every x > 0 is
    ``profile(z, x)`` (uniform across the wind), the source at z = 1 m, the plane at 3 m."""
    t = np.arange(2, dtype=float)
    x = np.linspace(-10.0, 30.0, 81)
    y = np.linspace(-10.0, 10.0, 5)
    z = np.arange(0.0, 12.0, 0.1)
    column = np.where(x[None, :, None] > 0, profile(z[None, None, :], x[None, :, None]), 0.0)
    values = np.broadcast_to(column, (2, len(y), len(x), len(z))).copy()
    rec = PlaybackTruth(values, t, x, y, z, "linear", loop=True)
    source = np.array([20.0, 25.0, 1.0])
    return SolverPlume3dTruth(rec, source, 1.0, 1.0, 1.0, math.pi, 0.0, 0.0, 3.0)


def test_the_tails_of_a_gaussian_profile_are_a_gaussians_and_a_heavier_tail_holds_more():
    """On a column that is a Gaussian about z̄ = 1.5 m, the plane's ratio to the release height
    is the Gaussian's (up to the 0.1 m grid's share of the spread); on one with an exponential
    tail above the centroid it is far larger than the Gaussian of the same z̄ and σ_z gives."""
    oracle = _oracle()

    def gaussian(z, x):  # type: ignore[no-untyped-def]
        s = 0.3 + 0.01 * np.maximum(x, 0.0)  # narrow enough that the ground cuts off none of it
        return np.exp(-0.5 * ((z - 1.5) / s) ** 2)

    for section in oracle.vertical_tails(_profile_truth(gaussian))["sections"]:
        plume, model = section["plane_over_release"], section["gaussian_plane_over_release"]
        assert abs(math.log(plume / model)) < 0.1, section  # ratios of e^-11 to e^-7

    def exponential(z, x):  # type: ignore[no-untyped-def]
        return np.exp(-np.abs(z - 1.5) / (0.2 + 0.05 * np.maximum(x, 0.0)))

    near = oracle.vertical_tails(_profile_truth(exponential))["sections"][0]
    assert near["plane_over_release"] > 5 * near["gaussian_plane_over_release"], near


def test_the_filter_replay_ends_where_the_search_it_replays_ended():
    """Told a search's readings in order, with the search's particles and seed, the scenario's
    filter (no planner) ends with the posterior the search ended with: the replay's RMSE about
    the truth is the search's own final RMSE (the height declared known, so both are
    horizontal)."""
    import sys
    from types import SimpleNamespace

    sys.path.insert(0, str(ROOT))
    from studies.slice_models import filter_replay

    from dcee.runs import run_episode
    from dcee.scenarios import load_scenario

    scenario = load_scenario("paper:1").with_overrides(
        **{"search.particles": 500, "search.hypotheses": 4, "search.budget": 60.0},
        dimensions=2,
    )
    result = run_episode(scenario, "infotaxis", 3)
    source = scenario.truth_theta()[:3]
    truth = SimpleNamespace(source=source, downwind=np.array([1.0, 0.0]), left=np.array([0.0, 1.0]))
    post = filter_replay(scenario, truth, result.records, 500, 3)
    assert math.isclose(post["rmse"], result.summary["final_rmse"], rel_tol=1e-9)
    assert post["candidates"] == 500
