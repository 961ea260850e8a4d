"""An unknown number of releases: one filter per count K = 0 … K_max and Bayesian model
selection over K.

A leaking plant rarely has exactly one leak. A :class:`SourceCountBank` runs, on the same
readings, the no-release model (every reading is noise; its evidence is exact), the ordinary
one-release :class:`~dcee.estimation.particle_filter.ParticleFilter` and a
:class:`~dcee.estimation.multi_source.MultiSourceFilter` for each K ≥ 2, and keeps each one's
evidence log p(z₁…z_k | K) (the SMC estimate, re-anchored every :data:`EVIDENCE_EVERY`
readings by bridge sampling from the present particles: :mod:`dcee.estimation.evidence`), so

    P(K | z₁…z_k) ∝ P(K) · p(z₁…z_k | K).

This is the multi-hypothesis form of a reversible-jump sampler over K (Yee 2008): the same
posterior over the count and each count's posterior over the releases, without moves between
dimensions. The Occam factor that keeps a surplus release from being believed is the evidence's
own: a K + 1 model pays for the prior volume of a release the readings never saw.

What the planners read: the *target*. First the most probable count's least-localised release,
until each of its releases is found (spread √tr P at most ``found``, 1 m at the paper's scale:
:data:`FOUND_SHARE`); then the least-localised release among the counts K ≥ 1 still plausible
(P(K) ≥ ``plausible``) and the count one above the most probable (however improbable): the
broad marginal of a further release is the target, so the robot looks where one could still be,
until the readings rule it out or find it. Without that last count the robot stayed at the
releases it had found once a further one had become improbable, although the readings had never
reached most of the places where it could be (issue 45: in each of the nine three-release
tuning searches that answered two, the third release's gas had reached at most 6 of ~450
readings). The stop rule reads the *settled* target, the same without the count above and with
"localised" (the stop rule's threshold) for "found", so a search may stop once every plausible
count's releases are localised. The planners see the target release as a one-release belief
(its location and rate with the shared wind): their hypothesised readings leave out the other
releases' gas, an approximation of planning, not of estimation (the filters' likelihood sums
every release).

The answer (:meth:`SourceCountBank.estimated_sources`) is the most probable count's releases, at
their posterior means.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.special import logsumexp

from dcee.errors import DceeInputError
from dcee.estimation.base import ReadingModelChoice, UpdateInfo
from dcee.estimation.evidence import bridge_log_evidence, one_more_log_evidence
from dcee.estimation.multi_source import MultiSourceFilter
from dcee.estimation.particle_filter import ParticleFilter
from dcee.estimation.priors import SourcePrior
from dcee.estimation.release_target import DEFAULT_PLAUSIBLE, FOUND_SHARE, choose_targets
from dcee.estimation.summaries import in_credible_ellipsoid, weighted_moments, weighted_rmse
from dcee.models.plume import IsotropicPlume
from dcee.models.sensor import Sensor

EVIDENCE_EVERY = 30
"""Readings between two bridge-sampling anchors of each count's evidence. The SMC estimate
alone keeps, for good, the deficit of readings a lagging filter found surprising (a release it
had not found yet) and chose the count by the path its filters took
(:mod:`dcee.estimation.evidence`); every this many readings each count's evidence is
re-estimated from its present particles, and the SMC terms of the readings since are added to
it. Set for cost: an anchor of the counts 1-3 (three bridge estimates and two of one release
more) takes about 1 s at 10,000 particles and 450 readings, 15 anchors in the paper's 450
readings."""


class NoSource:
    """K = 0: no release; every reading is noise (a detection a false alarm or an outlier).
    Its evidence is exact: Σ_k w_k log p(z_k | C = 0), w_k each reading's weight as the
    filters give it (``reading_weight``, the repeat discount)."""

    def __init__(self, like: ParticleFilter) -> None:
        self.sensor = like.sensor
        self.reading_weight = like.reading_weight
        self.repeat_radius = like.repeat_radius
        self.repeat_power = like.repeat_power
        self._hist_order: list[tuple[float, float, float]] = []
        self.log_evidence = 0.0

    def update(self, position: np.ndarray, reading: float) -> None:
        position = np.asarray(position, dtype=np.float64)
        weight = ParticleFilter.repeat_weight(self, position)  # type: ignore[arg-type]
        if self.repeat_radius > 0.0:
            self._hist_order.append(tuple(position.tolist()))
        z = 0.0 if reading < self.sensor.threshold else float(reading)
        self.log_evidence += weight * float(self.sensor.log_likelihood(z, 0.0, np.inf))


class SourceCountBank:
    """Filters over K = 0 … K_max releases, selected by P(K | readings) (see the module doc).

    Parameters
    ----------
    members: the K = 1 … K_max filters, in order (a :class:`ParticleFilter`, then
        :class:`MultiSourceFilter` with 2, 3, … releases), on the same prior and readings.
    count_prior: P(K) for K = 0 … K_max, positive; None: equal.
    plausible: the least P(K) whose releases the target and the stop rule consider.
    localised: m; the settled target (:meth:`settled_target`, what the stop rule reads) is the
        most probable count's releases until every one's spread √tr P is at most this (the
        stop rule's threshold: :func:`dcee.runs.make_searcher`).
    found: m; the same for the planners' :meth:`target`, after which they also look for one
        release more (:data:`FOUND_SHARE` of ``search.acquired_rmse`` in a search).
    seed: an int or a ``numpy.random.Generator`` for the bridge-sampling draws
        (:data:`EVIDENCE_EVERY`).
    """

    def __init__(
        self,
        members: Sequence[ParticleFilter],
        count_prior: Sequence[float] | None = None,
        plausible: float = DEFAULT_PLAUSIBLE,
        localised: float = 0.45,
        found: float = 1.0,
        seed: int | np.random.Generator | None = 0,
    ) -> None:
        members = list(members)
        if not members or not isinstance(members[0], ParticleFilter):
            raise DceeInputError("members", "need the one-release filter first")
        for k, m in enumerate(members[1:], start=2):
            if not (isinstance(m, MultiSourceFilter) and m.n_sources == k):
                raise DceeInputError("members", f"member {k} must be a {k}-release filter")
        probs = np.ones(len(members) + 1) if count_prior is None else count_prior
        probs = np.asarray(probs, dtype=np.float64)
        if probs.shape != (len(members) + 1,) or not np.all(np.isfinite(probs) & (probs > 0)):
            raise DceeInputError(
                "estimator.count_prior", f"must be {len(members) + 1} positive numbers (K = 0 …)"
            )
        if not 0 < plausible < 1:
            raise DceeInputError("plausible", f"must be in (0, 1), got {plausible!r}")
        self.members = members
        self.none = NoSource(members[0])
        self.log_prior = np.log(probs / probs.sum())
        self.plausible = float(plausible)
        self.localised = float(localised)
        self.found = float(found)
        self.switches = 0
        self._rng = np.random.default_rng(seed)
        # bridge-sampling estimate minus the SMC estimate of each member at the last anchor
        self._anchor = np.zeros(len(members))
        self._count = int(np.argmax(self.log_prior))
        # the target and its rows, kept while the belief is unchanged (:meth:`_state`)
        self._target: tuple[tuple[int, ...], tuple[int, int], tuple[int, int]] | None = None
        self._target_rows: tuple[tuple[int, ...], np.ndarray] | None = None

    @property
    def max_sources(self) -> int:
        return len(self.members)

    # --- the posterior over the count ---------------------------------------------------------

    def _log_joint(self) -> np.ndarray:
        ev = [m.log_evidence + a for m, a in zip(self.members, self._anchor, strict=True)]
        return self.log_prior + np.array([self.none.log_evidence, *ev])

    def _reanchor(self) -> None:
        """Re-estimate every member's evidence from its present particles by bridge sampling
        (:func:`~dcee.estimation.evidence.bridge_log_evidence`), for K ≥ 2 at least the K − 1
        filter's with one release more anywhere
        (:func:`~dcee.estimation.evidence.one_more_log_evidence`); the SMC terms of later
        readings are added to it until the next anchor (:data:`EVIDENCE_EVERY`)."""
        previous = math.nan
        for i, m in enumerate(self.members):
            est = bridge_log_evidence(m, self._rng)
            if i > 0 and math.isfinite(previous):
                est = np.nanmax(
                    [est, one_more_log_evidence(self.members[i - 1], m, previous, self._rng)]
                )
            if math.isfinite(est):
                self._anchor[i] = est - m.log_evidence
            previous = m.log_evidence + self._anchor[i]

    @property
    def log_evidence(self) -> float:
        return float(logsumexp(self._log_joint()))

    @property
    def count_probabilities(self) -> np.ndarray:
        """(K_max + 1,) P(K | readings) for K = 0 … K_max."""
        joint = self._log_joint()
        return np.exp(joint - logsumexp(joint))

    @property
    def estimated_count(self) -> int:
        """The most probable count."""
        return int(np.argmax(self.count_probabilities))

    def member(self, k: int) -> ParticleFilter:
        """The K = k filter (k ≥ 1)."""
        return self.members[k - 1]

    def release_summary(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """((k, 3) mean locations m, (k, 3, 3) covariances m²) of the K = k filter's releases."""
        f = self.member(k)
        if isinstance(f, MultiSourceFilter):
            return f.release_means(), f.release_covs()
        return f.source_mean()[None, :], f.source_cov()[None, :, :]

    def estimated_sources(self) -> np.ndarray:
        """(K̂, 3) the most probable count's releases at their posterior means (0 rows: none)."""
        k = self.estimated_count
        return np.empty((0, 3)) if k == 0 else self.release_summary(k)[0]

    # --- the target: the least-localised plausible release ------------------------------------

    def _state(self) -> tuple[int, ...]:
        """What changes the belief: a reading (every member counts it), a wind reading or a
        resampling (the members' particles move only then)."""
        first = self.members[0]
        return (first.n_readings, first.wind.n, *(m.n_resamples for m in self.members))

    def target(self) -> tuple[int, int]:
        """(K, j): the release the planners go after. First the most probable count's
        least-localised release, while its spread √tr P exceeds ``found`` m; then the
        release with the largest spread among the counts K ≥ 1 with P(K) ≥ ``plausible`` and
        the count one above the most probable (a further release the readings have not ruled
        out). Count 0 most probable: the one-release filter's. Computed once per belief state
        (the planners, the stop rule and the records each ask)."""
        return self._targets()[0]

    def settled_target(self) -> tuple[int, int]:
        """(K, j): :meth:`target` without the count above the most probable one unless it is
        plausible itself: the release the stop rule and the estimate (:meth:`source_cov`)
        read, so that a search may stop once every plausible release is localised."""
        return self._targets()[1]

    def _targets(self) -> tuple[tuple[int, int], tuple[int, int]]:
        """(:meth:`target`, :meth:`settled_target`), chosen once per belief state
        (:func:`~dcee.estimation.release_target.choose_targets`)."""
        state = self._state()
        if self._target is None or self._target[0] != state:
            target, settled = choose_targets(
                self.count_probabilities,
                lambda k: self.release_summary(k)[1],
                self.plausible,
                found=self.found,
                localised=self.localised,
            )
            self._target = (state, target, settled)
        return self._target[1], self._target[2]

    def _target_member(self) -> tuple[ParticleFilter, int]:
        k, j = self.target()
        return self.member(k), j

    @property
    def theta(self) -> np.ndarray:
        """(N, 8) the target release of every particle of its filter (what planners read)."""
        f, j = self._target_member()
        key = (*self.target(), f.n_resamples)  # the rows move only when the filter resamples
        if self._target_rows is not None and self._target_rows[0] == key:
            return self._target_rows[1]
        rows = f.release_rows(j) if isinstance(f, MultiSourceFilter) else f.theta
        self._target_rows = (key, rows)
        return rows

    @property
    def weights(self) -> np.ndarray:
        return self._target_member()[0].weights

    def estimate_particles(self) -> tuple[np.ndarray, np.ndarray]:
        """((N, 8 + 4 (K̂ − 1)) particles, (N,) weights) of the most probable count's filter
        (the one-release filter's when it is 0): the answer's particles, every release."""
        f = self.member(max(self.estimated_count, 1))
        return f.theta, f.weights

    def joint_particles(self) -> tuple[np.ndarray, np.ndarray]:
        """((N, 8 + 4 (K − 1)) particles, (N,) weights) of the target's filter: every release,
        for what needs the gas of all of them (:mod:`dcee.exploration`)."""
        f = self._target_member()[0]
        return f.theta, f.weights

    def _target_locations(self) -> np.ndarray:
        f, j = self._target_member()
        return f.release_locations(j) if isinstance(f, MultiSourceFilter) else f.source_locations

    @property
    def source_locations(self) -> np.ndarray:
        return self._target_locations()

    def _settled_release(self) -> tuple[np.ndarray, np.ndarray]:
        """((N, 3) locations, (N,) weights) of :meth:`settled_target`."""
        k, j = self.settled_target()
        f = self.member(k)
        locations = (
            f.release_locations(j) if isinstance(f, MultiSourceFilter) else f.source_locations
        )
        return locations, f.weights

    def source_mean(self) -> np.ndarray:
        """(3,) the settled target's posterior mean (what the stop rule and the records read)."""
        locations, weights = self._settled_release()
        return weights @ locations

    def source_cov(self) -> np.ndarray:
        """(3, 3) the settled target's posterior covariance: its spread is the largest of
        every plausible release's, so the stop rule holds only when all are localised."""
        return weighted_moments(*self._settled_release())[1]

    # --- updates ------------------------------------------------------------------------------

    def update(self, position: np.ndarray, reading: float) -> UpdateInfo:
        """Assimilate one reading into every count's filter; returns the one-release filter's
        :class:`UpdateInfo` (it validates the reading first)."""
        info = self.members[0].update(position, reading)
        if not info.rejected:
            for m in self.members[1:]:
                m.update(position, reading)
            self.none.update(position, reading)
            if self.members[0].n_readings % EVIDENCE_EVERY == 0:
                self._reanchor()
        count = self.estimated_count
        if count != self._count:
            self.switches += 1
            self._count = count
        return info

    def update_wind(self, speed: float, direction: float) -> UpdateInfo:
        infos = [m.update_wind(speed, direction) for m in self.members]
        return infos[0]

    def resample(self) -> None:
        for m in self.members:
            m.resample()

    def reading_model(self) -> ReadingModelChoice | None:
        return None

    # --- the rest of the estimator interface ----------------------------------------------------

    @property
    def prior(self) -> SourcePrior:
        return self.members[0].prior

    @property
    def sensor(self) -> Sensor:
        return self.members[0].sensor

    @property
    def plume(self) -> IsotropicPlume:
        return self.members[0].plume

    @property
    def n(self) -> int:
        return self.members[0].n

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return self.members[0].parameter_names

    @property
    def particles(self) -> np.ndarray:
        return self.members[0].particles

    @property
    def ess(self) -> float:
        return self.members[0].ess

    @property
    def n_readings(self) -> int:
        return self.members[0].n_readings

    @property
    def n_resamples(self) -> int:
        return sum(m.n_resamples for m in self.members)

    @property
    def recoveries(self) -> list[dict[str, float | str]]:
        return [r for m in self.members for r in m.recoveries]

    def mean(self) -> np.ndarray:
        return self.members[0].mean()

    def cov(self) -> np.ndarray:
        return self.members[0].cov()

    def history(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.members[0].history()

    def log_likelihood(self, theta: np.ndarray, position: np.ndarray, reading: float) -> np.ndarray:
        return self.members[0].log_likelihood(theta, position, reading)

    def _nearest_release(self, true_location: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, 3) locations, (N,) weights: the most probable count's release nearest the truth."""
        k = max(self.estimated_count, 1)
        f = self.member(k)
        if not isinstance(f, MultiSourceFilter):
            return f.source_locations, f.weights
        means = f.release_means()
        j = int(np.argmin(np.linalg.norm(means - np.asarray(true_location), axis=1)))
        return f.release_locations(j), f.weights

    def rmse(self, true_location: np.ndarray) -> float:
        """RMSE (m) about ``true_location`` (3,) of the most probable count's nearest release."""
        points, weights = self._nearest_release(true_location)
        return weighted_rmse(points, weights, true_location)

    def in_credible_region(
        self, true_location: np.ndarray, level: float = 0.95, floor: float = 0.0
    ) -> bool:
        """Whether ``true_location`` is in the ``level`` region (floored) of the nearest release."""
        cols = self.members[0]._loc_block
        if not cols:
            return True
        points, weights = self._nearest_release(true_location)
        truth = np.asarray(true_location, dtype=np.float64)[cols]
        return in_credible_ellipsoid(points[:, cols], weights, truth, level, floor)

    def count_summary(self) -> dict[str, object]:
        """What a summary reports of the count: the estimate, P(K) and the releases."""
        probs = self.count_probabilities
        return {
            "estimated_count": self.estimated_count,
            "count_probabilities": [round(float(p), 6) for p in probs],
            "count_switches": self.switches,
            "estimated_sources": [[float(v) for v in row] for row in self.estimated_sources()],
        }


__all__ = ["DEFAULT_PLAUSIBLE", "EVIDENCE_EVERY", "FOUND_SHARE", "NoSource", "SourceCountBank"]
