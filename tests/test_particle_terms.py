"""ParticleTerms (issue 17): merged particle copies and per-position terms kept across decisions
give the statistics of the plain computation, never stale ones."""

import numpy as np
import pytest

from dcee.models import IsotropicPlume, Sensor
from dcee.planning.base import Belief
from dcee.planning.particle_terms import ParticleTerms, merge_runs, pairwise_sum, run_sums
from dcee.planning.position_kernels import content_hash
from dcee.planning.predicted import PredictionContext
from tests.helpers import planar_prior, random_theta

SENSOR = Sensor.paper_exact()
PLUME = IsotropicPlume()


def _resampled(n=3000, seed=0):
    rng = np.random.default_rng(seed)
    base = random_theta(n // 3, rng)
    idx = np.sort(rng.integers(0, len(base), n))  # runs of copies, as resampling leaves them
    theta = np.ascontiguousarray(base[idx])
    w = rng.random(n)
    return theta, w / w.sum()


def test_merge_runs_keeps_one_particle_per_run_with_the_runs_weight():
    theta, w = _resampled()
    pt = ParticleTerms()
    pt.sync(theta, SENSOR, PLUME)
    starts = merge_runs(theta)
    assert pt.n == len(starts) < len(theta)
    np.testing.assert_array_equal(pt.theta, theta[starts])
    merged = pt.weights(w)
    ends = np.append(starts[1:], len(theta))
    np.testing.assert_allclose(merged, [w[a:b].sum() for a, b in zip(starts, ends, strict=True)])
    assert np.all(np.any(pt.theta[1:] != pt.theta[:-1], axis=1))  # no run left


def test_run_sums_are_numpys_reduceat_bit_for_bit():
    # runs shorter than 8, up to 128 and longer (NumPy's pairwise summation splits those)
    rng = np.random.default_rng(5)
    for trial in range(150):
        n = int(rng.integers(1, 4000))
        w = rng.random(n) * 10.0 ** rng.uniform(-12, 0, n)
        cuts = int(rng.integers(1, 4)) if trial % 2 else int(rng.integers(1, n + 1))
        starts = np.unique(np.concatenate([[0], rng.integers(0, n, cuts)])).astype(np.int64)
        assert np.array_equal(run_sums(w, starts), np.add.reduceat(w, starts))


def test_pairwise_sum_is_numpys_sum_bit_for_bit():
    # below 8, up to 128 (one block), and the halvings above it, to past NumPy's 8,192 buffer
    rng = np.random.default_rng(6)
    for n in (1, 7, 8, 9, 127, 128, 129, 300, 1000, 8191, 8192, 8193, 10_000, 100_003):
        a = rng.random(n + 5) * 10.0 ** rng.uniform(-12, 0, n + 5)
        assert pairwise_sum(a, 3, n) == a[3 : 3 + n].sum(), n


def _content_hash_reference(values: np.ndarray) -> tuple[int, int]:
    """The content hash in Python integers (splitmix64's mix of k + 1, made odd)."""
    mask = 2**64 - 1
    a = b = 0
    for k, bits in enumerate(values.view(np.uint64).tolist()):
        h = ((k + 1) * 0x9E3779B97F4A7C15) & mask
        h = ((h ^ (h >> 29)) * 0xBF58476D1CE4E5B9) & mask
        h = (h ^ (h >> 32)) | 1
        a = (a + bits * h) & mask
        b = (b + bits * ((h * 0x94D049BB133111EB) & mask)) & mask
    return a, b


def test_the_content_hash_matches_its_reference_and_sees_any_one_changed_value():
    rng = np.random.default_rng(11)
    x = rng.standard_normal(500)
    assert tuple(int(v) for v in content_hash(x.view(np.uint64))) == _content_hash_reference(x)
    base = content_hash(x.view(np.uint64))
    for k in rng.integers(0, len(x), 50):
        y = x.copy()
        y[k] = np.nextafter(y[k], np.inf)  # the smallest change a float allows
        changed = content_hash(y.view(np.uint64))
        assert changed[0] != base[0] and changed[1] != base[1]
    swapped = x.copy()
    swapped[[3, 7]] = swapped[[7, 3]]  # the same values elsewhere: a different set of particles
    assert content_hash(swapped.view(np.uint64)) != base


def test_merged_statistics_equal_the_unmerged_ones():
    theta, w = _resampled()
    positions = np.array([[[20.0, 20.0, 2.0]], [[24.0, 20.0, 2.0]], [[20.0, 26.0, 2.0]]])
    out = []
    for merge in (True, False):
        belief = Belief(theta, w, SENSOR, PLUME, ParticleTerms(merge=merge))
        ctx = PredictionContext(belief, 30, 1, np.random.default_rng(3))
        out.append(ctx.stats(positions))
    fast, plain = out
    np.testing.assert_array_equal(fast.readings, plain.readings)  # the same hypotheses
    for a, b in [
        (fast.log_evidence, plain.log_evidence),
        (fast.mean, plain.mean),
        (fast.trace_cov, plain.trace_cov),
        (fast.kl, plain.kl),
    ]:
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12)


