import math

import numpy as np
import pytest

from dcee import DceeInputError, isotropic_concentration
from dcee.models.plume import MIN_DISTANCE, isotropic_concentration_reference
from tests.helpers import random_theta


def test_hand_calculation_without_wind():
    # q = 5, u = 0, ζ1 = 1, ζ2 = 8: λ = √8; point 5 m away (3-4-5 triangle).
    theta = np.array([[0, 0, 0, 5.0, 0.0, 0.0, 1.0, 8.0]])
    c = isotropic_concentration(theta, np.array([[3.0, 4.0, 0.0]]))[0, 0]
    expected = 5.0 / (4 * math.pi * 1.0 * 5.0) * math.exp(-5.0 / math.sqrt(8.0))
    assert c == pytest.approx(expected, rel=1e-13)


def test_hand_calculation_with_wind():
    # q = 2, u = 3, φ = 30°, ζ1 = 0.5, ζ2 = 4; source (1, 2, 1); point (-2, 0, 3).
    q, u, phi, z1, z2 = 2.0, 3.0, math.radians(30), 0.5, 4.0
    theta = np.array([[1.0, 2.0, 1.0, q, u, phi, z1, z2]])
    dx, dy, dz = -3.0, -2.0, 2.0
    r = math.sqrt(dx * dx + dy * dy + dz * dz)
    lam = math.sqrt(z1 * z2 / (1 + u * u * z2 / (4 * z1)))
    expected = (
        q
        / (4 * math.pi * z1 * r)
        * math.exp(-r / lam)
        * math.exp(-dx * u * math.cos(phi) / (2 * z1))
        * math.exp(-dy * u * math.sin(phi) / (2 * z1))
    )
    assert isotropic_concentration(theta, np.array([[-2.0, 0.0, 3.0]]))[0, 0] == pytest.approx(
        expected, rel=1e-13
    )


def test_plume_extends_towards_minus_wind_direction():
    for phi_deg in (0, 90, 200):
        phi = math.radians(phi_deg)
        theta = np.array([[0, 0, 0, 5.0, 4.0, phi, 1.0, 8.0]])
        d = np.array([math.cos(phi), math.sin(phi), 0.0])
        c = isotropic_concentration(theta, np.stack([-5 * d, 5 * d]))[0]
        # Symmetric points: the ratio is exactly the advection factor e^{2·5u/(2ζ1)} = e^{20}.
        assert c[0] / c[1] == pytest.approx(math.exp(20.0), rel=1e-9)


def test_pure_diffusion_limit():
    # u = 0 and ζ2 → ∞: λ → ∞, C → q / (4π ζ1 r).
    theta = np.array([[0, 0, 0, 3.0, 0.0, 0.0, 0.7, 1e14]])
    c = isotropic_concentration(theta, np.array([[2.0, 0.0, 0.0]]))[0, 0]
    assert c == pytest.approx(3.0 / (4 * math.pi * 0.7 * 2.0), rel=1e-6)


def test_distance_is_clamped_at_the_source():
    theta = np.array([[1, 1, 1, 5.0, 4.0, 0.3, 1.0, 8.0]])
    at_source = isotropic_concentration(theta, np.array([[1.0, 1.0, 1.0]]))[0, 0]
    assert np.isfinite(at_source)
    c_min = 5.0 / (4 * math.pi * MIN_DISTANCE) * math.exp(-MIN_DISTANCE / math.sqrt(8 / 33))
    assert at_source == pytest.approx(c_min, rel=1e-12)


def test_compiled_matches_reference():
    rng = np.random.default_rng(3)
    n, m = 300, 17
    theta = random_theta(n, rng)
    pos = np.column_stack([rng.uniform(0, 50, m), rng.uniform(0, 50, m), np.full(m, 4.0)])
    fast = isotropic_concentration(theta, pos)
    ref = isotropic_concentration_reference(theta, pos)
    assert fast.shape == (n, m)
    np.testing.assert_allclose(fast, ref, rtol=1e-9, atol=0)


