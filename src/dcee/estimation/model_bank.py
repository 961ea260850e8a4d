"""Several reading models at once: one particle filter per model and Bayesian model selection.

How turbulent the plume is cannot be known before the search: the paper's calm model (Gaussian
reading noise, no intermittency) is exact for a steady plume and overconfident in a turbulent
one, and the fluctuation model (intermittent log-normal readings, meander) is honest in turbulence
but discounts every reading of a calm plume (measured: median final RMSE 0.57 m against 0.18 m on
the isotropic truth, docs/results.md). A :class:`ModelBank` estimates the turbulence level online
as a discrete unknown: it runs one :class:`~dcee.estimation.particle_filter.ParticleFilter` per
reading model m on the same readings and keeps each one's evidence log p(z₁…z_k | m)
(:attr:`ParticleFilter.log_evidence`), so

    P(m | z₁…z_k) ∝ P(m) · p(z₁…z_k | m).

Everything that reads the belief (the planners, the estimate, the records) reads the *selected*
member: the most probable model (ties keep the earlier member); the 95 % region is the members'
mixture's (:meth:`ModelBank.in_credible_region`). Every member assimilates every reading, so a
model that becomes the most probable late has its full posterior ready. A :class:`ModelBank`
offers the part of the :class:`ParticleFilter` interface that a :class:`~dcee.searcher.Searcher`,
the simulation and the interfaces use, answered by the selected member, plus
:attr:`probabilities`, :attr:`selected_name` and :attr:`switches`.

Cost: one filter update per member per reading; the planners' cost is unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.special import logsumexp

from dcee.errors import DceeInputError
from dcee.estimation.base import ReadingModelChoice, UpdateInfo
from dcee.estimation.particle_filter import ParticleFilter
from dcee.estimation.priors import SourcePrior
from dcee.estimation.summaries import in_credible_ellipsoid
from dcee.models.plume import IsotropicPlume
from dcee.models.sensor import Sensor


class ModelBank:
    """Particle filters under different reading models, selected by their posterior probability.

    Parameters
    ----------
    members: one filter per model, all with the same prior and particle count.
    names: a name per model (for records), unique.
    prior_probabilities: P(m), positive; None: equal.
    """

    def __init__(
        self,
        members: Sequence[ParticleFilter],
        names: Sequence[str],
        prior_probabilities: Sequence[float] | None = None,
    ) -> None:
        if len(members) < 1 or len(members) != len(names) or len(set(names)) != len(names):
            raise DceeInputError("members", "need one filter per model and unique model names")
        probs = np.ones(len(members)) if prior_probabilities is None else prior_probabilities
        probs = np.asarray(probs, dtype=np.float64)
        if probs.shape != (len(members),) or not np.all(np.isfinite(probs) & (probs > 0)):
            raise DceeInputError("prior_probabilities", "must be one positive number per model")
        self.members = list(members)
        self.names = tuple(names)
        self.log_prior = np.log(probs / probs.sum())
        self.selected = int(np.argmax(self.log_prior))
        self.switches = 0
        """how often the selected model changed"""

    # --- model probabilities --------------------------------------------------------------

    def _log_joint(self) -> np.ndarray:
        """(M,) log P(m) + log p(readings | m)."""
        return self.log_prior + np.array([f.log_evidence for f in self.members])

    @property
    def log_evidence(self) -> float:
        """log p(readings) under the model mixture."""
        return float(logsumexp(self._log_joint()))

    @property
    def log_posterior(self) -> np.ndarray:
        """(M,) log P(m | readings), normalised."""
        joint = self._log_joint()
        return joint - logsumexp(joint)

    @property
    def probabilities(self) -> np.ndarray:
        """(M,) P(m | readings)."""
        return np.exp(self.log_posterior)

    @property
    def selected_probability(self) -> float:
        """P(selected model | readings)."""
        return float(self.probabilities[self.selected])

    @property
    def selected_name(self) -> str:
        return self.names[self.selected]

    @property
    def current(self) -> ParticleFilter:
        """The selected member."""
        return self.members[self.selected]

    def _select(self) -> None:
        best = int(np.argmax(self.log_posterior))
        if best != self.selected:
            self.switches += 1
            self.selected = best

    def update(self, position: np.ndarray, reading: float) -> UpdateInfo:
        """Assimilate one reading into every member; returns the selected member's
        :class:`UpdateInfo` (selected after the reading)."""
        infos = [f.update(position, reading) for f in self.members]
        self._select()
        return infos[self.selected]

    def update_wind(self, speed: float, direction: float) -> UpdateInfo:
        """Assimilate one anemometer reading into every member (it does not change which
        model the readings select: every member predicts the wind alike)."""
        infos = [f.update_wind(speed, direction) for f in self.members]
        return infos[self.selected]

    def resample(self) -> None:
        """Resample-move every member now (see :meth:`ParticleFilter.resample`)."""
        for member in self.members:
            member.resample()

    def reading_model(self) -> ReadingModelChoice:
        """The selected reading model, its posterior probability and the switches so far."""
        return ReadingModelChoice(self.selected_name, self.selected_probability, self.switches)

    # --- the ParticleFilter interface, answered by the selected member ----------------------

    @property
    def prior(self) -> SourcePrior:
        return self.current.prior

    @property
    def sensor(self) -> Sensor:
        return self.current.sensor

    @property
    def plume(self) -> IsotropicPlume:
        return self.current.plume

    @property
    def n(self) -> int:
        return self.current.n

    @property
    def theta(self) -> np.ndarray:
        return self.current.theta

    def planning_particles(self) -> np.ndarray:
        """The current model's particles, read-only (ResampleMove.planning_particles)."""
        return self.current.planning_particles()

    @property
    def weights(self) -> np.ndarray:
        return self.current.weights

    @property
    def particles(self) -> np.ndarray:
        return self.current.particles

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return self.current.parameter_names

    @property
    def source_locations(self) -> np.ndarray:
        return self.current.source_locations

    @property
    def ess(self) -> float:
        return self.current.ess

    @property
    def n_readings(self) -> int:
        return self.current.n_readings

    @property
    def n_resamples(self) -> int:
        return self.current.n_resamples

    @property
    def recoveries(self) -> list[dict[str, float | str]]:
        return self.current.recoveries

    def mean(self) -> np.ndarray:
        return self.current.mean()

    def cov(self) -> np.ndarray:
        return self.current.cov()

    def source_mean(self) -> np.ndarray:
        return self.current.source_mean()

    def source_cov(self) -> np.ndarray:
        return self.current.source_cov()

    def rmse(self, true_location: np.ndarray) -> float:
        return self.current.rmse(true_location)

    def in_credible_region(
        self, true_location: np.ndarray, level: float = 0.95, floor: float = 0.0
    ) -> bool:
        """Whether ``true_location`` (3,) lies in the ``level`` credible region of the models'
        mixture, widened by ``floor`` (m) as the particle filter's: every member's particles,
        each weighted by its posterior probability P(m | readings) (the Bayesian average over
        the reading models; one member: its own region).
        Where the readings cannot yet tell the models apart, the region holds the locations
        each of them supports, not only the selected one's (measured on point and area
        releases of the tuning truths: docs/results/mixture-region-prior-13-40)."""
        cols = self.current._loc_block
        if not cols:
            return True
        points = np.vstack([m.theta[:, cols] for m in self.members])
        weights = np.concatenate(
            [p * m.weights for p, m in zip(self.probabilities, self.members, strict=True)]
        )
        truth = np.asarray(true_location, dtype=np.float64)[cols]
        return in_credible_ellipsoid(points, weights / weights.sum(), truth, level, floor)

    def history(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.current.history()

    def log_likelihood(self, theta: np.ndarray, position: np.ndarray, reading: float) -> np.ndarray:
        return self.current.log_likelihood(theta, position, reading)
