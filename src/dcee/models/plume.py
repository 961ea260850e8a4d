"""Isotropic plume model (the paper's dispersion equation, eq. 2).

Source term Θ = (x, y, z, q, u, φ, ζ1, ζ2), always in this column order:

========  =====================================  ======
column    meaning                                unit
========  =====================================  ======
x, y, z   source location                        m
q         release rate                           g/s
u         mean wind speed                        m/s
φ         wind direction (see below)             rad
ζ1        diffusivity                            m²/s
ζ2        average particle lifetime              s
========  =====================================  ======

Expected concentration (g/m³) at position p from a source at s::

    C = q / (4π ζ1 r) · exp(−r/λ) · exp(−((p_x−s_x) u cos φ + (p_y−s_y) u sin φ) / (2 ζ1))
    λ = sqrt(ζ1 ζ2 / (1 + u² ζ2 / (4 ζ1))),   r = max(‖p − s‖, MIN_DISTANCE)

Wind-direction convention: with this formula the plume extends from the source towards
−(cos φ, sin φ); φ is the direction the wind *comes from* (φ = 0: wind from +x blowing towards −x).

Meander (``meander`` = i > 0, off by default): a real plume's centreline swings with the
large eddies, so its *time mean* is wider than the diffusion-only solution above. Following
Taylor's short-range result (crosswind spread σ_m = i · d at distance d downwind, i the
crosswind turbulence intensity σ_v/u), the horizontal crosswind profile, Gaussian with
variance σ_d² = 2 ζ1 d / u in the far field, is convolved with N(0, σ_m²): the concentration
is the isotropic one at the crosswind offset compressed by f = σ_d / √(σ_d² + σ_m²) =
1/√(1 + i² d u / (2 ζ1)), times f (mass conserved across the plume). Exact for the far field's
Gaussian profile, f → 1 at the source and upwind.

Vertical meander (``meander_z`` = i_z > 0, off by default): the same broadening across the
wind in the vertical, at its own intensity (Taylor: σ_z = i_z · d with i_z = σ_w / u): the
height offset compressed by f_z = 1/√(1 + i_z² d u / (2 ζ1)), the concentration times f_z.
Near the ground the vertical eddies are weaker than the horizontal ones (σ_w / σ_v ≈ 0.66 in a
neutral surface layer; Panofsky & Dutton 1984). Without it the plume grows upwards
diffusively (σ_z² = 2 ζ1 d / u), so a reading model fitted to gas met some way above a
release makes the height it must climb depend on ζ1; with it the climb is ballistic, as the
near field of a real plume's is.

Decay (``decay`` = p, 1 by default): the prefactor falls with distance as 1/r^p. p = 1 is the
paper's point source in three dimensions; p = 1/2 is the far field of the same equation in two
dimensions, a planar plume (the 2-D solution q'/(2π ζ1) · K0(r/λ) · exp(advection), with
K0(s) ≈ √(π / 2s) e^(−s) for s ≫ 1, is this formula with r^(1/2) for r and a constant that the
release rate absorbs). A planar plume's centreline mean falls as x^(−1/2…−1) downwind, a
point source's as x^(−1) or faster; a reading model with the wrong law places the source
upwind of a planar plume (it explains the slower fall by a more distant source). The reading
model can weigh both (``estimator.learn = {decay = [1, 0.5]}``).

Backflow (``backflow`` = w, 0 by default): near a release in strong turbulence the wind's
direction swings through large angles, and gas is found upwind of the source. The time mean
over a wind that blows from φ for a share 1 − w of the time and from φ + π for a share w is
``(1 − w) · C(φ) + w · C(φ + π)`` (the release rate keeps its meaning). Why one share fits at
every distance: in the near field, where a plume's spread grows ballistically (σ = i · u · t
for the turbulence intensity i), the time mean a distance d upwind is a fixed fraction of the
mean the same distance downwind, whatever d (the integral over travel times is scale-free): in
a planar plume P(Z > 1/i) / P(Z < 1/i), 0.023 for i = 0.5, 0.050 for i = 0.6, 0.12 for
i = 0.8; in three dimensions less (0.004, 0.012, 0.039; numerical integration). Beyond the
Lagrangian time scale the spread grows diffusively and upwind gas dies out, which this term
does not model: its reversed plume reaches as far upwind as the plume downwind, at a share w
of its strength (a weak term far upwind, where readings are mostly below the threshold
anyway). The reading model can weigh it (``estimator.learn = {backflow = [0, 0.05]}``).

Source radius (``radius`` = R m, 0 by default): a pool, a vent or a spill releases over an
area, and a recording stored on a coarse grid spreads even a point release over a cell or two;
either way gas is found up to about R upwind of the source location, which a point source
explains only by moving upwind. The release is spread evenly over a horizontal disc of radius R
about the source location: seven sub-sources, the centre weighing 1/4 and six on a ring of
radius R √(2/3) (one straight upwind) 1/8 each, which matches the disc's mean square offset
R²/2; each sub-source's distance is clamped at half the ring radius, the spacing of the rule,
so the model stays smooth inside the disc. The distance the reading model's near-source terms
use is to the disc's centre. The reading model can weigh it (``estimator.learn =
{source_radius = [0, 1]}``).

Vertical ratio (``vertical`` = a, 1 by default) and ground (``ground`` = g, 0 by default): the
paper's plume spreads as fast vertically as horizontally in unbounded air. Near the ground the
eddies are flatter (in a neutral surface layer σ_w / σ_v ≈ 1.25 / 1.9 ≈ 0.66; Panofsky &
Dutton 1984), and the ground turns back the gas that reaches it. With a vertical diffusivity
a² ζ1, the solution is the isotropic one with every height divided by a and the release rate
too (substitute z = a z' in the advection-diffusion equation: the point source's δ(z) becomes
δ(z') / a); a ground that reflects adds the mirror image of the release at −z (the image
method for a zero-flux boundary), weighted by g. Both together keep the flux through a
crosswind plane above the ground equal to the release rate (tests/test_plume.py).

The distance is clamped at :data:`MIN_DISTANCE` = 0.1 m, the scale of a sensor inlet, so the
model stays finite when a hypothesised source sits on the sensor (the authors' MATLAB code uses
1e-5 m, Stone Soup 0.1 m; a tiny clamp makes a particle at the sensor predict absurd
concentrations, which is a property of the clamp, not of the physics).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dcee.errors import DceeInputError
from dcee.models import plume_kernels

PARAMETER_NAMES: tuple[str, ...] = ("x", "y", "z", "q", "u", "phi", "zeta1", "zeta2")
"""Column order of Θ everywhere in dcee."""

PARAMETER_UNITS: dict[str, str] = {
    "x": "m",
    "y": "m",
    "z": "m",
    "q": "g/s",
    "u": "m/s",
    "phi": "rad",
    "zeta1": "m²/s",
    "zeta2": "s",
}

MIN_DISTANCE = 0.1
"""Distance clamp (m) used by :func:`isotropic_concentration`."""


def _check_shapes(theta: np.ndarray, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    theta = np.ascontiguousarray(theta, dtype=np.float64)
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    if theta.ndim == 1:
        theta = theta[None, :]
    if positions.ndim == 1:
        positions = positions[None, :]
    if theta.ndim != 2 or theta.shape[1] != 8:
        raise DceeInputError("theta", f"must have shape (N, 8), got {theta.shape}")
    if positions.ndim != 2 or positions.shape[1] != 3:
        raise DceeInputError("positions", f"must have shape (M, 3), got {positions.shape}")
    return theta, positions


def isotropic_concentration_reference(
    theta: np.ndarray,
    positions: np.ndarray,
    min_distance: float = MIN_DISTANCE,
    meander: float = 0.0,
    decay: float = 1.0,
    backflow: float = 0.0,
    radius: float = 0.0,
    vertical: float = 1.0,
    ground: float = 0.0,
    meander_z: float = 0.0,
) -> np.ndarray:
    """Plain NumPy implementation of the plume; the compiled kernel is tested against it.

    theta: (N, 8); positions: (M, 3) in m. Returns (N, M) concentrations in g/m³.
    """
    theta, positions = _check_shapes(theta, positions)
    if vertical != 1.0 or ground != 0.0:
        # heights divided by a (and the release rate with them), plus the image below z = 0
        scaled = theta.copy()
        scaled[:, 2] /= vertical
        scaled[:, 3] /= vertical
        pos = positions.copy()
        pos[:, 2] /= vertical
        total = isotropic_concentration_reference(
            scaled, pos, min_distance, meander, decay, backflow, radius, meander_z=meander_z
        )
        if ground > 0:
            scaled[:, 2] *= -1.0
            total = total + ground * isotropic_concentration_reference(
                scaled, pos, min_distance, meander, decay, backflow, radius, meander_z=meander_z
            )
        return total
    if radius > 0:
        # the disc rule: the centre weighs 1/4, six points on a ring of radius R √(2/3) 1/8
        # each (one straight upwind), every sub-source's distance clamped at half the ring
        ring = radius * math.sqrt(2.0 / 3.0)
        clamp = max(min_distance, ring / 2.0)
        total = 0.25 * isotropic_concentration_reference(
            theta, positions, clamp, meander, decay, backflow, meander_z=meander_z
        )
        for j in range(6):
            angle = theta[:, 5] + j * math.pi / 3.0
            moved = theta.copy()
            moved[:, 0] += ring * np.cos(angle)
            moved[:, 1] += ring * np.sin(angle)
            total += 0.125 * isotropic_concentration_reference(
                moved, positions, clamp, meander, decay, backflow, meander_z=meander_z
            )
        return total
    if backflow > 0:
        # the time mean over a wind that blows from φ + π for a share w of the time
        reversed_wind = theta.copy()
        reversed_wind[:, 5] += np.pi
        return (1.0 - backflow) * isotropic_concentration_reference(
            theta, positions, min_distance, meander, decay, meander_z=meander_z
        ) + backflow * isotropic_concentration_reference(
            reversed_wind, positions, min_distance, meander, decay, meander_z=meander_z
        )
    x, y, z, q, u, phi, z1, z2 = (theta[:, k : k + 1] for k in range(8))
    dx = positions[None, :, 0] - x
    dy = positions[None, :, 1] - y
    factor = np.ones_like(dx)
    down = np.maximum(-(dx * np.cos(phi) + dy * np.sin(phi)), 0.0)
    if meander > 0:
        factor = 1.0 / np.sqrt(1.0 + meander**2 * down * u / (2.0 * z1))
        cross = -dx * np.sin(phi) + dy * np.cos(phi)
        along = dx * np.cos(phi) + dy * np.sin(phi)
        cross = cross * factor
        dx = along * np.cos(phi) - cross * np.sin(phi)
        dy = along * np.sin(phi) + cross * np.cos(phi)
    dz = positions[None, :, 2] - z
    if meander_z > 0:
        factor_z = 1.0 / np.sqrt(1.0 + meander_z**2 * down * u / (2.0 * z1))
        dz = dz * factor_z
        factor = factor * factor_z
    r = np.maximum(np.sqrt(dx * dx + dy * dy + dz * dz), min_distance)
    lam = np.sqrt(z1 * z2 / (1.0 + u * u * z2 / (4.0 * z1)))
    advection = (dx * u * np.cos(phi) + dy * u * np.sin(phi)) / (2.0 * z1)
    return factor * q / (4.0 * np.pi * z1 * r**decay) * np.exp(-r / lam - advection)


def isotropic_concentration(
    theta: np.ndarray,
    positions: np.ndarray,
    min_distance: float = MIN_DISTANCE,
    meander: float = 0.0,
    decay: float = 1.0,
    backflow: float = 0.0,
    radius: float = 0.0,
    vertical: float = 1.0,
    ground: float = 0.0,
    meander_z: float = 0.0,
) -> np.ndarray:
    """Expected concentration (g/m³) of the isotropic plume, compiled.

    theta: (N, 8) source terms in :data:`PARAMETER_NAMES` order (φ in radians);
    positions: (M, 3) sensor positions in m. Returns an (N, M) array.
    """
    theta, positions = _check_shapes(theta, positions)
    out = np.empty((theta.shape[0], positions.shape[0]))
    plume_kernels.concentration_matrix(
        theta, positions, min_distance, meander, decay, backflow, radius, vertical, ground,
        meander_z, out,
    )  # fmt: skip
    return out


@dataclass(frozen=True)
class IsotropicPlume:
    """The estimator's dispersion model; wraps :func:`isotropic_concentration`."""

    min_distance: float = MIN_DISTANCE
    meander: float = 0.0
    """crosswind turbulence intensity i of the time-mean meander broadening (0: none)"""
    decay: float = 1.0
    """exponent p of the prefactor's fall with distance, 1/r^p: 1 a point source in 3-D (the
    paper), 1/2 a planar plume (module doc)"""
    backflow: float = 0.0
    """share w of the time the wind blows against its mean direction: (1 − w) · the plume +
    w · the plume of the reversed wind (module doc); 0: none"""
    radius: float = 0.0
    """m, the release spread evenly over a horizontal disc of this radius about the source
    location (module doc); 0: a point source"""
    vertical: float = 1.0
    """ratio a of the plume's vertical to its horizontal spread (module doc); 1: isotropic"""
    ground: float = 0.0
    """weight of the release's image below the ground z = 0 (module doc): 1 a ground that
    reflects all gas, 0 none (the paper's unbounded air)"""
    meander_z: float = 0.0
    """vertical turbulence intensity i_z of the meander broadening (module doc); 0: none"""

    def __post_init__(self) -> None:
        if not (0.0 <= self.meander <= 2.0):
            raise DceeInputError("meander", f"must be in [0, 2], got {self.meander}")
        if not (0.25 <= self.decay <= 2.0):
            raise DceeInputError("decay", f"must be in [0.25, 2], got {self.decay}")
        if not (0.0 <= self.backflow <= 0.5):
            raise DceeInputError("backflow", f"must be in [0, 0.5], got {self.backflow}")
        if not (0.0 <= self.radius <= 10.0):
            raise DceeInputError("source_radius", f"must be in [0, 10] m, got {self.radius}")
        if not (0.1 <= self.vertical <= 10.0):
            raise DceeInputError("vertical_ratio", f"must be in [0.1, 10], got {self.vertical}")
        if not (0.0 <= self.ground <= 1.0):
            raise DceeInputError("ground", f"must be in [0, 1], got {self.ground}")
        if not (0.0 <= self.meander_z <= 2.0):
            raise DceeInputError("vertical_meander", f"must be in [0, 2], got {self.meander_z}")

    @property
    def shape(self) -> tuple[float, float, float, float, float, float, float]:
        """(meander, decay, backflow, radius, vertical, ground, meander_z): the plume's shape
        settings, in the order the kernels take them."""
        return (
            self.meander,
            self.decay,
            self.backflow,
            self.radius,
            self.vertical,
            self.ground,
            self.meander_z,
        )

    def concentration(self, theta: np.ndarray, positions: np.ndarray) -> np.ndarray:
        """(N, 8) source terms × (M, 3) positions → (N, M) concentrations in g/m³."""
        return isotropic_concentration(theta, positions, self.min_distance, *self.shape)