def test_wrong_shapes_are_rejected():
    with pytest.raises(DceeInputError, match="theta"):
        isotropic_concentration(np.zeros((3, 7)), np.zeros((2, 3)))
    with pytest.raises(DceeInputError, match="positions"):
        isotropic_concentration(np.zeros((3, 8)), np.zeros((2, 2)))


def test_backflow_by_hand_upwind_downwind_and_crosswind():
    """w = 0.05: the time mean over a wind from φ (95 % of the time) and from φ + π (5 %).
    At points 5 m up- and downwind the two plumes swap (one factor e^{20} apart); crosswind
    both plumes agree, so nothing changes; the release rate keeps its meaning."""
    from dcee.models.plume import IsotropicPlume

    w = 0.05
    phi = math.radians(200)
    theta = np.array([[0, 0, 0, 5.0, 4.0, phi, 1.0, 8.0]])
    d = np.array([math.cos(phi), math.sin(phi), 0.0])
    cross = np.array([-math.sin(phi), math.cos(phi), 0.0])
    pts = np.stack([-5 * d, 5 * d, 3 * cross])
    lam = math.sqrt(1.0 * 8.0 / (1 + 16.0 * 8.0 / 4.0))
    down = 5.0 / (4 * math.pi * 5.0) * math.exp(-5.0 / lam + 10.0)  # 5 m downwind, no backflow
    up = down * math.exp(-20.0)
    c = IsotropicPlume(backflow=w).concentration(theta, pts)[0]
    assert c[0] == pytest.approx((1 - w) * down + w * up, rel=1e-12)
    assert c[1] == pytest.approx((1 - w) * up + w * down, rel=1e-12)
    assert c[1] / c[0] == pytest.approx(w / (1 - w), rel=1e-7)  # upwind / downwind
    assert c[2] == pytest.approx(isotropic_concentration(theta, pts[2:])[0, 0], rel=1e-13)
    with pytest.raises(DceeInputError, match="backflow"):
        IsotropicPlume(backflow=0.6)


def test_disc_source_against_a_dense_disc_integral_and_the_point_limit():
    """source radius R: the seven-point rule against the uniform disc integrated densely
    (200 rings × 400 angles): within 12 % at 1.5 R, 5 % at 2 R, 1.5 % at 4 R, a factor 2
    inside the disc (measured: 50 %, 10 %, 4 %, 1.2 %; the rule smooths the disc's own
    singular near field, well inside a log-normal reading's spread); a
    vanishing radius is the point source; far downwind the crosswind integral (the mass flux)
    is the point source's."""
    from dcee.models.plume import IsotropicPlume

    theta = np.array([[0, 0, 1.0, 5.0, 3.0, math.radians(30), 1.0, 8.0]])
    radius = 1.0
    rho = (np.arange(200) + 0.5) / 200 * radius
    ang = (np.arange(400) + 0.5) / 400 * 2 * math.pi
    rr, aa = np.meshgrid(rho, ang, indexing="ij")
    weights = (rr / rr.sum()).ravel()  # uniform over the disc: weight ∝ ring radius
    subs = np.repeat(theta, weights.size, axis=0)
    subs[:, 0] += (rr * np.cos(aa)).ravel()
    subs[:, 1] += (rr * np.sin(aa)).ravel()
    rng = np.random.default_rng(0)
    for distance, tol in ((0.5, 1.0), (1.5, 0.12), (2.0, 0.05), (4.0, 0.015)):
        a = rng.uniform(0, 2 * math.pi, 12)
        pts = np.column_stack([distance * np.cos(a), distance * np.sin(a), np.full(12, 1.0)])
        dense = weights @ isotropic_concentration(subs, pts, 1e-3)
        rule = IsotropicPlume(radius=radius).concentration(theta, pts)[0]
        np.testing.assert_allclose(rule, dense, rtol=tol)
    pts = np.array([[-3.0, -2.0, 1.0], [5.0, 1.0, 2.0]])
    np.testing.assert_allclose(
        IsotropicPlume(radius=1e-9).concentration(theta, pts),
        isotropic_concentration(theta, pts),
        rtol=1e-12,
    )
    phi = math.radians(30)
    ys = np.linspace(-40, 40, 4001)
    down = -30.0 * np.array([math.cos(phi), math.sin(phi)])
    cross = np.array([-math.sin(phi), math.cos(phi)])
    line = np.column_stack([down[0] + ys * cross[0], down[1] + ys * cross[1], np.ones_like(ys)])
    point = np.trapezoid(isotropic_concentration(theta, line)[0], ys)
    disc = np.trapezoid(IsotropicPlume(radius=radius).concentration(theta, line)[0], ys)
    assert disc == pytest.approx(point, rel=0.02)


