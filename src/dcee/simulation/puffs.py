"""Puff plume in a spatially correlated, meandering wind field after Farrell, Murlis, Long, Li &
Cardé (2002): a second turbulent truth, written apart from the filament truth and the fluctuation
likelihood, so that a likelihood or planner fitted to one is measured on the other.

Where it differs from :mod:`dcee.simulation.filament` (which moves the whole plume with one
uniform meander and releases puffs like clockwork):

* **Wind field.** The horizontal wind lives on a grid covering the search area plus a margin
  (``wind_spacing`` m apart). On the grid's boundary it is the mean wind ``u`` (blowing towards
  ``-(cos φ, sin φ)``) plus coloured noise: independent Ornstein-Uhlenbeck processes (standard
  deviation ``meander_intensity · u`` per component, correlation time ``meander_time`` s) at
  anchors every ``boundary_spacing`` m round the boundary, linearly interpolated between them
  (Farrell drives the corners only; more anchors give a correlation length inside the search
  area rather than across the whole domain). Inside, the wind obeys Farrell's
  ``∂v/∂t = −(v·∇)v + K_w ∇²v`` (first-order upwind advection, central diffusion,
  ``wind_diffusivity`` K_w m²/s), so the boundary's fluctuations are carried downwind and smoothed:
  the plume bends and snakes rather than swinging as a rigid line.
* **Release.** Puffs leave the source as a Poisson process at ``puff_rate`` per second (Farrell),
  each carrying ``q / puff_rate`` g (so the mean release rate is ``q``), at a uniformly drawn
  instant within the step.
* **Puffs.** Each puff's centre moves with the wind interpolated (bilinearly) at its position plus
  a random walk of diffusivity ``centre_diffusivity`` m²/s in all three axes (Farrell's centre-
  relative dispersion); its radius grows as ``σ² = puff_radius² + 2 · puff_diffusivity · age``
  (Farrell: ``dR²/dt`` constant). There is no decay and no ground reflection: the scenario's ζ1
  and ζ2, parameters of the estimator's isotropic model, play no part (this plume has its own
  dispersion, as a real one would).

Consequences a test checks (``tests/test_puffs.py``): with the meander off, the ensemble mean is
the Gaussian plume of a continuous point source, ``c = q/(2π u σ_y σ_z) exp(−y²/2σ_y²)`` with
``σ² = puff_radius² + 2 (puff_diffusivity + centre_diffusivity) x / u`` (slender-plume limit);
with it on, the mean plume is wider and a fixed sensor's readings are intermittent, more so
across the plume and towards its edges.

The field is piecewise constant over ``dt`` and can be asked for at any time
(:class:`~dcee.simulation.truth.SteppedTruth`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from dcee.simulation.filament import gaussian_puffs_field
from dcee.simulation.truth import SteppedTruth, plume_stream, register_truth

if TYPE_CHECKING:
    from dcee.scenarios import PuffsSpec, Scenario

PRUNE_EVERY = 10
"""steps between removals of puffs that left the area (every step costs more than it saves)"""


@dataclass
class _State:
    wind: np.ndarray  # (2, ny, nx) m/s: horizontal wind (x, y components) on the grid
    anchors: np.ndarray  # (A, 2) m/s: boundary noise at the anchors
    centres: np.ndarray  # (P, 3) m
    ages: np.ndarray  # (P,) s
    origins: np.ndarray  # (P,) int: the release each puff came from
    released: int = 0  # puffs released since the start of the spin-up

    def copy(self) -> _State:
        return _State(
            self.wind.copy(),
            self.anchors.copy(),
            self.centres.copy(),
            self.ages.copy(),
            self.origins.copy(),
            self.released,
        )


class PuffTruth(SteppedTruth):
    """Farrell-style puff plume in a meandering wind field.

    Parameters
    ----------
    theta : (8,) true source term (x, y, z, q, u, φ rad, ζ1, ζ2); ζ1 and ζ2 are not used. Or
        (K, 8) for K releases in one wind field (``truth.extra_sources``: each row its own
        location and rate, the wind the first row's), each releasing its own Poisson puffs.
    spec : the scenario's :class:`~dcee.scenarios.PuffsSpec`.
    rng : generator for the wind noise, the releases and the puff random walks.
    low, high : (3,) corners of the search volume, m.
    """

    name = "puffs"
    label = "instantaneous puff truth"

    def __init__(
        self,
        theta: np.ndarray,
        spec: PuffsSpec,
        rng: np.random.Generator,
        low: np.ndarray,
        high: np.ndarray,
    ) -> None:
        releases = np.asarray(theta, dtype=np.float64).reshape(-1, 8)
        theta = releases[0]
        self.sources = releases[:, :3].copy()  # (K, 3) m
        self.source = self.sources[0]
        self.q, self.u, phi = float(theta[3]), float(theta[4]), float(theta[5])
        self.spec = spec
        self.mean_wind = -self.u * np.array([math.cos(phi), math.sin(phi)])
        self.puff_mass = self.q / spec.puff_rate
        self.puff_masses = releases[:, 3] / spec.puff_rate  # (K,) g: each release's puffs
        self.low = np.asarray(low, dtype=np.float64)
        self.high = np.asarray(high, dtype=np.float64)
        # wind grid: the area plus the margin, nodes wind_spacing apart (at least 3 per axis)
        h, margin = spec.wind_spacing, spec.margin
        nx = max(3, math.ceil((self.high[0] - self.low[0] + 2 * margin) / h) + 1)
        ny = max(3, math.ceil((self.high[1] - self.low[1] + 2 * margin) / h) + 1)
        self.x0, self.y0 = self.low[0] - margin, self.low[1] - margin
        self.h, self.nx, self.ny = h, nx, ny
        self._boundary = _perimeter(nx, ny)  # (B, 2) (iy, ix) in order round the boundary
        # neighbouring boundary nodes are one cell apart: (B,) m along the boundary, from 0
        self._boundary_arc = h * np.arange(len(self._boundary), dtype=np.float64)
        self._perimeter_length = h * len(self._boundary)
        count = max(4, round(self._perimeter_length / spec.boundary_spacing))
        self._anchor_arc = np.linspace(0.0, self._perimeter_length, count, endpoint=False)
        sd = spec.meander_intensity * self.u
        self._walk = math.sqrt(2.0 * spec.centre_diffusivity * spec.dt)
        # the wind advances every wind_steps puff steps: about one cell's travel time at the
        # mean wind, at most a quarter of the noise's correlation time
        cell_time = min(h / max(self.u, 1e-9), spec.meander_time / 4.0)
        self._wind_steps = max(1, round(cell_time / spec.dt))
        self._wind_dt = self._wind_steps * spec.dt
        gy, gx = np.mgrid[1 : ny - 1, 1 : nx - 1]
        self._nodes_xy = np.column_stack(
            [self.x0 + h * gx.ravel(), self.y0 + h * gy.ravel()]
        )  # (interior nodes, 2) m
        self._ou_keep = math.exp(-self._wind_dt / spec.meander_time)
        self._ou_kick = sd * math.sqrt(1.0 - self._ou_keep**2)
        anchors = sd * rng.standard_normal((count, 2))  # start in the stationary distribution
        wind = np.empty((2, ny, nx))
        wind[0], wind[1] = self.mean_wind[0], self.mean_wind[1]
        self._state = _State(wind, anchors, np.empty((0, 3)), np.empty(0), np.empty(0, np.int64))
        self._set_boundary(self._state)
        # spin-up: long enough for a puff to cross the whole grid twice (the field then no
        # longer depends on the empty start) and for the wind noise to decorrelate
        span = math.hypot(nx * h, ny * h)
        spin = max(2.0 * span / max(self.u, 0.1), 5.0 * spec.meander_time)
        self._start_stepping(spec.dt, math.ceil(spin / spec.dt), rng)

    # --- wind ---------------------------------------------------------------------------------

    def _set_boundary(self, s: _State) -> None:
        """Boundary nodes: the mean wind plus the anchors' noise interpolated along the boundary
        (periodic: the boundary is a closed loop)."""
        arc, period = self._anchor_arc, self._perimeter_length
        iy, ix = self._boundary[:, 0], self._boundary[:, 1]
        for k in range(2):
            noise = np.interp(self._boundary_arc, arc, s.anchors[:, k], period=period)
            s.wind[k, iy, ix] = self.mean_wind[k] + noise

    def _step_wind(self, s: _State) -> None:
        """One wind step of ``wind_steps · dt`` s: semi-Lagrangian advection (each node takes
        the wind found upwind, bilinearly interpolated, at the point it came from), then
        explicit diffusion. A step of about one cell's travel time keeps the numerical
        diffusion of the interpolation far below that of a small-step upwind scheme, which
        would damp the boundary's meander before it crosses the search area."""
        w, h, dt = s.wind, self.h, self._wind_dt
        inner = (slice(None), slice(1, -1), slice(1, -1))
        xy = self._nodes_xy - dt * w[:, 1:-1, 1:-1].reshape(2, -1).T
        new = w.copy()
        new[inner] = self._wind_at(w, xy).T.reshape(2, self.ny - 2, self.nx - 2)
        kw = self.spec.wind_diffusivity
        if kw > 0:
            n = max(1, math.ceil(kw * dt / h**2 / 0.2))
            for _ in range(n):
                c = new[inner]
                lap = (
                    new[:, 1:-1, 2:] + new[:, 1:-1, :-2] + new[:, 2:, 1:-1] + new[:, :-2, 1:-1]
                ) - 4.0 * c
                new[inner] = c + (kw * dt / n / h**2) * lap
        s.wind = new
        self._set_boundary(s)

    def wind_at(self, xy: np.ndarray, time: float | None = None) -> np.ndarray:
        """(K, 2) wind (m/s) at (K, 2) horizontal positions, bilinear on the grid (positions
        beyond it take the nearest boundary value); at ``time`` s, or now if None."""
        if time is not None:
            self._advance_to(self._step_for(time))
        return self._wind_at(self._state.wind, np.asarray(xy, dtype=np.float64).reshape(-1, 2))

    def _wind_at(self, wind: np.ndarray, xy: np.ndarray) -> np.ndarray:
        gx = np.clip((xy[:, 0] - self.x0) / self.h, 0.0, self.nx - 1.0)
        gy = np.clip((xy[:, 1] - self.y0) / self.h, 0.0, self.ny - 1.0)
        ix = np.minimum(gx.astype(np.int64), self.nx - 2)
        iy = np.minimum(gy.astype(np.int64), self.ny - 2)
        fx, fy = gx - ix, gy - iy
        out = np.empty((len(xy), 2))
        for k in range(2):
            f = wind[k]
            out[:, k] = (1 - fy) * ((1 - fx) * f[iy, ix] + fx * f[iy, ix + 1]) + fy * (
                (1 - fx) * f[iy + 1, ix] + fx * f[iy + 1, ix + 1]
            )
        return out

    # --- dynamics -----------------------------------------------------------------------------

    def _advance_one(self) -> None:
        s, dt, rng = self._state, self.dt, self._rng
        s.anchors = self._ou_keep * s.anchors + self._ou_kick * rng.standard_normal(s.anchors.shape)
        self._step_wind(s)
        if s.ages.size:
            velocity = self._wind_at(s.wind, s.centres[:, :2])
            s.centres[:, :2] += velocity * dt
            s.centres += self._walk * rng.standard_normal(s.centres.shape)
            s.ages += dt
        for origin, source in enumerate(self.sources):  # each release its own Poisson puffs
            born = int(rng.poisson(self.spec.puff_rate * dt))
            if not born:
                continue
            ages = dt * rng.random(born)  # released at a uniform instant within the step
            here = self._wind_at(s.wind, source[None, :2])[0]
            new = np.repeat(source[None, :], born, axis=0)
            new[:, :2] += np.outer(ages, here)
            new += np.sqrt(2.0 * self.spec.centre_diffusivity * ages)[
                :, None
            ] * rng.standard_normal((born, 3))
            s.centres = np.concatenate([s.centres, new])
            s.ages = np.concatenate([s.ages, ages])
            s.origins = np.concatenate([s.origins, np.full(born, origin)])
            s.released += born
        if self.step_count % PRUNE_EVERY == 0 and s.ages.size:
            margin = (4.0 * np.sqrt(self._sigma_sq(s.ages)) + 1.0)[:, None]
            near = np.all((s.centres > self.low - margin) & (s.centres < self.high + margin), 1)
            s.centres, s.ages, s.origins = s.centres[near], s.ages[near], s.origins[near]

    def _sigma_sq(self, ages: np.ndarray) -> np.ndarray:
        return self.spec.puff_radius**2 + 2.0 * self.spec.puff_diffusivity * ages

    # --- queries ------------------------------------------------------------------------------

    def puffs(self, time: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centres (P, 3) m, radii σ (P,) m, masses (P,) g) of the live puffs at ``time`` s."""
        self._advance_to(self._step_for(time))
        s = self._state
        return (
            s.centres.copy(),
            np.sqrt(self._sigma_sq(s.ages)),
            self.puff_masses[s.origins],
        )

    def released(self, time: float) -> int:
        """Puffs released from the start of the spin-up until ``time`` s."""
        self._advance_to(self._step_for(time))
        return self._state.released

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) instantaneous concentrations (g/m³) at (K, 3) positions at ``time`` s."""
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        self._advance_to(self._step_for(time))
        s = self._state
        masses = self.puff_masses[s.origins]
        return gaussian_puffs_field(positions, s.centres, self._sigma_sq(s.ages), masses)

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.field(np.reshape(position, (1, 3)), time)[0])


def _perimeter(nx: int, ny: int) -> np.ndarray:
    """(B, 2) grid indices (iy, ix) of the boundary nodes in order round the rectangle."""
    bottom = [(0, i) for i in range(nx)]
    right = [(j, nx - 1) for j in range(1, ny)]
    top = [(ny - 1, i) for i in range(nx - 2, -1, -1)]
    left = [(j, 0) for j in range(ny - 2, 0, -1)]
    return np.array(bottom + right + top + left, dtype=np.int64)


@register_truth("puffs")
def puff_truth(scenario: Scenario, seed: int) -> PuffTruth:
    """The puff truth of ``truth.model`` for episode ``seed`` (the episode's plume stream)."""
    low, high = np.array(scenario.volume.low), np.array(scenario.volume.high)
    return PuffTruth(scenario.truth_thetas(), scenario.truth.model, plume_stream(seed), low, high)


__all__ = ["PuffTruth"]
