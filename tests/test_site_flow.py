"""The wind round a site's walls (:mod:`dcee.models.site_flow`) against limiting cases and the
physics of a bluff body: the free wind untouched where nothing stands in it, no divergence in the
air and nothing through a wall, and behind a wall across the wind a recirculating wake that the
mass-consistent (potential) wind does not have."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcee.models.site_flow import Projection, mass_consistent_wind, wake_wind
from dcee.models.site_plume import SitePlume

H = 0.5


def _wall_site() -> np.ndarray:
    """(60, 60) cells of 0.5 m (30 m square): a wall 1 m thick, 10 m long across a wind along +x,
    at x = 10-11 m, y = 10-20 m."""
    fluid = np.ones((60, 60), bool)
    fluid[20:40, 20:22] = False
    return fluid


@pytest.fixture
def stand_in_wake(monkeypatch):
    """The wake solver replaced by a recording stand-in (the mass-consistent wind), so a
    scenario's wind costs nothing; the list of (viscosity, faces) it was asked for. The site
    caches are emptied before and after: no stand-in wind outlives the test."""
    from dcee.models import site_flow
    from dcee.models.site_flow import WAKE_VISCOSITY
    from dcee.scenarios import builders

    solved = []

    def recording_wake_wind(fluid, h, free, viscosity=WAKE_VISCOSITY, **_):
        faces = site_flow.mass_consistent_wind(fluid, h, free)
        solved.append((viscosity, faces))
        return faces

    caches = (builders._site_wind, builders._wall_plume)
    for cache in caches:
        cache.cache_clear()
    monkeypatch.setattr(site_flow, "wake_wind", recording_wake_wind)
    yield solved
    for cache in caches:
        cache.cache_clear()


def _divergence(fu: np.ndarray, fv: np.ndarray) -> np.ndarray:
    return fu[:, 1:] - fu[:, :-1] + fv[1:, :] - fv[:-1, :]


@pytest.mark.parametrize("free", [(4.0, 0.0), (-1.5, 2.5)])
def test_open_terrain_keeps_the_free_wind(free: tuple[float, float]) -> None:
    fluid = np.ones((30, 40), bool)
    for fu, fv in (
        mass_consistent_wind(fluid, H, np.array(free)),
        wake_wind(fluid, H, np.array(free)),
    ):
        np.testing.assert_allclose(fu, free[0], atol=1e-9)
        np.testing.assert_allclose(fv, free[1], atol=1e-9)


def test_projection_removes_divergence_and_wall_flux() -> None:
    fluid = _wall_site()
    rng = np.random.default_rng(3)
    project = Projection(fluid, H)
    fu, fv = project(rng.normal(size=(60, 61)), rng.normal(size=(61, 60)))
    assert np.abs(_divergence(fu, fv)[fluid]).max() < 1e-9
    # a face beside a wall cell carries nothing
    assert np.all(fu[20:40, 20:23] == 0.0) and np.all(fv[20:41, 20:22] == 0.0)
    # projecting twice changes nothing (a projection)
    again = project(fu, fv)
    np.testing.assert_allclose(again[0], fu, atol=1e-9)
    np.testing.assert_allclose(again[1], fv, atol=1e-9)


def test_wake_behind_a_wall_across_the_wind() -> None:
    fluid = _wall_site()
    free = np.array([3.0, 0.0])
    fu, fv = wake_wind(fluid, H, free)
    assert np.abs(_divergence(fu, fv)[fluid]).max() < 1e-9
    centre = 0.5 * (fu[30, 1:] + fu[30, :-1])  # x-velocity at cell centres, y = 15.25 m
    behind = centre[23:30]  # 0.5-4 m behind the wall's lee face
    assert behind.min() < -0.02 * free[0]  # the air turns back towards the wall
    assert np.all(centre[:18] > 0)  # in front it still blows along +x, slowing
    assert centre[10] < free[0]
    # the potential wind has no wake: it blows away from the wall's lee face
    pu, _ = mass_consistent_wind(fluid, H, free)
    assert np.all(0.5 * (pu[30, 24:31] + pu[30, 23:30]) > 0)
    # in front of the wall the air turns aside, away from its middle (v < 0 below, > 0 above)
    assert fv[18, 17] < 0 < fv[42, 17]


def test_wake_wind_carries_gas_from_the_lee_back_to_the_wall() -> None:
    """A release 2 m behind the wall: the wake's back-flow carries gas to the wall's lee face,
    the potential wind carries it away."""
    fluid = _wall_site()
    origin = (0.0, 0.0)
    source = np.array([13.0, 15.0])
    lee_face = np.array([[11.5, 15.0, 1.0]])
    theta = np.array([[*source, 1.0, 1.0, 3.0, math.pi, 1.0, math.inf]])  # wind from 180°: +x
    at_wall = {}
    for wind in ("wake", "potential"):
        plume = SitePlume(fluid, origin, H, u=3.0, phi=math.pi, zeta1=1.0, zeta2=1e9, wind=wind)
        at_wall[wind] = float(plume.concentration(theta, lee_face)[0, 0])
    assert at_wall["wake"] > 3.0 * at_wall["potential"]


def _reattachment(fluid: np.ndarray, viscosity: float) -> float:
    """m behind the wall's lee face where the centre line's wind blows downwind again."""
    fu, _ = wake_wind(fluid, H, np.array([3.0, 0.0]), viscosity=viscosity)
    centre = 0.5 * (fu[30, 1:] + fu[30, :-1])[22:]  # from the lee face on
    back = np.flatnonzero(centre < 0)
    return H * (back.max() + 1) if len(back) else 0.0


def test_a_lower_eddy_viscosity_gives_a_longer_wake() -> None:
    """Below the onset of shedding a bluff body's recirculation lengthens as its Reynolds number
    U L / ν_t grows (about linearly for a steady wake): the wall (L = 10 m) in a 3 m/s wind at
    ν_t = 10 m²/s (Re 3) and 2 m²/s (Re 15), both steady. (Near and past the onset, ν_t = 1, the
    time-mean bubble shortens again as the wake sheds; not asserted.)"""
    fluid = _wall_site()
    viscous, lower = (_reattachment(fluid, nu) for nu in (10.0, 2.0))
    assert 0.0 < viscous < 0.6 * lower


def test_the_scenarios_eddy_viscosity_reaches_the_wake_wind(stand_in_wake) -> None:
    """The scenario's ``estimator.wall_viscosity`` (unset: WAKE_VISCOSITY) is the viscosity
    the site plume's wind is solved with, and the plume's faces are that solve's. The solver is
    replaced by a recording stand-in (the solves themselves are tested above)."""
    from dcee.models import site_flow
    from dcee.models.site_flow import WAKE_VISCOSITY
    from dcee.scenarios import load_scenario

    solved = stand_in_wake
    sc = load_scenario("site:wall").with_overrides(**{"estimator.plume": "walls"})
    assert sc.wall_viscosity == WAKE_VISCOSITY  # unset: the default
    default = sc.make_plume()
    other = sc.with_overrides(**{"estimator.wall_viscosity": 0.5}).make_plume()
    assert [v for v, _ in solved] == [WAKE_VISCOSITY, 0.5]
    assert default.face_u is solved[0][1][0] and other.face_u is solved[1][1][0]
    fluid = default.fluid
    assert np.array_equal(
        default.face_u,
        site_flow.mass_consistent_wind(fluid, default.resolution, _free(default))[0],
    )


def _free(plume: SitePlume) -> np.ndarray:
    """(2,) m/s: the free wind of a site plume (it blows towards −(cos φ, sin φ))."""
    u, phi = plume.wind
    return -u * np.array([math.cos(phi), math.sin(phi)])


def test_a_learned_eddy_viscosity_gives_each_member_its_own_wake(stand_in_wake) -> None:
    """``estimator.learn.wall_viscosity``: each member of the bank is solved in the wake wind
    of its own ν_t (one solve per ν_t, shared by the members that differ only in K), the
    preferred member in the fixed one's."""
    from dcee.scenarios import load_scenario

    solved = stand_in_wake
    sc = load_scenario("site:wall").with_overrides(
        **{
            "estimator.plume": "walls",
            "estimator.likelihood": "fluctuation",
            "estimator.wall_viscosity": 0.7,
            "estimator.learn": {"wall_diffusivity": [1.0, 3.0], "wall_viscosity": [0.7, 0.15]},
        }
    )
    assert sc.reading_models[:4] == (
        "fluctuation",
        "fluctuation[wall_diffusivity=1,wall_viscosity=0.15]",
        "fluctuation[wall_diffusivity=3,wall_viscosity=0.7]",
        "fluctuation[wall_diffusivity=3,wall_viscosity=0.15]",
    )
    plumes = [sc.make_plume(m) for m in sc.reading_models[:4]]
    assert sorted({v for v, _ in solved}) == [0.15, 0.7] and len(solved) == 2
    by_nu = {v: faces for v, faces in solved}
    assert [p.zeta1 for p in plumes] == [1.0, 1.0, 3.0, 3.0]
    for plume, nu in zip(plumes, (0.7, 0.15, 0.7, 0.15), strict=True):
        assert plume.face_u is by_nu[nu][0]