def test_rows_are_reused_across_decisions_and_recomputed_when_the_particles_change():
    theta, w = _resampled()
    cache = ParticleTerms()
    a = np.array([[10.0, 10.0, 2.0], [12.0, 10.0, 2.0]])
    ctx = PredictionContext(Belief(theta, w, SENSOR, PLUME, cache), 5, 1, np.random.default_rng(0))
    rows = ctx.position_index(a)
    first = [t[rows].copy() for t in ctx.terms]
    # a second decision on the same particles (new weights) finds the rows
    PredictionContext(Belief(theta, w[::-1].copy(), SENSOR, PLUME, cache), 5, 1,
                      np.random.default_rng(1))  # fmt: skip
    assert cache.rows(a).tolist() == rows.tolist()
    # an edit in place is noticed: the terms are those of the new particles
    theta[:, 0] += 1.0
    ctx = PredictionContext(Belief(theta, w, SENSOR, PLUME, cache), 5, 1, np.random.default_rng(0))
    new = [t[ctx.position_index(a)] for t in ctx.terms]
    fresh = PredictionContext(Belief(theta, w, SENSOR, PLUME), 5, 1, np.random.default_rng(0))
    ref = [t[fresh.position_index(a)] for t in fresh.terms]
    for x, y in zip(new, ref, strict=True):
        np.testing.assert_array_equal(x, y)
    assert not np.array_equal(new[0], first[0])


def test_read_only_particles_are_trusted_unchanged_and_anything_else_is_read_again(monkeypatch):
    """An array that is read-only, with every array it views, cannot change: the same one
    bound again is not hashed (what a filter's planning_particles hands over). A writeable
    array, or a read-only view of a writeable one, is hashed at every binding, so an edit
    through it is noticed."""
    import dcee.planning.particle_terms as pt_module

    theta, w = _resampled()
    a = np.array([[10.0, 10.0, 2.0], [12.0, 10.0, 2.0]])
    hashed = []

    def counting_hash(bits):
        hashed.append(len(bits))
        return content_hash(bits)

    monkeypatch.setattr(pt_module, "content_hash", counting_hash)
    frozen = theta.copy()
    frozen.flags.writeable = False
    cache = ParticleTerms()
    for seed in range(3):
        PredictionContext(Belief(frozen, w, SENSOR, PLUME, cache), 5, 1,
                          np.random.default_rng(seed))  # fmt: skip
    assert len(hashed) == 1  # once, when it was first bound
    rows = cache.rows(a)
    # a read-only view of a writeable array: hashed every time, and an edit is noticed
    base = theta.copy()
    view = base[:]
    view.flags.writeable = False
    for _ in range(2):
        PredictionContext(Belief(view, w, SENSOR, PLUME, cache), 5, 1, np.random.default_rng(0))
    assert len(hashed) == 3
    before = cache.terms.conc[cache.rows(a)].copy()
    base[:, 0] += 1.0
    PredictionContext(Belief(view, w, SENSOR, PLUME, cache), 5, 1, np.random.default_rng(0))
    assert len(hashed) == 4
    assert not np.array_equal(cache.terms.conc[cache.rows(a)], before)
    assert rows.shape == (2,)


def test_a_filters_planning_particles_never_change_under_the_planner():
    """planning_particles makes the filter's particles read-only; its next move works on a
    copy (the array a planner bound keeps its values) and an edit in place from outside
    raises instead of going unnoticed."""
    from dcee.estimation import ParticleFilter

    pf = ParticleFilter(planar_prior(u=2.0), SENSOR, PLUME, n_particles=500, seed=1)
    seen = pf.planning_particles()
    kept = seen.copy()
    assert not seen.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        pf.theta[0, 0] = 1.0
    pf.resample()  # resample and move
    np.testing.assert_array_equal(seen, kept)
    assert pf.theta is not seen and pf.theta.flags.writeable


