"""Where a broad belief is densest: the window the planners go after while they look for a
release the readings have not found.

A further release's marginal, once the found releases are localised, is spread over every
place the readings have not ruled out: the far edges, the ground upwind of what was sampled,
the corners whose gas leaves the area. Its mean lies between those places, often where the
readings have already ruled a release out, and its spread is so wide that the closed-loop
planner's reach (twice the spread) charges no distance anywhere: the robot then follows the
local information gradient and wanders (issue 45: random3:5 and random3:20 circled for
hundreds of seconds beside the releases they had found). The planners instead read the
particles in the densest window of the marginal, a square of ``FOCUS_CELLS`` × ``FOCUS_CELLS``
cells: a belief narrow enough to travel to. When the readings there rule the release out, the
mass moves and so does the window; a window is kept while it holds at least ``FOCUS_KEEP`` of
the densest one's mass, so that two nearly equal windows do not make the robot turn back and
forth, and until the robot has taken ``FOCUS_SPENT`` readings inside it.
"""

from __future__ import annotations

import numpy as np

FOCUS_CELL = 5.0
"""m: the side of the grid's cells (a tenth of the paper's 50 m area)."""

FOCUS_CELLS = 3
"""The window's side in cells (15 m at 5 m cells): about the width of a plume the paper's
sensor detects a few tens of metres downwind."""

FOCUS_KEEP = 0.5
"""The share of the densest window's mass above which the current window is kept."""

FOCUS_SPENT = 15
"""Readings taken inside a window after which it is searched: the planners move on to the
densest window not searched (30 s at the paper's 2 s per move: time to cross a 15 m window
twice). A window whose mass the readings there could not remove is one the sensor cannot test
(a release at the edge whose gas leaves the area, or under the sensor's altitude); more
readings of the same kind would not remove it either, and a robot kept there paced for the
rest of the search (random3:5 and random3:20 of the tuning range, hundreds of seconds)."""


def window_sums(
    cells: np.ndarray, values: np.ndarray, origin: np.ndarray, shape: tuple[int, int]
) -> np.ndarray:
    """(n_x - FOCUS_CELLS + 1, n_y - FOCUS_CELLS + 1) the sum of ``values`` (M,) over every
    ``FOCUS_CELLS``-square window of the (n_x, n_y) grid of lattice cells starting at
    ``origin`` (2,), indexed by the window's lower-left cell. cells: (M, 2) lattice cells
    (floor of m / cell); those outside the grid are left out."""
    idx = (np.asarray(cells, dtype=np.int64) - origin.astype(np.int64)).reshape(-1, 2)
    ok = np.all((idx >= 0) & (idx < shape), axis=1)
    flat = idx[ok, 0] * shape[1] + idx[ok, 1]
    grid = np.bincount(flat, np.asarray(values)[ok], shape[0] * shape[1]).reshape(shape)
    summed = np.cumsum(np.cumsum(np.pad(grid, ((1, 0), (1, 0))), axis=0), axis=1)
    k = FOCUS_CELLS
    return summed[k:, k:] - summed[:-k, k:] - summed[k:, :-k] + summed[:-k, :-k]


def densest_window(
    xy: np.ndarray,
    weights: np.ndarray,
    keep: tuple[float, float] | None = None,
    visits: dict[tuple[int, int], int] | None = None,
    cell: float = FOCUS_CELL,
) -> tuple[float, float]:
    """(x, y) m, the lower-left corner of the densest window not yet searched (fewer than
    ``FOCUS_SPENT`` readings taken inside it), or ``keep`` (a corner returned before) while it
    holds at least ``FOCUS_KEEP`` of that window's mass and is not spent itself. xy: (N, 2) m;
    weights: (N,); visits: readings taken in each lattice cell (floor of m / ``cell``)."""
    xy = np.asarray(xy, dtype=np.float64)
    cells = np.floor(xy / cell)
    origin = cells.min(axis=0)
    shape = tuple(int(v) for v in np.maximum(cells.max(axis=0) - origin + 1, FOCUS_CELLS))
    masses = window_sums(cells, weights, origin, shape)
    spent = np.zeros(masses.shape, dtype=bool)
    if visits:
        counts = window_sums(np.array(list(visits)), np.array(list(visits.values())), origin, shape)
        spent = counts >= FOCUS_SPENT
        if spent.all():  # every window searched: the densest again
            spent[:] = False
    open_masses = np.where(spent, -np.inf, masses)
    i, j = np.unravel_index(int(np.argmax(open_masses)), masses.shape)
    if keep is not None:
        ki, kj = (int(v) for v in np.round(np.divide(keep, cell) - origin))
        if (
            0 <= ki < masses.shape[0]
            and 0 <= kj < masses.shape[1]
            and not spent[ki, kj]
            and masses[ki, kj] >= FOCUS_KEEP * masses[i, j]
        ):
            return keep
    return float((origin[0] + i) * cell), float((origin[1] + j) * cell)
