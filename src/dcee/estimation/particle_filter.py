"""Particle filter for the source term (the paper's Algorithm 1), with a full-history MCMC move.

Per reading: weights are updated in log space; when the effective sample size (ESS) falls below
``resample_threshold · N`` the particles are resampled systematically and moved by
``mcmc_steps`` random-walk Metropolis–Hastings steps whose acceptance uses the prior and the
likelihood of *every* reading so far, so the chain leaves the true posterior invariant.
(AutoSTE and Stone Soup accept on the latest reading only, which does not target the posterior.)

Degeneracy: in log space the weights cannot all underflow, but a reading that every particle
finds very unlikely can collapse the weight onto a handful of particles. When the ESS after a
reading would fall below ``collapse_threshold · N`` the reading is instead assimilated by
likelihood tempering: exponents 0 = β₀ < β₁ < … < 1 chosen by bisection so that each stage keeps
ESS ≈ ``resample_threshold · N``, with resampling and MCMC moves targeting prior × history ×
p(z|Θ)^β between stages (an adaptive tempered SMC step; it targets the exact posterior). Each
such event is recorded in :attr:`ParticleFilter.recoveries`.

Known parameters stay at their fixed values: the filter stores full (N, 8) source terms but only
the unknown columns are sampled, moved and reported by :attr:`ParticleFilter.particles`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dcee.errors import DceeInputError
from dcee.estimation.filter_kernels import history_log_likelihood
from dcee.estimation.priors import SourcePrior
from dcee.models.plume import IsotropicPlume, isotropic_concentration_reference
from dcee.models.sensor import Sensor


def history_log_likelihood_reference(
    theta: np.ndarray,
    positions: np.ndarray,
    readings: np.ndarray,
    multiplicity: np.ndarray,
    sensor: Sensor,
    plume: IsotropicPlume,
) -> np.ndarray:
    """NumPy reference of the compiled history likelihood: (N,) Σ_k m_k log p(z_k | Θ_i)."""
    conc = isotropic_concentration_reference(theta, positions, plume.min_distance)
    return (sensor.log_likelihood(readings[None, :], conc) * multiplicity[None, :]).sum(axis=1)


def systematic_resample(weights: np.ndarray, rng: np.random.Generator, n: int) -> np.ndarray:
    """n indices drawn ∝ weights by systematic sampling (one uniform, O(N + n), no sorting)."""
    cumulative = np.cumsum(weights)
    cumulative[-1] = 1.0  # guard against round-off
    points = (rng.random() + np.arange(n)) / n
    return np.searchsorted(cumulative, points, side="right").clip(0, len(weights) - 1)


def effective_sample_size(weights: np.ndarray) -> float:
    return float(1.0 / np.sum(weights * weights))


@dataclass(frozen=True)
class UpdateInfo:
    """What one :meth:`ParticleFilter.update` did."""

    ess: float
    resampled: bool
    acceptance: float
    tempering_stages: int


class ParticleFilter:
    """Sequential Monte Carlo estimate of the source term.

    Parameters
    ----------
    prior: which parameters are unknown and their priors.
    sensor, plume: the measurement and dispersion models.
    n_particles: N.
    seed: an int or a ``numpy.random.Generator``; every random draw of the filter comes from it.
    resample_threshold: resample when ESS < this · N (paper: N/2).
    mcmc_steps: Metropolis–Hastings sweeps after each resampling.
    collapse_threshold: below this ESS/N a reading is assimilated by tempering (see module doc).
    """

    def __init__(
        self,
        prior: SourcePrior,
        sensor: Sensor,
        plume: IsotropicPlume | None = None,
        n_particles: int = 20_000,
        seed: int | np.random.Generator = 0,
        resample_threshold: float = 0.5,
        mcmc_steps: int = 1,
        collapse_threshold: float = 0.01,
        max_tempering_stages: int = 30,
    ) -> None:
        if int(n_particles) != n_particles or n_particles < 2:
            raise DceeInputError("particles", f"must be an integer >= 2, got {n_particles}")
        if not 0 < resample_threshold <= 1:
            raise DceeInputError("resample_threshold", "must be in (0, 1]")
        if not 0 <= collapse_threshold < resample_threshold:
            raise DceeInputError("collapse_threshold", "must be in [0, resample_threshold)")
        if mcmc_steps < 0:
            raise DceeInputError("mcmc_steps", "must be >= 0")
        self.prior = prior
        self.sensor = sensor
        self.plume = plume or IsotropicPlume()
        self.n = int(n_particles)
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        self.resample_threshold = resample_threshold
        self.mcmc_steps = mcmc_steps
        self.collapse_threshold = collapse_threshold
        self.max_tempering_stages = max_tempering_stages
        self._unknown = np.array(prior.unknown)
        self._sp = sensor.params
        self.theta = prior.sample(self.rng, self.n)
        self._logw = np.full(self.n, -math.log(self.n))
        self._weights: np.ndarray | None = None
        self._hist_loglik = np.zeros(self.n)
        self._hist_pos: list[tuple[float, float, float]] = []
        self._hist_z: list[float] = []
        self._hist_mult: list[float] = []
        self._nd_index: dict[tuple[float, float, float], int] = {}
        self.n_readings = 0
        self.recoveries: list[dict[str, float]] = []
        self.n_resamples = 0

    # --- public state -----------------------------------------------------------------------

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return self.prior.unknown_names

    @property
    def particles(self) -> np.ndarray:
        """(N, D) unknown parameters of every particle (a copy)."""
        return self.theta[:, self._unknown]

    @property
    def weights(self) -> np.ndarray:
        """(N,) normalised weights."""
        if self._weights is None:
            w = np.exp(self._logw - self._logw.max())
            self._weights = w / w.sum()
        return self._weights

    @property
    def source_locations(self) -> np.ndarray:
        """(N, 3) source location of every particle (known coordinates included)."""
        return self.theta[:, :3]

    def mean(self) -> np.ndarray:
        """(D,) posterior mean of the unknown parameters."""
        return self.weights @ self.particles

    def cov(self) -> np.ndarray:
        """(D, D) posterior covariance of the unknown parameters."""
        return np.atleast_2d(np.cov(self.particles, rowvar=False, aweights=self.weights, ddof=0))

    def source_mean(self) -> np.ndarray:
        """(3,) posterior mean source location."""
        return self.weights @ self.source_locations

    def source_cov(self) -> np.ndarray:
        """(3, 3) posterior covariance of the source location."""
        return np.cov(self.source_locations, rowvar=False, aweights=self.weights, ddof=0)

    def rmse(self, true_location: np.ndarray) -> float:
        """√(Σ wᵢ ‖sᵢ − s‖²): RMSE of the particles' source locations about ``true_location``."""
        d = self.source_locations - np.asarray(true_location)[None, :]
        return float(math.sqrt(self.weights @ np.einsum("ij,ij->i", d, d)))

    @property
    def ess(self) -> float:
        return effective_sample_size(self.weights)

    def history(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Readings assimilated so far: ((K, 3) positions, (K,) readings, (K,) multiplicity).

        Non-detections at the same position are merged into one entry with a multiplicity.
        """
        return (
            np.array(self._hist_pos, dtype=np.float64).reshape(-1, 3),
            np.array(self._hist_z, dtype=np.float64),
            np.array(self._hist_mult, dtype=np.float64),
        )

    # --- update -----------------------------------------------------------------------------

    def log_likelihood(self, theta: np.ndarray, position: np.ndarray, reading: float) -> np.ndarray:
        """(N,) log p(reading | Θ) at ``position`` for source terms ``theta`` (N, 8)."""
        out = np.empty(theta.shape[0])
        history_log_likelihood(
            theta,
            np.ones(theta.shape[0], dtype=np.bool_),
            np.asarray(position, dtype=np.float64).reshape(1, 3),
            np.array([reading], dtype=np.float64),
            np.ones(1),
            self.plume.min_distance,
            self._sp,
            out,
        )
        return out

    def update(self, position: np.ndarray, reading: float) -> UpdateInfo:
        """Assimilate one reading (g/m³; below the threshold = non-detection) taken at position."""
        position = np.asarray(position, dtype=np.float64)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise DceeInputError("position", f"must be 3 finite numbers, got {position!r}")
        if not math.isfinite(float(reading)):
            raise DceeInputError("reading", f"must be a finite number, got {reading}")
        reading = float(reading)
        if reading < self.sensor.threshold:
            reading = 0.0
        ll_new = self.log_likelihood(self.theta, position, reading)
        entry, base_mult = self._add_to_history(position, reading)
        self.n_readings += 1

        logw = self._logw + ll_new
        w = _normalise(logw)
        ess = effective_sample_size(w)
        if ess >= self.collapse_threshold * self.n:
            self._hist_loglik += ll_new
            self._set_logw(logw)
            if ess < self.resample_threshold * self.n:
                acc = self._resample_move(self.mcmc_steps)
                return UpdateInfo(ess, True, acc, 1)
            return UpdateInfo(ess, False, math.nan, 1)
        return self._tempered_update(ll_new, entry, base_mult, ess)

    # --- internals --------------------------------------------------------------------------

    def _add_to_history(self, position: np.ndarray, reading: float) -> tuple[int, float]:
        key = tuple(np.round(position, 9).tolist())
        if reading == 0.0 and key in self._nd_index:
            idx = self._nd_index[key]
            base = self._hist_mult[idx]
            self._hist_mult[idx] = base + 1.0
            return idx, base
        self._hist_pos.append(key)
        self._hist_z.append(reading)
        self._hist_mult.append(1.0)
        idx = len(self._hist_z) - 1
        if reading == 0.0:
            self._nd_index[key] = idx
        return idx, 0.0

    def _set_logw(self, logw: np.ndarray) -> None:
        self._logw = logw - logw.max()
        self._weights = None

    def _resample(self, *per_particle: np.ndarray) -> list[np.ndarray]:
        """Systematic resampling of the particles, their cached history log-likelihoods and any
        other per-particle arrays given (returned re-indexed); weights become uniform."""
        idx = systematic_resample(self.weights, self.rng, self.n)
        self.theta = self.theta[idx]
        self._hist_loglik = self._hist_loglik[idx]
        self._logw = np.full(self.n, -math.log(self.n))
        self._weights = None
        self.n_resamples += 1
        return [a[idx] for a in per_particle]

    def _resample_move(self, steps: int) -> float:
        self._resample()
        acc = [self._mh_sweep() for _ in range(steps)]
        return float(np.mean(acc)) if acc else math.nan

    def _mh_sweep(self) -> float:
        """One random-walk Metropolis–Hastings move of every particle, full-history target."""
        d = len(self._unknown)
        x = self.theta[:, self._unknown]
        cov = np.atleast_2d(np.cov(x, rowvar=False))
        # Gaussian kernel bandwidth of the regularised particle filter (Musso et al.),
        # as in the authors' code; a floor keeps the kernel alive if the particles collapse.
        h = (4.0 / (self.n * (d + 2))) ** (1.0 / (d + 4))
        floor = (1e-3 * self.prior.scales) ** 2
        cov = h * h * cov + np.diag(floor)
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            chol = np.diag(np.sqrt(np.maximum(np.diag(cov), floor)))
        proposal = self.theta.copy()
        proposal[:, self._unknown] += self.rng.standard_normal((self.n, d)) @ chol.T
        lp_prop = self.prior.log_density(proposal)
        lp_cur = self.prior.log_density(self.theta)
        active = np.isfinite(lp_prop)
        ll_prop = np.empty(self.n)
        pos, z, mult = self.history()
        history_log_likelihood(
            proposal, active, pos, z, mult, self.plume.min_distance, self._sp, ll_prop
        )
        log_u = np.log(self.rng.random(self.n))
        with np.errstate(invalid="ignore"):
            accept = active & (log_u < (ll_prop + lp_prop) - (self._hist_loglik + lp_cur))
        self.theta[accept] = proposal[accept]
        self._hist_loglik[accept] = ll_prop[accept]
        return float(accept.mean())

    def _tempered_update(
        self, ll_new: np.ndarray, entry: int, base_mult: float, ess0: float
    ) -> UpdateInfo:
        beta = 0.0
        stages = 0
        target = self.resample_threshold * self.n
        hist_base = self._hist_loglik.copy()
        acc: list[float] = []
        while beta < 1.0:
            stages += 1
            if stages >= self.max_tempering_stages or (
                effective_sample_size(_normalise(self._logw + (1.0 - beta) * ll_new)) >= target
            ):
                new_beta = 1.0
            else:
                lo, hi = beta, 1.0
                for _ in range(40):
                    mid = 0.5 * (lo + hi)
                    if (
                        effective_sample_size(_normalise(self._logw + (mid - beta) * ll_new))
                        >= target
                    ):
                        lo = mid
                    else:
                        hi = mid
                new_beta = max(lo, beta + 1e-6)
            # ll_new: the new reading's log-likelihood for the current particles.
            self._set_logw(self._logw + (new_beta - beta) * ll_new)
            self._hist_loglik = hist_base + new_beta * ll_new
            self._hist_mult[entry] = base_mult + new_beta
            beta = new_beta
            ll_new, hist_base = self._resample(ll_new, hist_base)
            for _ in range(max(1, self.mcmc_steps)):
                acc.append(self._mh_sweep())
            if beta < 1.0:
                # After the move, recompute the new reading's likelihood for the moved particles.
                ll_new = self.log_likelihood(
                    self.theta, np.array(self._hist_pos[entry]), self._hist_z[entry]
                )
                hist_base = self._hist_loglik - beta * ll_new
        self._hist_mult[entry] = base_mult + 1.0
        self.recoveries.append(
            {"reading_index": float(self.n_readings), "ess_before": ess0, "stages": float(stages)}
        )
        return UpdateInfo(ess0, True, float(np.mean(acc)), stages)


def _normalise(logw: np.ndarray) -> np.ndarray:
    w = np.exp(logw - logw.max())
    return w / w.sum()