def test_the_byte_cap_evicts_old_rows_never_the_current_decisions():
    theta, _ = _resampled(900)
    cache = ParticleTerms(max_bytes=6 * 8 * 300 * 10)  # 10 rows of 300 merged particles or more
    cache.sync(theta, SENSOR, PLUME)
    rng = np.random.default_rng(0)
    for decision in range(6):
        cache.begin()
        pts = np.column_stack([rng.uniform(0, 50, (8, 2)), np.full(8, 2.0)])
        rows = cache.rows(pts)
        assert len(set(rows.tolist())) == 8
        # every row asked for in this decision still holds its position's terms
        fresh = ParticleTerms()
        fresh.sync(theta, SENSOR, PLUME)
        fresh.begin()
        ref = fresh.rows(pts)
        np.testing.assert_array_equal(cache.terms.loc[rows], fresh.terms.loc[ref])
        assert cache.capacity <= max(16, 8 * (decision + 1))
    # a call that mixes rows cached by earlier decisions with new positions under the cap's
    # pressure keeps the old rows it asks for (they are this decision's now)
    cache.begin()
    old_pts = pts[:3]
    mixed = np.vstack([old_pts, np.column_stack([rng.uniform(0, 50, (9, 2)), np.full(9, 2.0)])])
    rows = cache.rows(mixed)
    fresh = ParticleTerms()
    fresh.sync(theta, SENSOR, PLUME)
    fresh.begin()
    fresh_rows = fresh.rows(mixed)
    np.testing.assert_array_equal(cache.terms.loc[rows], fresh.terms.loc[fresh_rows])
    # one decision needing more rows than the cap grows the buffers instead of evicting its own
    cache.begin()
    many = np.column_stack([rng.uniform(0, 50, (30, 2)), np.full(30, 2.0)])
    rows = cache.rows(many)
    assert len(set(rows.tolist())) == 30 and cache.capacity >= 30


@pytest.mark.parametrize("expectation", ["sampled", "stratified"])
def test_a_branch_on_a_subset_sees_the_same_terms(expectation):
    theta, w = _resampled()
    ctx = PredictionContext(Belief(theta, w, SENSOR, PLUME), 6, 1, np.random.default_rng(0),
                            expectation)  # fmt: skip
    pts = np.array([[10.0, 10.0, 2.0], [30.0, 12.0, 2.0]])
    rows = ctx.position_index(pts)
    bw = ctx.belief.weights.copy()
    bw[::3] = 0.0  # a third cannot explain the hypothesised reading: the branch drops them
    bw /= bw.sum()
    branch = ctx.branch(bw, 4, np.random.default_rng(1))
    keep = bw > 1e-12 * bw.max()
    assert branch.belief.theta.shape[0] == keep.sum()
    brow = branch.position_index(pts)
    for full, sub in zip(ctx.terms, branch.terms, strict=True):
        np.testing.assert_array_equal(sub[brow], full[rows][:, keep])


def test_a_cached_row_asked_for_again_is_not_evicted_for_the_new_ones_of_the_same_call():
    theta, _ = _resampled(900)
    cache = ParticleTerms(max_bytes=1)  # the cap in force at once: evict whatever is old
    cache.sync(theta, SENSOR, PLUME)
    cache.begin()
    first = np.array([[float(x), 10.0, 2.0] for x in range(8)])
    cache.rows(first)
    cache.begin()  # next decision: the first position again, and seven new ones
    mixed = np.vstack([first[:1], [[float(x), 30.0, 2.0] for x in range(7)]])
    rows = cache.rows(mixed)
    assert len(set(rows.tolist())) == 8
    fresh = ParticleTerms()
    fresh.sync(theta, SENSOR, PLUME)
    fresh.begin()
    fresh_rows = fresh.rows(mixed)
    for a, b in zip(cache.terms, fresh.terms, strict=True):
        np.testing.assert_array_equal(a[rows], b[fresh_rows])


def test_merge_runs_is_the_numpy_comparison_nan_and_signed_zero_included():
    theta, _ = _resampled(n=900, seed=3)
    theta[10:12, 2] = np.nan  # two equal rows with a NaN: still two runs (NaN != NaN)
    theta[20, 1], theta[21, 1] = 0.0, -0.0  # equal values: one run where the rest agrees
    theta[21] = theta[20]
    theta[21, 1] = -0.0
    differs = np.any(theta[1:] != theta[:-1], axis=1)
    expected = np.concatenate([[0], np.flatnonzero(differs) + 1])
    np.testing.assert_array_equal(merge_runs(theta), expected)
    assert 11 in merge_runs(theta) and 21 not in merge_runs(theta)
    assert merge_runs(np.zeros((0, 8))).shape == (0,)
