"""Particle filter for the source term (the paper's Algorithm 1), with a full-history MCMC move.

Per reading: weights are updated in log space; when the effective sample size (ESS) falls below
``resample_threshold · N`` the particles are resampled systematically and *rejuvenated* by
Metropolis–Hastings sweeps whose acceptance uses the prior and the likelihood of *every* reading
so far, so the chain leaves the true posterior invariant. (AutoSTE and Stone Soup accept on the
latest reading only, which does not target the posterior.)

The resample-move step (systematic resampling, Metropolis–Hastings rejuvenation that keeps
every mode, likelihood tempering when a reading would collapse the weights) is
:class:`~dcee.estimation.resample_move.ResampleMove`.

Outlier safety: a reading above the sensor's ``max_reading`` (or not a finite real number) is
refused with :class:`DceeInputError` before anything changes. A reading that *no* particle can
explain (log-likelihood −inf or NaN for all) is not assimilated and is recorded as a recovery of
kind "rejected"; so no sequence of inputs leaves the filter with no live particle. The sensor's
outlier component (``Sensor.outlier``) bounds the influence of any finite reading.

Model evidence: every assimilated reading adds log Σᵢ wᵢ p(z | Θᵢ) (the normalised weights
before the reading) to :attr:`ParticleFilter.log_evidence`, the standard SMC estimate of
log p(z₁…z_k | model); :class:`dcee.estimation.model_bank.ModelBank` compares reading models
with it. A refused reading adds nothing.

Known parameters stay at their fixed values: the filter stores full (N, 8) source terms but only
the unknown columns are sampled, moved and reported by :attr:`ParticleFilter.particles`.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.estimation.base import ReadingModelChoice, UpdateInfo
from dcee.estimation.priors import SourcePrior
from dcee.estimation.resample_move import ResampleMove
from dcee.estimation.resampling import (
    effective_sample_size,
    reweighted,
)
from dcee.estimation.summaries import in_credible_ellipsoid, weighted_moments, weighted_rmse
from dcee.models.anemometer import PHI_COLUMN, U_COLUMN, Anemometer, WindEvidence
from dcee.models.plume import IsotropicPlume
from dcee.models.sensor import Sensor


class ParticleFilter(ResampleMove):
    """Sequential Monte Carlo estimate of the source term.

    Parameters
    ----------
    prior: which parameters are unknown and their priors.
    sensor, plume: the measurement and dispersion models.
    n_particles: N.
    seed: an int or a ``numpy.random.Generator``; every random draw of the filter comes from it.
    resample_threshold: resample when ESS < this · N (paper: N/2).
    mcmc_steps: least Metropolis–Hastings sweeps after each resampling.
    collapse_threshold: below this ESS/N a reading is assimilated by tempering (see module doc).
    global_share: share of particles proposing a location from the prior in each sweep.
    diversify: sweep until this share of the particles has moved since the resampling.
    max_sweeps: most sweeps after one resampling.
    move_history: most history entries a sweep may read per particle (``search.move_history``;
        None: no limit).
    """

    # checkpoints written before these existed restore with them
    move_history: int | None = None
    anemometer: Anemometer | None = None
    wind: WindEvidence = WindEvidence()
    wind_log_evidence: float = 0.0

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
        global_share: float = 0.2,
        diversify: float = 0.5,
        max_sweeps: int = 8,
        reading_weight: float = 1.0,
        anemometer: Anemometer | None = None,
        repeat_radius: float = 0.0,
        repeat_power: float = 1.0,
        move_history: int | None = None,
    ) -> None:
        if move_history is not None and not (
            isinstance(move_history, int)
            and not isinstance(move_history, bool)
            and move_history >= 1
        ):
            raise DceeInputError(
                "search.move_history", f"must be an integer >= 1 or None, got {move_history!r}"
            )
        if not (isinstance(reading_weight, int | float) and 0 < reading_weight <= 1):
            raise DceeInputError(
                "estimator.reading_weight", f"must be in (0, 1], got {reading_weight!r}"
            )
        if not (isinstance(repeat_radius, int | float) and 0 <= repeat_radius < math.inf):
            raise DceeInputError(
                "estimator.repeat_radius",
                f"must be a finite number of m >= 0, got {repeat_radius!r}",
            )
        if not (isinstance(repeat_power, int | float) and 0 < repeat_power <= 2):
            raise DceeInputError(
                "estimator.repeat_power", f"must be in (0, 2], got {repeat_power!r}"
            )
        if int(n_particles) != n_particles or n_particles < 2:
            raise DceeInputError("particles", f"must be an integer >= 2, got {n_particles!r}")
        if not 0 < resample_threshold <= 1:
            raise DceeInputError("resample_threshold", "must be in (0, 1]")
        if not 0 <= collapse_threshold < resample_threshold:
            raise DceeInputError("collapse_threshold", "must be in [0, resample_threshold)")
        if mcmc_steps < 0:
            raise DceeInputError("mcmc_steps", "must be >= 0")
        if not 0 <= global_share <= 1:
            raise DceeInputError("global_share", f"must be in [0, 1], got {global_share}")
        if not 0 <= diversify <= 1:
            raise DceeInputError("diversify", f"must be in [0, 1], got {diversify}")
        if int(max_sweeps) != max_sweeps or max_sweeps < max(1, mcmc_steps):
            raise DceeInputError(
                "max_sweeps", f"must be an integer >= mcmc_steps, got {max_sweeps}"
            )
        self.prior = prior
        self.sensor = sensor
        self.plume = plume or IsotropicPlume()
        self.n = int(n_particles)
        seeds = np.random.Generator | np.random.SeedSequence | np.random.BitGenerator
        if not isinstance(seed, seeds) and not (
            isinstance(seed, int | np.integer) and not isinstance(seed, bool) and seed >= 0
        ):
            raise DceeInputError(
                "seed", f"must be an integer >= 0 or a numpy.random.Generator, got {seed!r}"
            )
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        self.resample_threshold = resample_threshold
        self.mcmc_steps = mcmc_steps
        self.collapse_threshold = collapse_threshold
        self.max_tempering_stages = max_tempering_stages
        self.global_share = global_share
        self.diversify = diversify
        self.max_sweeps = int(max_sweeps)
        self.move_history = move_history
        self.reading_weight = float(reading_weight)
        self.repeat_radius = float(repeat_radius)
        self.repeat_power = float(repeat_power)
        # the weight of the reading being assimilated (reading_weight, discounted for a repeat)
        self._weight_now = self.reading_weight
        self._unknown = np.array(prior.unknown)
        # the unknown location columns: the block the global proposal redraws from the prior
        self._loc_block = [int(i) for i in self._unknown if i < 3]
        self._sp = sensor.params
        self.theta = prior.sample(self.rng, self.n)
        self._logw = np.full(self.n, -math.log(self.n))
        self._weights: np.ndarray | None = None
        self._hist_loglik = np.zeros(self.n)
        self._hist_pos: list[tuple[float, float, float]] = []
        self._hist_z: list[float] = []
        self._hist_mult: list[float] = []
        self._nd_index: dict[tuple[float, float, float], int] = {}
        # every assimilated reading's position in order, with repeat_radius > 0 (its runs)
        self._hist_order: list[tuple[float, float, float]] = []
        self.n_readings = 0
        self.recoveries: list[dict[str, float | str]] = []
        self._origin = np.arange(self.n)
        self.n_resamples = 0
        self.log_evidence = 0.0
        """log p(every assimilated reading | model), the SMC estimate (see the module doc)"""
        self.anemometer = anemometer
        """the wind readings' model (:meth:`update_wind`); None: this filter takes none"""
        self.wind = WindEvidence()
        """sufficient statistics of the wind readings assimilated so far"""

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
        return weighted_moments(self.particles, self.weights)[1]

    def source_mean(self) -> np.ndarray:
        """(3,) posterior mean source location."""
        return self.weights @ self.source_locations

    def source_cov(self) -> np.ndarray:
        """(3, 3) posterior covariance of the source location."""
        return weighted_moments(self.source_locations, self.weights)[1]

    def rmse(self, true_location: np.ndarray) -> float:
        """√(Σ wᵢ ‖sᵢ − s‖²): RMSE of the particles' source locations about ``true_location``."""
        return weighted_rmse(self.source_locations, self.weights, true_location)

    def in_credible_region(
        self, true_location: np.ndarray, level: float = 0.95, floor: float = 0.0
    ) -> bool:
        """Whether ``true_location`` (3,) lies in the posterior's ``level`` credible region of
        the unknown location coordinates, widened by a model-discrepancy ``floor`` (m; see
        :func:`~dcee.estimation.summaries.in_credible_ellipsoid`)."""
        cols = self._loc_block  # unknown location columns, in order
        if not cols:
            return True
        x = self.theta[:, cols]
        truth = np.asarray(true_location, dtype=np.float64)[cols]
        return in_credible_ellipsoid(x, self.weights, truth, level, floor)

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

    def __setstate__(self, state: dict[str, Any]) -> None:
        # filters checkpointed before estimator.repeat_radius: off, and no run to continue
        state = {"repeat_radius": 0.0, "repeat_power": 1.0, "_hist_order": [], **state}
        state.setdefault("_weight_now", state.get("reading_weight", 1.0))
        self.__dict__.update(state)

    # --- update -----------------------------------------------------------------------------

    def log_likelihood(
        self,
        theta: np.ndarray,
        position: np.ndarray,
        reading: float,
        weight: float | None = None,
    ) -> np.ndarray:
        """(N,) w · log p(reading | Θ) at ``position`` for source terms ``theta`` (N, 8), w =
        ``weight`` (default the filter's ``reading_weight``; 1: the plain likelihood), applied
        as the reading's multiplicity in the kernel."""
        w = self.reading_weight if weight is None else weight
        out = np.empty(theta.shape[0])
        self._history_ll(
            theta,
            np.ones(theta.shape[0], dtype=np.bool_),
            np.asarray(position, dtype=np.float64).reshape(1, 3),
            np.array([reading], dtype=np.float64),
            np.array([w], dtype=np.float64),
            out,
        )
        return out

    def repeat_weight(self, position: np.ndarray) -> float:
        """The weight a reading at ``position`` (3,) m gets: ``reading_weight`` / (1 + m)^p, m
        the number of readings just before it, in an unbroken run, taken within
        ``repeat_radius`` m of it (0: off, every reading ``reading_weight``), p
        ``repeat_power``. A robot holding one spot sees the same puffs in successive readings,
        so with p = 1 its n readings there weigh w · (1 + 1/2 + … + 1/n), growing like
        w · ln n, not w · n; with p = 1/2 like 2 w √n."""
        if self.repeat_radius <= 0.0 or not self._hist_order:
            return self.reading_weight
        reach = self.repeat_radius * (1.0 + 1e-9) + 1e-9
        m = 0
        for earlier in reversed(self._hist_order):
            if math.dist(earlier, position) > reach:
                break
            m += 1
        return self.reading_weight / (1.0 + m) ** self.repeat_power

    def update(self, position: np.ndarray, reading: float) -> UpdateInfo:
        """Assimilate one reading (g/m³; below the threshold = non-detection) taken at position."""
        try:
            position = np.asarray(position, dtype=np.float64)
        except (TypeError, ValueError):
            raise DceeInputError(
                "position", f"must be 3 finite numbers, got {position!r}"
            ) from None
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise DceeInputError("position", f"must be 3 finite numbers, got {position!r}")
        reading = self.sensor.check_reading(reading)
        if reading < self.sensor.threshold:
            reading = 0.0
        self._weight_now = self.repeat_weight(position)
        ll_new = self.log_likelihood(self.theta, position, reading, self._weight_now)
        if self.repeat_radius > 0.0:
            self._hist_order.append(tuple(position.tolist()))
        ll_new[np.isnan(ll_new)] = -np.inf
        live = np.isfinite(self._logw)
        if not np.any(np.isfinite(ll_new[live])):
            # No live particle can explain the reading at all: assimilating it would kill the
            # filter. Keep the belief and record the refusal.
            self.n_readings += 1
            self.recoveries.append(
                {"kind": "rejected", "reading_index": float(self.n_readings), "reading": reading}
            )
            return UpdateInfo(self.ess, False, math.nan, 1, 0, self.n, rejected=True)
        entry, base_mult = self._add_to_history(position, reading)
        self.n_readings += 1

        logw, log_ev, ess, weights = self._reweighted(ll_new)
        self.log_evidence += log_ev
        if ess >= self.collapse_threshold * self.n:
            self._hist_loglik += ll_new
            self._set_logw(logw)
            self._weights = weights  # normalised already (resampling.reweighted)
            return self._resampled_if_needed(ess, log_ev)
        info = self._tempered_update(ll_new, entry, base_mult, ess)
        return dataclasses.replace(info, log_evidence=log_ev)

    def update_wind(self, speed: float, direction: float) -> UpdateInfo:
        """Assimilate one anemometer reading: wind ``speed`` m/s from ``direction`` rad
        (counter-clockwise from +x, as φ). Its likelihood (:mod:`dcee.models.anemometer`)
        multiplies the weights; from then on the resample-move target includes every wind
        reading (through their sufficient statistics). With u and φ both known a reading
        carries no information and only counts."""
        if self.anemometer is None:
            raise DceeInputError("anemometer", "this filter was built without an anemometer model")
        speed, direction = self.anemometer.check(speed, direction)
        new = WindEvidence.of(speed, direction)
        self.wind = self.wind + new
        if not ({U_COLUMN, PHI_COLUMN} & {int(i) for i in self._unknown}):
            return UpdateInfo(self.ess, False, math.nan, 1, 0, self.n)
        logw, log_ev, ess, _ = self._reweighted(new.log_likelihood(self.theta, self.anemometer))
        # kept apart from log_evidence: every reading model predicts the wind alike, so the
        # model bank compares its members on the concentration readings only
        self.wind_log_evidence += log_ev
        self._set_logw(logw)
        return self._resampled_if_needed(ess, log_ev)

    def _reweighted(self, ll: np.ndarray) -> tuple[np.ndarray, float, float, np.ndarray]:
        """The log weights after a reading of per-particle log-likelihood ``ll`` (N,), the
        reading's log evidence log Σ wᵢ p(z|Θᵢ) (wᵢ the normalised weights before it), the
        effective sample size after it and the normalised weights after it."""
        logw, log_ev, ess, weights = reweighted(
            self._logw, np.ascontiguousarray(ll, dtype=np.float64)
        )
        return logw, float(log_ev), float(ess), weights

    def _resampled_if_needed(self, ess: float, log_ev: float) -> UpdateInfo:
        """Resample-move when the effective sample size fell below the threshold."""
        if ess < self.resample_threshold * self.n:
            self._resample()
            acc, sweeps, distinct = self._rejuvenate()
            return UpdateInfo(ess, True, acc, 1, sweeps, distinct, log_evidence=log_ev)
        return UpdateInfo(ess, False, math.nan, 1, 0, self.n, log_evidence=log_ev)

    def _log_prior(self, theta: np.ndarray) -> np.ndarray:
        """(N,) log prior density times the wind readings' likelihood (the part of the target
        that does not depend on the concentration readings)."""
        lp = self.prior.log_density(theta)
        if self.wind.n and self.anemometer is not None:
            with np.errstate(invalid="ignore"):
                lp = lp + self.wind.log_likelihood(theta, self.anemometer)
        return lp

    def resample(self) -> None:
        """Resample-move now (systematic resampling, then the MCMC rejuvenation of
        :meth:`update`), whatever the effective sample size; the weights become uniform."""
        self._resample()
        self._rejuvenate()

    def reading_model(self) -> ReadingModelChoice | None:
        """None: a lone filter has one reading model (see :class:`ModelBank`)."""
        return None

    # --- internals --------------------------------------------------------------------------

    def _add_to_history(self, position: np.ndarray, reading: float) -> tuple[int, float]:
        key = tuple(np.round(position, 9).tolist())
        if reading == 0.0 and key in self._nd_index:
            idx = self._nd_index[key]
            base = self._hist_mult[idx]
            self._hist_mult[idx] = base + self._weight_now
            return idx, base
        self._hist_pos.append(key)
        self._hist_z.append(reading)
        self._hist_mult.append(self._weight_now)
        idx = len(self._hist_z) - 1
        if reading == 0.0:
            self._nd_index[key] = idx
        return idx, 0.0

    def _set_logw(self, logw: np.ndarray) -> None:
        self._logw = logw - logw.max()
        self._weights = None
