"""Agent model p_{k+1} = p_k + u_k (the paper's eq. 1) on eight headings at a fixed altitude,
optionally with a climb and a descent (``climb``)."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from dcee.errors import DceeInputError

if TYPE_CHECKING:
    from dcee.models.site import SiteMap


@dataclass(frozen=True)
class SearchVolume:
    """Axis-aligned search volume in m: lower corner ``low`` and upper corner ``high``."""

    low: tuple[float, float, float]
    high: tuple[float, float, float]

    @functools.cached_property
    def _corners(self) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(self.low, dtype=np.float64), np.asarray(self.high, dtype=np.float64)

    def contains(self, points: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """(K, 3) points → (K,) bool, inside the volume (boundary included)."""
        p = points if np.ndim(points) == 2 else np.atleast_2d(points)
        # the tree search asks thousands of times per decision: array methods, not np.all's
        # dispatch, and the corners kept
        low, high = self._corners
        return ((p >= low - tol) & (p <= high + tol)).all(axis=1)


CANDIDATES_KEPT = 65_536
"""Positions whose move sets a :class:`GridAgent` keeps (a few MB at most)."""


@dataclass(frozen=True)
class GridAgent:
    """Mobile sensor that moves ``step`` metres along one of ``headings`` directions.

    Headings are measured from +x towards +y (0°, 45°, …, 315° by default). With ``climb`` > 0
    two more moves change the altitude by ±``climb`` m at the same horizontal position (indices
    ``n_headings`` up and ``n_headings`` + 1 down; a fixed altitude, the paper's agent, with 0).
    Moves that would leave
    the search volume, or enter or cross a blocked cell of the ``site``
    (:class:`~dcee.models.site.SiteMap`: obstacles and no-go zones), are inadmissible. Each move
    takes ``step / speed + dwell`` seconds: travel plus the sampling dwell the sensor needs for
    a reading.
    """

    volume: SearchVolume
    step: float = 2.0
    speed: float = 2.0
    dwell: float = 1.0
    n_headings: int = 8
    site: SiteMap | None = None
    climb: float = 0.0

    def __post_init__(self) -> None:
        if not self.step > 0:
            raise DceeInputError("agent.step", f"must be > 0 m, got {self.step}")
        if not self.speed > 0:
            raise DceeInputError("agent.speed", f"must be > 0 m/s, got {self.speed}")
        if not self.dwell >= 0:
            raise DceeInputError("agent.dwell", f"must be >= 0 s, got {self.dwell}")
        if self.n_headings < 1:
            raise DceeInputError("agent.n_headings", f"must be >= 1, got {self.n_headings}")
        if not self.climb >= 0:
            raise DceeInputError("agent.climb", f"must be >= 0 m, got {self.climb}")

    @functools.cached_property
    def moves(self) -> np.ndarray:
        """(n_moves, 3) displacement vectors u in m: the headings (z component 0), then, with
        ``climb`` > 0, (0, 0, +climb) and (0, 0, −climb). Computed once per agent (read-only:
        the tree search asks for the candidates thousands of times per decision)."""
        angles = 2 * np.pi * np.arange(self.n_headings) / self.n_headings
        out = np.zeros((self.n_moves, 3))
        out[: self.n_headings, 0] = np.round(self.step * np.cos(angles), 12)
        out[: self.n_headings, 1] = np.round(self.step * np.sin(angles), 12)
        if self.climb > 0:
            out[self.n_headings :, 2] = (self.climb, -self.climb)
        out.flags.writeable = False
        return out

    @property
    def n_moves(self) -> int:
        """Number of moves: ``n_headings``, plus 2 with ``climb`` > 0."""
        return self.n_headings + (2 if self.climb > 0 else 0)

    @property
    def step_time(self) -> float:
        """Seconds per move: travel time plus sampling dwell (a climb or a descent is charged
        the same as a horizontal move)."""
        return self.step / self.speed + self.dwell

    @functools.cached_property
    def _candidates_kept(self) -> dict[bytes, tuple[np.ndarray, np.ndarray]]:
        return {}

    def __getstate__(self) -> dict:
        """What a checkpoint or a worker process gets: the fields, not the kept move sets (a
        cache, rebuilt on use)."""
        state = dict(self.__dict__)
        state.pop("_candidates_kept", None)
        return state

    def candidates(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Admissible next positions from ``position``: ((M, 3) positions, (M,) heading
        indices), read-only. Kept per position (the move set from a point never changes, and
        the tree search asks for the same few thousands of times per decision); at most
        :data:`CANDIDATES_KEPT` positions, then the kept ones are dropped."""
        position = np.asarray(position, dtype=np.float64)
        key = position.tobytes()
        kept = self._candidates_kept.get(key)
        if kept is not None:
            return kept
        nxt = position[None, :] + self.moves
        ok = self.volume.contains(nxt)
        if self.site is not None and ok.any():
            ok[ok] = self.site.segment_clear(position, nxt[ok])
        out = (nxt[ok], np.flatnonzero(ok))
        for a in out:
            a.flags.writeable = False
        if len(self._candidates_kept) >= CANDIDATES_KEPT:
            self._candidates_kept.clear()
        self._candidates_kept[key] = out
        return out


def travel_xy(site: SiteMap | None, start: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Horizontal travel distance (m) from ``start`` (2,) or (3,) to ``points`` (..., 2|3):
    the straight line without a ``site`` or where the way is clear, else the path around its
    blocked cells (:meth:`dcee.models.site.SiteMap.travel_distance`)."""
    start = np.asarray(start, dtype=np.float64)
    points = np.asarray(points, dtype=np.float64)
    if site is None or not site.blocked.any():
        return np.hypot(points[..., 0] - start[0], points[..., 1] - start[1])
    return site.travel_distance(start, points)


def stall_start(xy: np.ndarray, step: float) -> int:
    """Index of the first of the latest run of positions that all lie within ``step`` m
    (horizontally) of it: the latest k with every row of ``xy[k:]`` within ``step`` of
    ``xy[k]`` and none earlier (the stall guard's window; ``xy`` (n, 2 or 3) m, n ≥ 1, in time
    order). A robot that moved on has its last position alone (n − 1) or its last move."""
    xy = np.asarray(xy, dtype=np.float64)[:, :2]
    reach = step * (1.0 + 1e-9) + 1e-9
    # all pairs at once (the searcher asks before every decision, over up to 64 positions):
    # row i holds the distances of xy[j] from xy[i]; only j ≥ i count
    d = xy[None, :, :] - xy[:, None, :]
    near = np.hypot(d[..., 0], d[..., 1]) <= reach
    near |= np.tri(len(xy), k=-1, dtype=bool)
    return int(np.flatnonzero(near.all(axis=1))[0])
