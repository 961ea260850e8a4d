"""The particle set as the planners compute on it, and its per-position likelihood terms, kept
across decisions (issue 17).

Two exact savings:

* **Merged copies.** Resampling leaves runs of identical particles next to each other (about a
  quarter of a 20,000-particle posterior, until the MCMC move has moved them). Every
  predicted-posterior statistic is a weighted sum over particles, so a run merged into one
  particle carrying the run's total weight gives the same statistics (to rounding) for less
  work.
* **Terms kept across decisions.** A particle's terms at a position (concentration, source
  distance, transformed location, 1/σ, log P(non-detection), log Pd − log σ) depend on its
  source term and the position, not on its weight. While the particle set is unchanged (most
  readings only reweight it), the rows of positions already evaluated by an earlier decision are
  reused, and new rows go into the same buffers (no fresh allocation, no page faults).

A :class:`ParticleTerms` recognises "the same particle set" by the array's identity, shape and
a hash of its contents (:func:`~dcee.planning.position_kernels.content_hash`), so an edit in
place is noticed as well; an array that is read-only with everything it views (a filter's
``planning_particles``) cannot be edited, and the same one is taken unchanged without the hash.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from dcee.models.plume import IsotropicPlume
from dcee.models.sensor import Sensor
from dcee.numeric import read_only_view
from dcee.planning.position_kernels import (
    N_PLUME_CONSTANTS,
    content_hash,
    plume_constants,
    position_rows,
    rows_from_concentration,
    vectorised_case,
)


class PositionTerms(NamedTuple):
    """A particle set's likelihood terms at cached positions, each (R, M): R position rows (as
    :meth:`ParticleTerms.rows` maps them), M merged particles (see
    :func:`~dcee.planning.position_kernels.position_rows`)."""

    conc: np.ndarray
    """mean concentration at the position, g/m³"""
    dist: np.ndarray
    """distance from the particle's source, m"""
    loc: np.ndarray
    """the reading model's location term"""
    log_nd: np.ndarray
    """log-probability of a non-detection"""
    inv_sigma: np.ndarray
    """1 / the reading model's scale"""
    det_offset: np.ndarray
    """the detection log-density's constant"""


N_TERMS = len(PositionTerms._fields)
"""conc, dist, loc, log_nd, inv_sigma, det_offset (see :class:`PositionTerms`)."""

SEPARATE_SLOTS = tuple(range(N_TERMS))
LOC_IS_CONC_SLOTS = (0, 1, 0, 2, 3, 4)
"""Which buffer row holds each of the terms: with the paper's sensor family the transformed
location is the concentration itself (:func:`~dcee.planning.position_kernels.vectorised_case`),
and its rows share the concentration's memory: a sixth less to write at every new position and
to read back (measured: docs/performance.md, issue 82)."""

DEFAULT_MAX_BYTES = 32 * 2**20
"""Rows kept across decisions are capped at this many bytes (a decision's own rows always fit)."""


@njit(cache=True)
def merge_runs(theta: np.ndarray) -> np.ndarray:
    """(M,) start index of each run of identical consecutive rows of theta (N, 8): row i
    starts a run when any value differs from row i − 1 (``!=``, so a NaN always does). A
    loop, not ``np.any(theta[1:] != theta[:-1], axis=1)``: that builds an (N, 8) mask and
    reduces its short rows: 200 µs at 10,000 particles against 40 µs here (lab, 2026-11-29)."""
    n, d = theta.shape
    starts = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        differs = i == 0
        if i > 0:
            for k in range(d):  # no early exit: a branch per value cost more than the compares
                differs |= theta[i, k] != theta[i - 1, k]
        starts[m] = i
        m += differs
    return starts[:m].copy()


