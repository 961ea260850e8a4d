"""Bridge-sampling evidence from a filter's particles (dcee.estimation.evidence) against exact
integrals of prior × likelihood on grids: one release and two releases with (x, y) unknown."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import logsumexp

from dcee import ParticleFilter
from dcee.estimation.evidence import bridge_log_evidence, one_more_log_evidence
from dcee.estimation.grid import location_grid_posterior
from dcee.estimation.multi_source import MultiSourceFilter
from dcee.estimation.multi_source_kernels import multi_history_log_likelihood
from dcee.models.plume import IsotropicPlume
from dcee.scenarios import load_scenario
from tests.test_robust_estimation import _xy_prior

PAPER1 = load_scenario("paper:1")
SENSOR = PAPER1.make_sensor()
SECOND = (15.0, 35.0)  # a second release, m


def _path() -> np.ndarray:
    """A lawnmower over the area at 4 m, legs across the paper's wind."""
    rows = [(x, y, 4.0) for x in (8.0, 20.0, 32.0, 44.0) for y in np.linspace(4, 46, 8)]
    return np.array(rows)


def _readings(n_releases: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    truth = np.tile(PAPER1.truth_theta(), (n_releases, 1))
    if n_releases == 2:
        truth[1, :2] = SECOND
    path = _path()
    conc = IsotropicPlume().concentration(truth, path).sum(axis=0)
    return path, SENSOR.simulate(conc, np.random.default_rng(seed))


def _assimilated(filt: ParticleFilter, path: np.ndarray, zs: np.ndarray) -> ParticleFilter:
    for p, z in zip(path, zs, strict=True):
        filt.update(p, float(z))
    return filt


def _two_release_grid_log_evidence(path: np.ndarray, zs: np.ndarray, h: float = 1.25) -> float:
    """log ∫∫ prior · likelihood over both releases' (x, y) on a grid of spacing h (midpoint
    rule), pairs closer than the filter's 1 m separation at density 0, as in its prior; each
    unordered pair once, twice over (the likelihood is symmetric in the two releases). h =
    1.25 m: 1.3 million pairs, 2 s; at h = 1 m (3.1 million, 5 s) the integral moved by 0.006
    nats for the one-release readings and 0.13 for the two-release ones, within the tests'
    0.3."""
    g = np.arange(h / 2, 50.0, h)
    gx, gy = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    first, second = np.triu_indices(len(gx), k=1)
    keep = np.hypot(gx[first] - gx[second], gy[first] - gy[second]) >= 1.0
    first, second = first[keep], second[keep]
    row = np.concatenate([PAPER1.truth_theta(), PAPER1.truth_theta()[:4]])
    plume = IsotropicPlume()
    out = []
    for lo in range(0, len(first), 200_000):
        a, b = first[lo : lo + 200_000], second[lo : lo + 200_000]
        theta = np.tile(row, (len(a), 1))
        theta[:, 0], theta[:, 1], theta[:, 8], theta[:, 9] = gx[a], gy[a], gx[b], gy[b]
        ll = np.empty(len(a))
        multi_history_log_likelihood(
            theta,
            np.ones(len(a), dtype=bool),
            path,
            zs,
            np.ones(len(zs)),
            plume.min_distance,
            *plume.shape,
            SENSOR.params,
            ll,
            None,
            None,
        )
        out.append(logsumexp(ll))
    return float(logsumexp(out) + math.log(2.0) + 2 * math.log(h * h / 2500.0))


def test_bridge_evidence_matches_the_exact_grid_integral_for_one_release():
    """x, y unknown: bridge sampling from the particles after all readings against the grid
    integral (the same check as the SMC estimate's, tests/test_model_bank.py)."""
    path, zs = _readings(1, seed=3)
    assert (zs > 0).sum() >= 4  # the test needs detections
    pf = _assimilated(ParticleFilter(_xy_prior(), SENSOR, n_particles=5000, seed=1), path, zs)
    exact = location_grid_posterior(
        PAPER1.truth_theta(), (0, 0), (50, 50), 0.25, path, zs, SENSOR, refine=5
    ).log_evidence
    for seed in range(3):
        est = bridge_log_evidence(pf, np.random.default_rng(seed))
        assert est == pytest.approx(exact, abs=0.2), seed


@pytest.mark.parametrize("n_releases", [1, 2])
def test_two_release_evidence_matches_the_grid_over_both_releases(n_releases):
    """Two releases' (x, y) unknown, readings of one or of two releases: the bridge estimate
    from the two-release filter within 0.3 nats of the four-dimensional grid integral; the
    one-release filter's particles with a release more anywhere match it when the readings
    saw one release, and do not exceed it when they saw two (they estimate the integral over
    a part of the space)."""
    path, zs = _readings(n_releases, seed=5)
    prior = _xy_prior()
    one = _assimilated(ParticleFilter(prior, SENSOR, n_particles=5000, seed=2), path, zs)
    two = _assimilated(MultiSourceFilter(2, prior, SENSOR, n_particles=20_000, seed=3), path, zs)
    exact = _two_release_grid_log_evidence(path, zs)
    rng = np.random.default_rng(0)
    assert bridge_log_evidence(two, rng) == pytest.approx(exact, abs=0.3)
    more = one_more_log_evidence(one, two, bridge_log_evidence(one, rng), rng)
    if n_releases == 1:
        assert more == pytest.approx(exact, abs=0.3)
    else:
        assert more < exact + 0.3


def test_count_bank_replaces_a_lagging_filters_evidence_at_the_next_anchor():
    """A deficit in a member's running SMC evidence (what a filter that lagged behind its
    readings keeps) is gone from the count's posterior after the next anchor: the bank's
    evidence of each count is then within 1 nat of a fresh bridge estimate, the larger of the
    two for two releases (50 nats off without the anchor)."""
    from dcee.estimation.source_count import EVIDENCE_EVERY, SourceCountBank
    from tests.test_source_count import _filter, _lawnmower, _simulate

    truth = np.tile(PAPER1.truth_theta(), (2, 1))
    truth[1, :2] = SECOND
    path = _lawnmower()[:EVIDENCE_EVERY]
    zs = _simulate(truth, path, 4)
    bank = SourceCountBank([_filter(1, 3000, 1), _filter(2, 3000, 2)], seed=0)
    for k, (p, z) in enumerate(zip(path, zs, strict=True), start=1):
        if k == EVIDENCE_EVERY:
            bank.members[1].log_evidence -= 50.0  # a lagged deficit, just before the anchor
        bank.update(p, float(z))
    evidence = bank._log_joint()[1:] - bank.log_prior[1:]
    rng = np.random.default_rng(9)
    one = bridge_log_evidence(bank.members[0], rng)
    two = max(
        bridge_log_evidence(bank.members[1], rng),
        one_more_log_evidence(bank.members[0], bank.members[1], one, rng),
    )
    assert evidence == pytest.approx([one, two], abs=1.0)
