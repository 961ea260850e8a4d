"""The wall-aware plume (:mod:`dcee.models.site_plume`) against independent references: the
closed-form planar plume in open terrain, the adjoint identity (a receptor field sampled at a
source equals the forward field sampled at the receptor), mass conservation of the wind round
walls, and a wall that shelters what lies behind it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import k0

from dcee.errors import DceeInputError
from dcee.models.site_plume import SitePlume, bernoulli, site_grid


def _open(h: float = 0.5, **kw: float) -> SitePlume:
    fluid, origin = site_grid((0.0, 0.0), (50.0, 50.0), h, lambda xy: np.zeros(len(xy), bool))
    return SitePlume(fluid, origin, h, **{"u": 4.0, "phi": 0.0, "zeta1": 1.0, "zeta2": 8.0, **kw})


def _theta(x: float, y: float, q: float) -> np.ndarray:
    return np.array([[x, y, 1.0, q, 4.0, 0.0, 1.0, 8.0]])


def test_bernoulli_function_limits() -> None:
    x = np.array([-50.0, -1.0, -1e-12, 0.0, 1e-12, 1.0, 50.0])
    b = bernoulli(x)
    assert b[3] == 1.0 and b[2] == pytest.approx(1.0) and b[4] == pytest.approx(1.0)
    assert b[5] == pytest.approx(1.0 / (math.e - 1.0))
    assert b[0] == pytest.approx(50.0) and b[6] == pytest.approx(50.0 * math.exp(-50.0))
    np.testing.assert_allclose(bernoulli(-x) - bernoulli(x), x, atol=1e-11)  # B(−x) = B(x) + x


def test_open_terrain_is_the_closed_form_planar_plume() -> None:
    """C = q/(2π K h) e^(U d / 2K) K0(κ r), κ² = U²/(4K²) + 1/(K τ), d the downwind offset."""
    plume = _open()
    s, q, k, u, tau = np.array([37.3, 12.2]), 5.0, 1.0, 4.0, 8.0
    kappa = math.sqrt(u**2 / (4 * k**2) + 1 / (k * tau))
    for d, c in ((2, 0), (5, 0), (10, 0), (20, 0), (10, 2), (10, 4), (20, 5)):
        p = np.r_[s + np.array([-d, c]), 1.0]  # the wind comes from +x: downwind is −x
        r = math.hypot(d, c)
        exact = (
            q / plume.layer_depth / (2 * math.pi * k) * math.exp(u * d / (2 * k)) * k0(kappa * r)
        )
        got = plume.concentration(_theta(*s, q), p[None])[0, 0]
        assert got == pytest.approx(exact, rel=0.02), (d, c)  # measured within 1.1 %


def test_receptor_fields_are_the_forward_solution_sampled_at_the_sensor() -> None:
    fluid, origin = site_grid(
        (0.0, 0.0), (50.0, 50.0), 0.5, lambda xy: (np.abs(xy[:, 0] - 20.5) <= 0.5) & (xy[:, 1] < 35)
    )
    plume = SitePlume(fluid, origin, 0.5, u=4.0, phi=0.0, zeta1=1.0, zeta2=8.0)
    source, q = np.array([37.6, 12.3]), 3.0
    forward = plume.field(source, q)
    for p in ((30.25, 12.25), (10.25, 40.25), (19.25, 20.25), (45.75, 5.25)):
        i = int((p[1] - origin[1]) / 0.5)
        j = int((p[0] - origin[0]) / 0.5)  # a cell centre: the forward field there exactly
        got = plume.concentration(_theta(*source, q), np.array([[p[0], p[1], 4.0]]))[0, 0]
        assert got == pytest.approx(forward[i, j], rel=1e-6)  # fields are kept in float32


def test_the_wind_goes_round_walls_without_crossing_them_and_is_conserved() -> None:
    wall = lambda xy: (np.abs(xy[:, 0] - 20.5) <= 0.5) & (xy[:, 1] < 35)  # noqa: E731
    fluid, origin = site_grid((0.0, 0.0), (50.0, 50.0), 0.5, wall)
    plume = SitePlume(fluid, origin, 0.5, u=4.0, phi=0.0, zeta1=1.0, zeta2=8.0)
    fu, fv = plume.face_u, plume.face_v
    # no face of a wall cell carries wind
    walls = ~fluid
    assert np.all(fu[:, :-1][walls] == 0) and np.all(fu[:, 1:][walls] == 0)
    assert np.all(fv[:-1][walls] == 0) and np.all(fv[1:][walls] == 0)
    # every air cell: as much air out as in (to the solver's precision)
    div = (fu[:, 1:] - fu[:, :-1]) + (fv[1:] - fv[:-1])
    assert np.abs(div[fluid]).max() < 1e-8
    # without walls the free wind everywhere (from +x: towards −x); 25 m from the wall's end
    # nearly it (potential flow round a plate disturbs it as far as the plate is long); round
    # the end it turns north
    np.testing.assert_allclose(_open().face_u, -4.0, atol=1e-9)
    np.testing.assert_allclose(_open().face_v, 0.0, atol=1e-9)
    i_far, j_far = int((45.0 - origin[1]) / 0.5), int((45.0 - origin[0]) / 0.5)
    assert -4.0 < fu[i_far, j_far] < -3.4  # measured −3.68
    j_wall = int((20.5 - origin[0]) / 0.5)
    i_end = int((35.0 - origin[1]) / 0.5)
    assert fv[i_end - 4, j_wall + 3] > 0.5  # up the wall's east face towards its end


def test_a_wall_shelters_what_lies_behind_it() -> None:
    wall = lambda xy: (np.abs(xy[:, 0] - 20.5) <= 0.5) & (xy[:, 1] < 35)  # noqa: E731
    fluid, origin = site_grid((0.0, 0.0), (50.0, 50.0), 0.5, wall)
    walled = SitePlume(fluid, origin, 0.5, u=4.0, phi=0.0, zeta1=1.0, zeta2=8.0)
    open_ = _open()
    theta = _theta(37.5, 12.5, 5.0)
    behind = np.array([[15.0, 12.5, 4.0], [10.0, 12.5, 4.0]])
    ahead = np.array([[25.0, 12.5, 4.0]])
    c_w, c_o = walled.concentration(theta, behind)[0], open_.concentration(theta, behind)[0]
    assert np.all(c_w < 0.05 * c_o)
    # the wind carries it round the wall's north end instead
    round_end = np.array([[15.0, 40.0, 4.0]])
    assert (
        walled.concentration(theta, round_end)[0, 0]
        > 3 * open_.concentration(theta, round_end)[0, 0]
    )
    # a source inside a wall releases nothing; distances are clamped
    conc, _ = walled.concentration_distance(_theta(20.5, 10.0, 5.0), ahead)
    assert conc[0, 0] == 0.0
    _, d = walled.concentration_distance(_theta(25.0, 12.5, 5.0), np.array([[25.0, 12.5, 1.0]]))
    assert d[0, 0] == pytest.approx(0.1)


def test_refuses_a_model_without_diffusion() -> None:
    fluid = np.ones((10, 10), bool)
    with pytest.raises(DceeInputError):
        SitePlume(fluid, (0.0, 0.0), 1.0, u=4.0, phi=0.0, zeta1=0.0, zeta2=8.0)


def test_the_field_cache_evicts_the_least_recent_and_keeps_the_numbers(monkeypatch) -> None:
    import dcee.models.receptor_fields as module

    theta = np.vstack([_theta(30.0 + k, 12.0 + 2 * k, 1.0 + k) for k in range(5)])
    positions = np.array([[10.0 + 4 * k, 10.0 + k, 4.0] for k in range(7)])
    expected = _open().concentration(theta, positions)
    monkeypatch.setattr(module, "FIELD_CACHE", 4)  # two positions per gather, rows reused
    small = _open()
    np.testing.assert_array_equal(small.concentration(theta, positions), expected)
    assert len(small._slots) == 4  # rows reused, the bank never grown
    np.testing.assert_array_equal(small.concentration(theta, positions[::-1]), expected[:, ::-1])


def test_the_compiled_gather_is_its_numpy_reference() -> None:
    """The kernel that reads receptor fields at the particles' cells against the NumPy
    reference (einsum over a fancy-indexed gather), and the distances against einsum's."""
    from dcee.models.plume_kernels import gather_receptor_fields
    from dcee.models.site_plume import gather_receptor_fields_reference

    plume = _open()
    rng = np.random.default_rng(7)
    theta = np.column_stack(
        [rng.uniform(-5, 55, (700, 2)), np.ones(700), rng.uniform(0.5, 5, 700), np.zeros((700, 4))]
    )
    positions = np.column_stack([rng.uniform(0, 50, (9, 2)), np.full(9, 2.0)])
    conc, dist = plume.concentration_distance(theta, positions)
    rows = np.array([plume._slot(p[:2]) for p in positions])
    cells, w = plume.weights(theta[:, :2])
    reference = gather_receptor_fields_reference(plume._bank, rows, cells, w)
    out = np.empty_like(reference)
    gather_receptor_fields(plume._bank, rows, cells, w, out)
    np.testing.assert_allclose(out, reference, rtol=1e-14, atol=1e-300)
    np.testing.assert_allclose(conc, reference * theta[:, 3:4] / plume.layer_depth, rtol=1e-14)
    assert np.all(conc[np.all(w == 0, axis=1)] == 0)  # off the grid: clean air
    d = positions[None, :, :] - theta[:, None, :3]
    expected = np.maximum(np.sqrt(np.einsum("nki,nki->nk", d, d)), plume.min_distance)
    np.testing.assert_allclose(dist, expected, rtol=1e-15)