def test_ground_image_and_vertical_ratio_by_hand():
    """The ground adds the release's mirror image below z = 0; the vertical ratio a divides
    every height (and the release rate) by a: hand formulas of the paper's plume."""
    from dcee.models.plume import IsotropicPlume

    q, u, phi, z1, z2 = 2.0, 3.0, math.radians(30), 0.5, 40.0
    sx, sy, sz = 1.0, 2.0, 1.5
    p = np.array([-3.0, 0.5, 2.5])
    lam = math.sqrt(z1 * z2 / (1 + u * u * z2 / (4 * z1)))

    def paper(height_offset: float, a: float) -> float:
        dx, dy = p[0] - sx, p[1] - sy
        r = math.sqrt(dx * dx + dy * dy + (height_offset / a) ** 2)
        adv = (dx * u * math.cos(phi) + dy * u * math.sin(phi)) / (2 * z1)
        return q / a / (4 * math.pi * z1 * r) * math.exp(-r / lam - adv)

    theta = np.array([[sx, sy, sz, q, u, phi, z1, z2]])
    for a, g in ((1.0, 1.0), (0.66, 0.0), (0.66, 1.0), (1.5, 0.5)):
        expected = paper(p[2] - sz, a) + g * paper(p[2] + sz, a)
        got = IsotropicPlume(vertical=a, ground=g).concentration(theta, p[None])[0, 0]
        assert got == pytest.approx(expected, rel=1e-12)
        ref = isotropic_concentration_reference(theta, p[None], vertical=a, ground=g)[0, 0]
        assert ref == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("a", [1.0, 0.66])
def test_ground_keeps_the_flux_above_it(a):
    """Mass conservation, a limiting case: far downwind of a release on the ground, with no
    decay (ζ2 → ∞), the flux u ∫∫ C dy dz through a crosswind half-plane above the ground is
    the release rate, whatever the vertical ratio, when the ground reflects; half of it when
    it does not (the other half passes below z = 0)."""
    from dcee.models.plume import IsotropicPlume

    q, u = 3.0, 4.0
    theta = np.array([[0.0, 0.0, 0.0, q, u, math.pi, 0.4, 1e9]])  # wind towards +x
    ys = np.linspace(-12.0, 12.0, 241)
    zs = np.linspace(0.0, 12.0, 601)
    yy, zz = np.meshgrid(ys, zs, indexing="ij")
    plane = np.column_stack([np.full(yy.size, 40.0), yy.ravel(), zz.ravel()])
    for ground, share in ((1.0, 1.0), (0.0, 0.5)):
        c = IsotropicPlume(vertical=a, ground=ground).concentration(theta, plane)[0]
        flux = u * np.trapezoid(np.trapezoid(c.reshape(yy.shape), zs, axis=1), ys)
        assert flux == pytest.approx(share * q, rel=0.02)


