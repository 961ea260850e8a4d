"""The estimator interface: what a planner, a search and a record ask of a belief over the source
term, implemented by the particle filter (:class:`~dcee.estimation.ParticleFilter`) and the bank
of filters under competing reading models (:class:`~dcee.estimation.ModelBank`), so no caller
asks which one it holds."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

if TYPE_CHECKING:
    from dcee.estimation.priors import SourcePrior
    from dcee.models.plume import IsotropicPlume
    from dcee.models.sensor import Sensor


@dataclass(frozen=True)
class UpdateInfo:
    """What one :meth:`Estimator.update` did: the ESS the reading left (before any
    resampling), whether it resampled, the mean Metropolis–Hastings acceptance rate, tempering
    stages (1 = none), move sweeps, and the distinct particles after the move (N if none)."""

    ess: float
    resampled: bool
    acceptance: float
    tempering_stages: int
    move_sweeps: int = 0
    distinct: int = 0
    rejected: bool = False
    log_evidence: float = 0.0
    """log p(z | earlier readings) of this reading under the filter's model (0 if refused)"""


@dataclass(frozen=True)
class ReadingModelChoice:
    """Which reading model the readings chose, when an estimator compares several: its name,
    P(model | readings) and how often the choice changed."""

    name: str
    probability: float
    switches: int


@runtime_checkable
class Estimator(Protocol):
    """A weighted particle belief over the (8,) source term (x, y, z m; q g/s; u m/s; φ rad;
    ζ1 m²/s; ζ2 s) that assimilates readings (g/m³) taken at positions (3,) m."""

    @property
    def prior(self) -> SourcePrior: ...
    @property
    def sensor(self) -> Sensor:
        """The reading model the planners predict with."""
        ...

    @property
    def plume(self) -> IsotropicPlume: ...
    @property
    def n(self) -> int:
        """N, the particle count."""
        ...

    @property
    def theta(self) -> np.ndarray:
        """(N, 8) particles, every parameter (known ones at their values)."""
        ...

    @property
    def weights(self) -> np.ndarray:
        """(N,) normalised weights."""
        ...

    @property
    def source_locations(self) -> np.ndarray:
        """(N, 3) particle source locations, m."""
        ...

    @property
    def log_evidence(self) -> float:
        """log p(readings so far) under the estimator's model."""
        ...

    def update(self, position: np.ndarray, reading: float) -> UpdateInfo:
        """Assimilate one reading taken at ``position``."""
        ...

    def resample(self) -> None:
        """Resample-move now (systematic resampling, then the MCMC rejuvenation), whatever the
        effective sample size; the weights become uniform."""
        ...

    def update_wind(self, speed: float, direction: float) -> UpdateInfo:
        """Assimilate one anemometer reading: ``speed`` m/s, from ``direction`` rad."""
        ...

    def log_likelihood(self, theta: np.ndarray, position: np.ndarray, reading: float) -> np.ndarray:
        """(M,) log p(reading | theta) of (M, 8) source terms for a reading at ``position``."""
        ...

    def source_mean(self) -> np.ndarray:
        """(3,) posterior mean source location, m."""
        ...

    def source_cov(self) -> np.ndarray:
        """(3, 3) posterior covariance of the source location, m²."""
        ...

    def rmse(self, true_location: np.ndarray) -> float:
        """Posterior RMSE (m) of the source location about ``true_location`` (3,)."""
        ...

    def in_credible_region(
        self, true_location: np.ndarray, level: float = 0.95, floor: float = 0.0
    ) -> bool:
        """Whether ``true_location`` (3,) lies in the ``level`` credible region of the source
        location, widened by a model-discrepancy ``floor`` σ (m): the posterior convolved with
        N(0, σ² I) (:func:`~dcee.estimation.summaries.in_credible_ellipsoid`)."""
        ...

    def reading_model(self) -> ReadingModelChoice | None:
        """The reading model the readings chose, or None when there is only one."""
        ...


__all__ = ["Estimator", "ReadingModelChoice", "UpdateInfo"]
