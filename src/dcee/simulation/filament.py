"""Turbulent filament (puff) plume ground truth after Farrell et al. (2002).

The estimator assumes the isotropic plume, which is the *time average* of a release. Real plumes
meander and are intermittent: a sensor inside the mean plume often reads nothing, then a
filament passes and it reads far more than the mean. This truth produces that behaviour while
keeping the long-time average comparable to the isotropic model, so that the only difference the
estimator faces is the one of the real world: the instantaneous field is not the mean field.

Model (all arrays, no Python object per puff):

* Puffs are released at the source at ``puff_rate`` per second, each carrying the mass
  ``q / puff_rate`` (g), which decays as ``exp(-age / ζ2)``: the same removal as the isotropic
  model's particle lifetime ζ2.
* Each puff is a 3-D Gaussian of radius ``σ² = puff_radius² + 2 · puff_share · ζ1 · age``.
* Its centre moves with the wind and takes a random walk with diffusivity ``(1 - puff_share)·ζ1``
  (Farrell's "centre relative dispersion").
* The wind is the mean wind ``u`` (blowing towards ``-(cos φ, sin φ)``, the isotropic model's
  convention) plus a meander: along- and cross-wind velocity components, each a damped
  second-order coloured-noise process ``ẍ + 2ζωẋ + ω²x = ω²G ξ(t)`` (Farrell's wind noise) with
  standard deviation ``meander_intensity · u``. The meander is uniform over the search area:
  this is the large-eddy limit of Farrell's wind model, whose boundary-driven field varies on
  scales (hundreds of metres) larger than a 50 m search area. It is smooth in space and time
  and moves the whole plume, which is what makes a point sensor's readings intermittent.

Why the mean is comparable: without meander, the expected concentration of this puff ensemble is
exactly the time-dependent solution of the advection-diffusion-decay equation whose steady
state is the isotropic model (Gaussian puffs of variance ``2 ζ1 age`` advected at ``u`` are its
Green's function). After the spin-up the mean field therefore equals the isotropic plume up to
the puff discretisation; the meander widens it as a real meandering plume is wider than the
mean-wind solution. ``tests/test_truth.py`` checks both.

The field is simulated from ``-spin_up`` (long enough for the plume to reach steady state: the
oldest live puff) and is piecewise constant over ``dt``. It can be queried at any time:
checkpoints every 10 s let figures look back without re-running the whole episode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from dcee.simulation.truth import SteppedTruth, plume_stream, register_truth

if TYPE_CHECKING:
    from dcee.scenarios import FilamentSpec, Scenario

DECAY_CUTOFF = 1e-6
"""A puff is dropped once its mass has decayed below this fraction (age > ζ2 · ln 1e6)."""
PRUNE_EVERY = 10
"""steps between removals of dead or far-away puffs (pruning every step costs more than it saves)"""


@dataclass
class _State:
    centres: np.ndarray  # (P, 3) m
    ages: np.ndarray  # (P,) s
    meander: np.ndarray  # (2, 2): [along, cross] x [displacement-like state, its rate]
    released: int  # puffs released so far by each release
    origins: np.ndarray  # (P,) int: the release each puff came from

    def copy(self) -> _State:
        return _State(
            self.centres.copy(),
            self.ages.copy(),
            self.meander.copy(),
            self.released,
            self.origins.copy(),
        )


def gaussian_puffs_field(
    positions: np.ndarray, centres: np.ndarray, var: np.ndarray, masses: np.ndarray
) -> np.ndarray:
    """(K,) concentration (g/m³) at (K, 3) positions of isotropic 3-D Gaussian puffs with
    (P, 3) centres (m), (P,) variances σ² (m²) and (P,) masses (g): each integrates to its mass."""
    out = np.zeros(len(positions))
    if not len(masses):
        return out
    amp = masses / (2.0 * math.pi * var) ** 1.5
    chunk = max(1, 2_000_000 // len(masses))  # bound the (K, P) temporaries to ~16 MB
    for a in range(0, len(positions), chunk):
        d = positions[a : a + chunk, None, :] - centres[None, :, :]
        out[a : a + chunk] = np.exp(-np.einsum("kpi,kpi->kp", d, d) / (2.0 * var)) @ amp
    return out


class FilamentTruth(SteppedTruth):
    """Farrell-style filament plume.

    Parameters
    ----------
    theta : (8,) true source term (x, y, z, q, u, φ rad, ζ1, ζ2), or (K, 8) for K releases in
        one flow (``truth.extra_sources``: each row its own location and rate; the wind and
        dispersion are the first row's). Every release puffs on the same schedule and rides the
        same meander.
    spec : the scenario's :class:`~dcee.scenarios.FilamentSpec`.
    rng : generator for the meander and the puff random walks (the episode's truth stream).
    low, high : (3,) corners of the search volume, m; puffs far outside it are dropped.
    """

    name = "filament"
    label = "instantaneous filament truth"

    def __init__(
        self,
        theta: np.ndarray,
        spec: FilamentSpec,
        rng: np.random.Generator,
        low: np.ndarray,
        high: np.ndarray,
    ) -> None:
        releases = np.asarray(theta, dtype=np.float64).reshape(-1, 8)
        theta = releases[0]
        self.sources = releases[:, :3].copy()  # (K, 3) m
        self.source = self.sources[0]
        self.q, self.u, phi, zeta1, self.tau = (float(v) for v in theta[3:])
        self.spec = spec
        self.direction = -np.array([math.cos(phi), math.sin(phi), 0.0])
        self.crosswind = np.array([-self.direction[1], self.direction[0], 0.0])
        self.puff_diffusivity = spec.puff_share * zeta1
        self.walk_scale = math.sqrt(2.0 * (1.0 - spec.puff_share) * zeta1 * spec.dt)
        self.puff_mass = self.q / spec.puff_rate
        self.puff_masses = releases[:, 3] / spec.puff_rate  # (K,) g: each release's puffs
        self.max_age = self.tau * math.log(1.0 / DECAY_CUTOFF)
        self.low = np.asarray(low, dtype=np.float64)
        self.high = np.asarray(high, dtype=np.float64)
        # coloured noise with stationary sd s: G = s · sqrt(4ζ/ω)  (var x = G² ω / 4ζ)
        w, z = spec.meander_bandwidth, spec.meander_damping
        sd = spec.meander_intensity * self.u
        self._omega, self._damping = w, z
        self._noise_gain = w * w * sd * math.sqrt(4.0 * z / w)
        meander = np.zeros((2, 2))
        meander[:, 0] = sd * rng.standard_normal(2)  # start in the stationary distribution
        meander[:, 1] = w * sd * rng.standard_normal(2)
        self._state = _State(np.empty((0, 3)), np.empty(0), meander, 0, np.empty(0, np.int64))
        # spin-up: the oldest puff alive in steady state; then the field no longer depends on
        # the empty start
        self._start_stepping(spec.dt, math.ceil(self.max_age / spec.dt), rng)

    # --- dynamics -----------------------------------------------------------------------------

    def _velocity(self, meander: np.ndarray) -> np.ndarray:
        return (self.u + meander[0, 0]) * self.direction + meander[1, 0] * self.crosswind

    def _advance_one(self) -> None:
        s, dt = self._state, self.dt
        # meander: semi-implicit Euler-Maruyama (ω dt ≤ 0.02 by default: accurate and stable)
        m = s.meander
        kick = self._noise_gain * math.sqrt(dt) * self._rng.standard_normal(2)
        m[:, 1] += dt * (-2.0 * self._damping * self._omega * m[:, 1] - self._omega**2 * m[:, 0])
        m[:, 1] += kick
        m[:, 0] += dt * m[:, 1]
        velocity = self._velocity(m)
        if s.ages.size:
            walk = self.walk_scale * self._rng.standard_normal(s.centres.shape)
            s.centres += velocity * dt + walk
            s.ages += dt
        step = self.step_count
        # puffs whose release time falls in this step, with their exact sub-step ages
        due = math.floor(step * dt * self.spec.puff_rate + 1e-9)
        if due > s.released:
            k = np.arange(s.released, due, dtype=np.float64)
            ages = step * dt - k / self.spec.puff_rate
            # every release puffs at once: (K · n) new puffs, release by release
            new = (self.sources[:, None, :] + np.outer(ages, velocity)[None]).reshape(-1, 3)
            count = len(self.sources)
            s.centres = np.concatenate([s.centres, new])
            s.ages = np.concatenate([s.ages, np.tile(ages, count)])
            s.origins = np.concatenate([s.origins, np.repeat(np.arange(count), len(ages))])
            s.released = due
        if step % PRUNE_EVERY == 0 and s.ages.size:
            sigma = np.sqrt(self._sigma_sq(s.ages))
            margin = (5.0 * sigma + 1.0)[:, None]
            near = np.all((s.centres > self.low - margin) & (s.centres < self.high + margin), 1)
            keep = near & (s.ages < self.max_age)
            s.centres, s.ages, s.origins = s.centres[keep], s.ages[keep], s.origins[keep]

    def _sigma_sq(self, ages: np.ndarray) -> np.ndarray:
        return self.spec.puff_radius**2 + 2.0 * self.puff_diffusivity * ages

    # --- queries ------------------------------------------------------------------------------

    def puffs(self, time: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centres (P, 3) m, radii σ (P,) m, masses (P,) g) of the live puffs at ``time`` s."""
        centres, var, masses = self._live_puffs(time)
        return centres.copy(), np.sqrt(var), masses

    def _live_puffs(self, time: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centres (P, 3) as a view of the state, variances σ² (P,), masses (P,))."""
        self._advance_to(self._step_for(time))
        s = self._state
        masses = self.puff_masses[s.origins] * np.exp(-s.ages / self.tau)
        return s.centres, self._sigma_sq(s.ages), masses

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) instantaneous concentrations (g/m³) at (K, 3) positions at ``time`` s."""
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        return gaussian_puffs_field(positions, *self._live_puffs(time))

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.field(np.reshape(position, (1, 3)), time)[0])


@register_truth("filament")
def filament_truth(scenario: Scenario, seed: int) -> FilamentTruth:
    """The filament truth of ``truth.model`` for episode ``seed`` (its own random stream)."""
    low, high = np.array(scenario.volume.low), np.array(scenario.volume.high)
    spec = scenario.truth.model
    return FilamentTruth(scenario.truth_thetas(), spec, plume_stream(seed), low, high)


__all__ = ["FilamentTruth"]