@pytest.mark.parametrize(
    "shape",
    [
        {"meander_z": 0.1},
        {"meander": 0.15, "meander_z": 0.1, "ground": 1.0, "vertical": 0.66},
        {"meander": 0.15, "meander_z": 0.3, "backflow": 0.05, "radius": 1.0, "decay": 0.5},
    ],
)
def test_compiled_matches_reference_with_vertical_meander(shape):
    from dcee.models.plume import IsotropicPlume

    rng = np.random.default_rng(5)
    theta = random_theta(200, rng)
    theta[:, 2] = rng.uniform(0.0, 3.0, len(theta))
    pos = rng.uniform([0, 0, 0], [50, 50, 6], size=(23, 3))
    fast = IsotropicPlume(**shape).concentration(theta, pos)
    ref = isotropic_concentration_reference(theta, pos, **shape)
    np.testing.assert_allclose(fast, ref, rtol=1e-9, atol=1e-300)


def test_vertical_meander_by_hand():
    """Downwind of the source the height offset is compressed by f_z = 1/√(1 + i_z² d u/(2ζ1))
    and the concentration multiplied by it; upwind nothing changes."""
    from dcee.models.plume import IsotropicPlume

    q, u, z1, z2, iz = 2.0, 3.0, 0.5, 40.0, 0.2
    theta = np.array([[0.0, 0.0, 1.0, q, u, math.pi, z1, z2]])  # wind towards +x
    lam = math.sqrt(z1 * z2 / (1 + u * u * z2 / (4 * z1)))

    def by_hand(x: float, y: float, z: float, fz: float) -> float:
        dz = (z - 1.0) * fz
        r = math.sqrt(x * x + y * y + dz * dz)
        return fz * q / (4 * math.pi * z1 * r) * math.exp(-r / lam + x * u / (2 * z1))

    for x, y, z in ((12.0, 0.5, 3.0), (3.0, -1.0, 0.2), (-4.0, 1.0, 2.5)):
        fz = 1.0 / math.sqrt(1.0 + iz * iz * max(x, 0.0) * u / (2 * z1))
        got = IsotropicPlume(meander_z=iz).concentration(theta, np.array([[x, y, z]]))[0, 0]
        assert got == pytest.approx(by_hand(x, y, z, fz), rel=1e-12)


@pytest.mark.parametrize("iz", [0.0, 0.1, 0.3])
def test_vertical_meander_grows_the_plume_ballistically_and_keeps_its_flux(iz):
    """Far downwind the vertical profile is Gaussian with variance 2 ζ1 d / u + i_z² d² (the
    diffusive spread plus Taylor's ballistic one), and the flux u ∫∫ C dy dz is the release
    rate whatever i_z: statistics of the profile against the closed form."""
    from dcee.models.plume import IsotropicPlume

    q, u, z1, d = 3.0, 4.0, 0.4, 40.0
    theta = np.array([[0.0, 0.0, 0.0, q, u, math.pi, z1, 1e9]])
    ys = np.linspace(-15.0, 15.0, 301)
    zs = np.linspace(-70.0, 70.0, 2801)  # ±5 σ_z at i_z = 0.3
    yy, zz = np.meshgrid(ys, zs, indexing="ij")
    plane = np.column_stack([np.full(yy.size, d), yy.ravel(), zz.ravel()])
    c = IsotropicPlume(meander_z=iz).concentration(theta, plane)[0].reshape(yy.shape)
    profile = np.trapezoid(c, ys, axis=0)
    assert u * np.trapezoid(profile, zs) == pytest.approx(q, rel=0.02)
    variance = np.trapezoid(profile * zs**2, zs) / np.trapezoid(profile, zs)
    assert variance == pytest.approx(2 * z1 * d / u + iz**2 * d**2, rel=0.03)


def test_the_vertical_meander_setting_reaches_the_turbulent_members_only() -> None:
    """``estimator.vertical_meander`` is the turbulent members' (the calm member, the paper's
    model, has none), and the paper's likelihood ignores it."""
    from dcee.scenarios import load_scenario

    sc = load_scenario("random:1").with_overrides(
        **{"estimator.likelihood": "fluctuation", "estimator.vertical_meander": 0.1}
    )
    assert sc.make_plume().meander_z == 0.1
    assert sc.make_plume("paper").meander_z == 0.0
    paper = sc.with_overrides(**{"estimator.likelihood": "paper"})
    assert paper.make_plume().meander_z == 0.0
