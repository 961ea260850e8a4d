"""The resample-move step of :class:`~dcee.estimation.particle_filter.ParticleFilter`.

Keeping every mode: a random-walk move cannot carry mass between separated modes, so after a
resampling that has concentrated the particles in one region a minority mode that later readings
favour can be lost for good. Each sweep is therefore a mixture: a share ``global_share`` of the
particles proposes a new source location from the prior (an independence proposal for the
location block; its acceptance ratio is the likelihood ratio times the prior ratio of the other
columns, here 1), the rest a regularised random walk. Sweeps repeat until at least
``diversify`` of the particles have moved since the resampling (at least ``mcmc_steps``, at most
``max_sweeps`` sweeps); the acceptance rate, the number of distinct particles and the sweeps are
returned in :class:`UpdateInfo` for every step.

Bounded cost on a long mission: a sweep reads the whole history for every particle it moves,
so on a robot that searches for hours a resampling grows dearer reading by reading (about 1 s at
4,000 readings and 20,000 particles, docs/guide/robot.md). With more than ``move_history``
history entries a sweep therefore proposes to move a random share ``move_history`` / entries of
the particles and leaves the others where they are (the sweeps continue until ``diversify`` of
that share has moved). A kernel that leaves the posterior invariant, applied to some particles
and not to others, leaves each particle a draw of the posterior, so the target is unchanged;
what the long mission pays is slower mixing per resampling, not a wrong posterior
(tests/test_particle_filter.py against the exact grid posterior).

Degeneracy: in log space the weights cannot all underflow, but a reading that every particle
finds very unlikely can collapse the weight onto a handful of particles. When the ESS after a
reading would fall below ``collapse_threshold · N`` the reading is instead assimilated by
likelihood tempering: exponents 0 = β₀ < β₁ < … < 1 chosen by bisection so that each stage keeps
ESS ≈ ``resample_threshold · N``, with resampling and MCMC moves targeting prior × history ×
p(z|Θ)^β between stages (an adaptive tempered SMC step; it targets the exact posterior). Each
such event is recorded in :attr:`ParticleFilter.recoveries`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from dcee.estimation.base import UpdateInfo
from dcee.estimation.filter_kernels import (
    history_log_likelihood,
    history_log_likelihood_generic,
    reading_upper_bounds,
)
from dcee.estimation.resampling import (
    effective_sample_size,
    normalised_weights,
    systematic_resample,
)
from dcee.models.plume import IsotropicPlume


class ResampleMove:
    """Resampling, MCMC rejuvenation and tempering for the particle filter (a mixin: it reads
    and writes the filter's particles ``theta`` (N, 8), log weights, cached history
    log-likelihoods and settings)."""

    def planning_particles(self) -> np.ndarray:
        """The particles ``theta`` made read-only until the filter next changes them (it then
        works on a copy): a planner's cache of per-particle terms
        (:class:`~dcee.planning.particle_terms.ParticleTerms`) may take the same read-only array
        for the same particles without reading all of them again (40-80 µs of an infotaxis
        decision on Stone Soup's workload, issue 82). An edit in place from outside raises;
        assign a new array instead."""
        self.theta.flags.writeable = False
        return self.theta

    def _editable_theta(self) -> np.ndarray:
        """``theta`` to edit in place: a copy where :meth:`planning_particles` made it
        read-only (so that the array a planner saw never changes)."""
        if not self.theta.flags.writeable:
            self.theta = self.theta.copy()
        return self.theta

    def _resample(self, *per_particle: np.ndarray) -> list[np.ndarray]:
        """Systematic resampling of the particles, their cached history log-likelihoods and any
        other per-particle arrays given (returned re-indexed); weights become uniform."""
        idx = systematic_resample(self.weights, self.rng, self.n)
        self.theta = self.theta[idx]
        self._hist_loglik = self._hist_loglik[idx]
        self._logw = np.full(self.n, -math.log(self.n))
        self._weights = None
        self.n_resamples += 1
        self._origin = idx
        return [a[idx] for a in per_particle]

    def _move_share(self) -> float:
        """The share of the particles a sweep proposes to move: all of them while the history
        holds at most ``move_history`` entries, then ``move_history`` / entries, so that a
        sweep costs at most ``move_history`` history entries per particle however long the
        mission (module doc)."""
        entries = len(self._hist_z)
        cap = self.move_history
        return 1.0 if cap is None or entries <= cap else cap / entries

    def _rejuvenate(self) -> tuple[float, int, int]:
        """Sweeps after a resampling until ``diversify`` of the particles that sweeps propose
        to move have moved (see the module doc). Returns (mean acceptance, sweeps, distinct
        particles)."""
        share = self._move_share()
        moved = np.zeros(self.n, dtype=bool)
        acc: list[float] = []
        while len(acc) < self.max_sweeps and (
            len(acc) < self.mcmc_steps or moved.mean() < self.diversify * share
        ):
            accepted, proposed = self._mh_sweep(share)
            moved |= accepted
            acc.append(float(accepted.sum()) / max(proposed, 1))
        distinct = int(moved.sum()) + len(np.unique(self._origin[~moved]))
        return (float(np.mean(acc)) if acc else math.nan), len(acc), distinct

    def _mh_sweep(self, share: float = 1.0) -> tuple[np.ndarray, int]:
        """One Metropolis–Hastings move of every particle (``share`` < 1: of a random share of
        them, the others stay), full-history target: a share ``global_share`` proposes its
        location from the prior, the rest a random walk. Returns the (N,) accepted mask and
        the number of particles proposed to move."""
        self._align()
        d = len(self._unknown)
        x = self.theta[:, self._unknown]
        cov = np.atleast_2d(np.cov(x, rowvar=False))
        # Gaussian kernel bandwidth of the regularised particle filter (Musso et al.),
        # as in the authors' code; a floor keeps the kernel alive if the particles collapse.
        h = (4.0 / (self.n * (d + 2))) ** (1.0 / (d + 4))
        floor = (1e-3 * self._unknown_scales()) ** 2
        cov = h * h * cov + np.diag(floor)
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            chol = np.diag(np.sqrt(np.maximum(np.diag(cov), floor)))
        proposal = self.theta.copy()
        proposal[:, self._unknown] += self.rng.standard_normal((self.n, d)) @ chol.T
        # Independence proposals of the location block from its prior: for these particles the
        # proposal density (the block's prior) cancels the block's prior in the target.
        jump = self.rng.random(self.n) < self.global_share if self._loc_block else None
        log_q_ratio = np.zeros(self.n)
        if jump is not None and jump.any():
            proposal[jump] = self.theta[jump]
            self._propose_jump(proposal, jump, log_q_ratio)
        lp_prop = self._log_prior(proposal)
        lp_cur = self._log_prior(self.theta)
        active = np.isfinite(lp_prop)
        if share < 1.0:
            # a kernel that leaves the posterior invariant, applied to some particles and not
            # to others, still leaves each particle's distribution the posterior
            active &= self.rng.random(self.n) < share
        proposed = int(active.sum()) if share < 1.0 else self.n
        ll_prop = np.empty(self.n)
        pos, z, mult = self.history()
        log_u = np.log(self.rng.random(self.n))
        # accepted iff ll_prop > threshold: lets the kernel abandon hopeless proposals early
        with np.errstate(invalid="ignore"):
            threshold = np.nan_to_num(
                log_u - lp_prop + self._hist_loglik + lp_cur - log_q_ratio,
                nan=-np.inf,
                posinf=np.inf,
            )
        bounds = reading_upper_bounds(z, self.sensor)
        if share < 1.0:
            # only the particles proposed to move go to the kernel, so that the sweep's cost
            # is that share of the full one (the kernel's blocks would compute the others)
            moving = np.flatnonzero(active)
            ll_moving = np.empty(moving.size)
            self._history_ll(
                np.ascontiguousarray(proposal[moving]),
                np.ones(moving.size, dtype=np.bool_),
                pos,
                z,
                mult,
                ll_moving,
                np.ascontiguousarray(threshold[moving]),
                bounds,
            )
            ll_prop.fill(-np.inf)
            ll_prop[moving] = ll_moving
        else:
            self._history_ll(proposal, active, pos, z, mult, ll_prop, threshold, bounds)
        with np.errstate(invalid="ignore"):
            log_ratio = (ll_prop + lp_prop) - (self._hist_loglik + lp_cur) + log_q_ratio
            accept = active & (log_u < log_ratio)
        self._editable_theta()[accept] = proposal[accept]
        self._hist_loglik[accept] = ll_prop[accept]
        return accept, proposed

    # --- what a filter with another particle layout overrides -------------------------------

    def _align(self) -> None:
        """Before a sweep: nothing for one release (a K-source filter relabels its releases)."""

    def _unknown_scales(self) -> np.ndarray:
        """(D,) the prior spread of each unknown column (the random walk's floor)."""
        return self.prior.scales

    def _propose_jump(
        self, proposal: np.ndarray, jump: np.ndarray, log_q_ratio: np.ndarray
    ) -> None:
        """Redraw the location block of the particles ``jump`` (N,) in ``proposal`` from the
        prior, adding log q(current) − log q(proposed) to ``log_q_ratio``."""
        k = int(jump.sum())
        dists = self.prior.distributions
        for col in self._loc_block:
            proposal[jump, col] = dists[col].sample(self.rng, k)
            log_q_ratio[jump] += dists[col].log_pdf(self.theta[jump, col]) - dists[col].log_pdf(
                proposal[jump, col]
            )

    def _release_blocks(self) -> np.ndarray:
        """(K, 4) the columns (x, y, z, q) of each release in a particle: one release."""
        return np.array([[0, 1, 2, 3]])

    def _prior_draws(self, rng: np.random.Generator, m: int) -> np.ndarray:
        """(m, columns) draws from the prior (:meth:`_prior_log_pdf` is their density)."""
        return self.prior.sample(rng, m)

    def _prior_log_pdf(self, theta: np.ndarray) -> np.ndarray:
        """(N,) normalised log density of :meth:`_prior_draws` (no wind readings)."""
        return self.prior.log_density(theta)

    def _likelihood_kernel(self) -> Callable[..., None]:
        """The compiled history likelihood of this filter's particle layout (one release)."""
        return history_log_likelihood

    def _history_ll(
        self,
        theta: np.ndarray,
        active: np.ndarray,
        positions: np.ndarray,
        readings: np.ndarray,
        multiplicity: np.ndarray,
        out: np.ndarray,
        threshold: np.ndarray | None = None,
        bounds: np.ndarray | None = None,
    ) -> None:
        """out (N,) = the history log-likelihood of particles ``theta`` (see
        :func:`~dcee.estimation.filter_kernels.history_log_likelihood`; the kernel is
        :meth:`_likelihood_kernel`'s; a plume without compiled constants, the wall-aware one,
        :func:`~dcee.estimation.filter_kernels.history_log_likelihood_generic`)."""
        if not isinstance(self.plume, IsotropicPlume):
            history_log_likelihood_generic(
                self.plume, theta, active, positions, readings, multiplicity, self._sp, out
            )
            return
        self._likelihood_kernel()(
            theta,
            active,
            positions,
            readings,
            multiplicity,
            self.plume.min_distance,
            *self.plume.shape,
            self._sp,
            out,
            threshold,
            bounds,
        )

    def _tempered_update(
        self, ll_new: np.ndarray, entry: int, base_mult: float, ess0: float
    ) -> UpdateInfo:
        beta = 0.0
        stages = 0
        sweeps = 0
        distinct = self.n
        target = self.resample_threshold * self.n
        hist_base = self._hist_loglik.copy()
        acc: list[float] = []
        while beta < 1.0:
            stages += 1
            if stages >= self.max_tempering_stages or (
                effective_sample_size(normalised_weights(self._logw + (1.0 - beta) * ll_new))
                >= target
            ):
                new_beta = 1.0
            else:
                lo, hi = beta, 1.0
                for _ in range(40):
                    mid = 0.5 * (lo + hi)
                    if (
                        effective_sample_size(
                            normalised_weights(self._logw + (mid - beta) * ll_new)
                        )
                        >= target
                    ):
                        lo = mid
                    else:
                        hi = mid
                new_beta = max(lo, beta + 1e-6)
            # ll_new: the new reading's log-likelihood for the current particles.
            self._set_logw(self._logw + (new_beta - beta) * ll_new)
            self._hist_loglik = hist_base + new_beta * ll_new
            self._hist_mult[entry] = base_mult + new_beta * self._weight_now
            beta = new_beta
            ll_new, hist_base = self._resample(ll_new, hist_base)
            stage_acc, stage_sweeps, distinct = self._rejuvenate()
            acc.append(stage_acc)
            sweeps += stage_sweeps
            if beta < 1.0:
                # After the move, recompute the new reading's likelihood for the moved particles.
                ll_new = self.log_likelihood(
                    self.theta,
                    np.array(self._hist_pos[entry]),
                    self._hist_z[entry],
                    self._weight_now,
                )
                hist_base = self._hist_loglik - beta * ll_new
        self._hist_mult[entry] = base_mult + self._weight_now
        self.recoveries.append(
            {
                "kind": "tempering",
                "reading_index": float(self.n_readings),
                "ess_before": ess0,
                "stages": float(stages),
            }
        )
        return UpdateInfo(ess0, True, float(np.mean(acc)), stages, sweeps, distinct)