@njit(cache=True, inline="always")
def _block_sum(a: np.ndarray, start: int, n: int) -> float:
    """NumPy's pairwise sum of a[start:start+n] for n ≤ 128: sequential below 8, eight
    interleaved partial sums otherwise."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[start + i]
        return res
    r = np.empty(8)
    for j in range(8):
        r[j] = a[start + j]
    i = 8
    while i < n - (n % 8):
        for j in range(8):
            r[j] += a[start + i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        res += a[start + i]
        i += 1
    return res


@njit(cache=True)
def pairwise_sum(a: np.ndarray, start: int, n: int) -> float:
    """a[start:start+n] summed as NumPy's ``add`` reduction sums a contiguous float64 run
    (numpy/_core/src/umath/loops_utils.h.src, ``pairwise_sum``): sequential below 8, eight
    interleaved partial sums up to 128, halves (multiples of 8) above; the same bits.

    NumPy's recursion, unrolled onto explicit stacks: a recursive numba function called from
    a kernel of another module and loaded from the on-disk cache is not linked ("unresolved
    symbol", or a crash; numba 0.68, reproduced 2026-12-05)."""
    if n <= 128:
        return _block_sum(a, start, n)
    # frames (start, length, phase): phase 0 visits the left half, 1 the right, 2 adds them
    f_start = np.empty(64, dtype=np.int64)
    f_len = np.empty(64, dtype=np.int64)
    f_phase = np.empty(64, dtype=np.int64)
    values = np.empty(64)
    top = 0
    n_values = 0
    f_start[0], f_len[0], f_phase[0] = start, n, 0
    while top >= 0:
        s0, m = f_start[top], f_len[top]
        if m <= 128:
            values[n_values] = _block_sum(a, s0, m)
            n_values += 1
            top -= 1
            continue
        half = m // 2
        half -= half % 8
        phase = f_phase[top]
        f_phase[top] = phase + 1
        if phase == 0:
            top += 1
            f_start[top], f_len[top], f_phase[top] = s0, half, 0
        elif phase == 1:
            top += 1
            f_start[top], f_len[top], f_phase[top] = s0 + half, m - half, 0
        else:
            n_values -= 1
            values[n_values - 1] = values[n_values - 1] + values[n_values]
            top -= 1
    return values[0]


@njit(cache=True)
def run_sums(weights: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """(M,) sums of the runs of ``weights`` (N,) that begin at ``starts`` (M,), increasing, the
    first 0): ``np.add.reduceat(weights, starts)`` bit for bit (each run's first element plus
    the pairwise sum of the rest), without its 40 µs per decision of call overhead at 10,000
    particles."""
    m = starts.shape[0]
    out = np.empty(m)
    for k in range(m):
        a = starts[k]
        b = starts[k + 1] if k + 1 < m else weights.shape[0]
        if b - a <= 8:
            # pairwise_sum's sequential case, inline: most runs are this short, and a call per
            # run (the recursive helper is never inlined) was most of this function's time
            rest = 0.0
            for i in range(a + 1, b):
                rest += weights[i]
            out[k] = weights[a] + rest
        else:
            out[k] = weights[a] + pairwise_sum(weights, a + 1, b - a - 1)
    return out


def _read_only(a: np.ndarray) -> bool:
    """Whether no one can change ``a``'s values in place: it and every array it views are
    read-only (a read-only view of a writeable array changes with it)."""
    while isinstance(a, np.ndarray):
        if a.flags.writeable:
            return False
        a = a.base
    return a is None  # it owns its memory (a base of another kind might be written)


class ParticleTerms:
    """Merged particles and a cache of their per-position terms, for one particle set at a time.

    :meth:`sync` binds it to the current particles; :meth:`weights` merges a weight vector the
    same way; :meth:`rows` returns the rows of (K, 3) positions in :attr:`terms`, computing the
    missing ones. Rows used since the last :meth:`begin` are never evicted, so every row a
    decision asked for stays valid for that decision.
    """

    def __init__(self, merge: bool = True, max_bytes: int = DEFAULT_MAX_BYTES) -> None:
        self.merge = bool(merge)
        self.max_bytes = int(max_bytes)
        self._key: tuple | None = None
        self.theta = np.zeros((0, 8))
        self.source = np.zeros((0, 3))
        self.starts = np.zeros(0, dtype=np.int64)
        self._flat: np.ndarray | None = None  # (stored terms, capacity · M) buffer
        self._slots = SEPARATE_SLOTS  # the buffer row of each term
        self._index: dict[tuple[float, ...], int] = {}
        self._stamp = np.zeros(0, dtype=np.int64)
        self._clock = 0
        self._terms: PositionTerms | None = None
        self._plume: tuple | None = None
        self._generic: object | None = None  # a plume that predicts with its own method
        self._sensor_params: tuple | None = None
        self._derived: ParticleTerms | None = None
        self._frozen: np.ndarray | None = None  # the read-only particles of the last binding

    def derived(self) -> ParticleTerms:
        """A second :class:`ParticleTerms` kept with this one, for a particle set derived from
        it at each decision (a planner's systematic resample, ``subsample`` < 1): that set is
        new every decision, so none of its rows can be reused, but its buffers can. A fresh
        cache per decision grew them from 8 rows by doubling, copying every row so far: 1.3 of
        a tree-search decision's 8 ms on Stone Soup's MCTS example (lab, 2026-12-05)."""
        if self._derived is None:
            self._derived = ParticleTerms(self.merge, self.max_bytes)
        return self._derived

    # --- binding ----------------------------------------------------------------------------

    def _fingerprint(self, theta: np.ndarray) -> tuple:
        bits = np.ascontiguousarray(theta).reshape(-1).view(np.uint64)
        return (id(theta), theta.shape, *content_hash(read_only_view(bits)))

    def sync(self, theta: np.ndarray, sensor: Sensor, plume: object) -> None:
        """Bind to the particles theta (N, 8) and the models; keeps the cached rows only if
        nothing changed."""
        theta = np.asarray(theta, dtype=np.float64)
        # a plume without compiled constants (the wall-aware one) predicts with its own method
        generic = None if isinstance(plume, IsotropicPlume) else plume
        shape = (
            ("generic", id(plume)) if generic is not None else (plume.min_distance, *plume.shape)
        )
        models = shape, tuple(sensor.params)
        same_models = models == (self._plume, self._sensor_params)
        if same_models and theta is self._frozen and not theta.flags.writeable:
            # the same array, read-only since it was bound (a filter's planning_particles):
            # its values cannot have changed, and need not all be read again (the hash below)
            return
        self._frozen = theta if _read_only(theta) else None
        key = self._fingerprint(theta)
        if key == self._key and same_models:
            return
        self._key = key
        self._plume, self._sensor_params = models
        self.sp = sensor.params
        self._generic = generic
        if generic is None:
            self.min_distance, self.shape = plume.min_distance, plume.shape
        slots = (
            LOC_IS_CONC_SLOTS
            if generic is None and vectorised_case(self.sp, *self.shape)
            else SEPARATE_SLOTS
        )
        if slots != self._slots:
            self._slots, self._flat = slots, None  # another layout: new buffers
        if self.merge:
            self.starts = merge_runs(read_only_view(theta))
            self.theta = np.ascontiguousarray(theta[self.starts])
        else:
            self.starts = np.arange(len(theta), dtype=np.int64)
            self.theta = np.ascontiguousarray(theta)
        # (M, 3) C-contiguous source locations, as the kernels read them: copied once per
        # particle set, not at every decision
        self.source = np.ascontiguousarray(self.theta[:, :3])
        if generic is None:
            self._plume_constants = np.empty((N_PLUME_CONSTANTS, self.n))
            plume_constants(self.theta, self._plume_constants)
        self._index.clear()
        self._terms = None  # the buffers stay; their (capacity, M) views follow M
        self._stamp = np.zeros(self.capacity, dtype=np.int64)

    def forget(self) -> None:
        """Drop every cached row and the binding (the buffers stay): the next decision computes
        all its terms, as one at a new position after the particles changed would."""
        self._key = None
        self._frozen = None
        self._index.clear()

    def weights(self, weights: np.ndarray) -> np.ndarray:
        """(M,) merged weights: the sum over each run."""
        if len(self.starts) == len(weights):
            return np.asarray(weights, dtype=np.float64)
        return run_sums(np.ascontiguousarray(weights, dtype=np.float64), self.starts)

    @property
    def n(self) -> int:
        """Particles after merging."""
        return len(self.theta)

    # --- rows -------------------------------------------------------------------------------

    def begin(self) -> None:
        """Start a decision: rows used from now on stay valid until the next call."""
        self._clock += 1

    @property
    def capacity(self) -> int:
        """Rows the buffers hold for the current particle count."""
        return 0 if self._flat is None else self._flat.shape[1] // max(self.n, 1)

    @property
    def _stored_terms(self) -> int:
        """Rows of the buffer per position (terms sharing a row counted once)."""
        return max(self._slots) + 1

    @property
    def terms(self) -> PositionTerms:
        """(conc, dist, loc, log_nd, inv_sigma, det_offset), each (capacity, M) C-contiguous;
        row r holds the terms at the position :meth:`rows` mapped to r (see
        :func:`~dcee.planning.position_kernels.position_rows`)."""
        if self._flat is None:
            self._grow(8)
        if self._terms is None:
            m, cap = max(self.n, 1), self.capacity
            self._terms = PositionTerms(
                *(self._flat[k, : cap * m].reshape(cap, m) for k in self._slots)
            )
        return self._terms

    def _grow(self, rows: int) -> None:
        """Buffers for at least ``rows`` rows, keeping the rows cached so far."""
        m = max(self.n, 1)
        old = self.terms if self._flat is not None else None
        used = min(self.capacity, len(self._stamp))
        flat = np.empty((self._stored_terms, rows * m))
        self._flat, self._terms = flat, None
        if old is not None and used:
            for k in range(N_TERMS):
                self.terms[k][:used] = old[k][:used]
        stamp = np.zeros(self.capacity, dtype=np.int64)
        stamp[:used] = self._stamp[:used]
        self._stamp = stamp

    def _free_rows(self, count: int) -> list[int]:
        """``count`` rows to overwrite: unused ones first, then the least recently used rows
        of earlier decisions once the byte cap is reached; grows the buffers otherwise (and
        always when the current decision itself needs more rows)."""
        used = set(self._index.values())
        free = [r for r in range(self.capacity) if r not in used]
        if len(free) >= count:
            return free[:count]
        cap_rows = max(self.max_bytes // (self._stored_terms * 8 * max(self.n, 1)), 1)
        if len(used) + count > cap_rows:
            old = sorted((int(self._stamp[r]), r) for r in used if self._stamp[r] < self._clock)
            evict = [r for _, r in old[: count - len(free)]]
            if len(free) + len(evict) >= count:
                drop = set(evict)
                self._index = {k: r for k, r in self._index.items() if r not in drop}
                return (free + evict)[:count]
        self._grow(max(len(used) + count, min(2 * self.capacity, cap_rows), 8))
        free = [r for r in range(self.capacity) if r not in used]
        return free[:count]

    def rows(self, positions: np.ndarray) -> np.ndarray:
        """(K,) rows of (K, 3) positions in :attr:`terms`, computing the missing ones."""
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        out = np.empty(len(positions), dtype=np.int64)
        missing: list[int] = []
        keys = [tuple(p) for p in np.round(positions, 9).tolist()]
        pending: dict[tuple[float, ...], int] = {}
        for k, key in enumerate(keys):
            row = self._index.get(key)
            if row is None and key not in pending:
                pending[key] = len(missing)
                missing.append(k)
            out[k] = -1 if row is None else row
        found = out[out >= 0]
        self._stamp[found] = self._clock  # in use by this decision: never evicted below
        if missing:
            free = self._free_rows(len(missing))
            new_rows = np.array(free, dtype=np.int64)
            pts = np.ascontiguousarray(positions[missing])
            if self._generic is not None:
                conc, dist = self._generic.concentration_distance(self.theta, pts)
                rows_from_concentration(
                    np.ascontiguousarray(conc.T),
                    np.ascontiguousarray(dist.T),
                    new_rows,
                    self.sp,
                    *self.terms,
                )
            else:
                position_rows(
                    self._plume_constants,
                    pts,
                    new_rows,
                    self.min_distance,
                    *self.shape,
                    self.sp,
                    *self.terms,
                )
            for key, j in pending.items():
                self._index[key] = int(new_rows[j])
            for k, key in enumerate(keys):
                if out[k] < 0:
                    out[k] = self._index[key]
        self._stamp[out] = self._clock
        return out

    def subset(self, keep: np.ndarray) -> ParticleTerms:
        """A new :class:`ParticleTerms` of the particles where ``keep`` (M,) is True, with the
        rows cached so far (copied, same row numbers)."""
        other = ParticleTerms(merge=False, max_bytes=self.max_bytes)
        other.sp, other._generic = self.sp, self._generic
        if self._generic is None:
            other.min_distance, other.shape = self.min_distance, self.shape
            other._plume_constants = np.ascontiguousarray(self._plume_constants[:, keep])
        other._plume, other._sensor_params = self._plume, self._sensor_params
        other._slots = self._slots
        other.theta = np.ascontiguousarray(self.theta[keep])
        other.source = np.ascontiguousarray(other.theta[:, :3])
        other.starts = np.arange(other.n, dtype=np.int64)
        other._key = ("subset", id(other))
        other._grow(max(self.capacity, 8))
        rows = sorted(set(self._index.values()))
        for k, src in enumerate(self.terms):
            other.terms[k][rows] = src[rows][:, keep]
        other._index = dict(self._index)
        other._clock = self._clock
        other._stamp[: len(self._stamp)] = self._stamp
        return other
