"""The compiled GADEN concentration (numba): :func:`dcee.recordings.gaden.filament_concentration`
runs it; :func:`dcee.recordings.gaden.filament_concentration_reference` is the NumPy reference
it is tested against (tests/test_gaden.py: equal on both samples' reference points and on
random points over the rooms). Float32 where GADEN computes in float32 (positions, the cut-off,
the line-of-sight walk and its cell look-ups), float64 sums."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_NORM = 1.0 / math.sqrt(8.0 * math.pi**3)


@njit(cache=True, inline="always")
def _free_cell(x, y, z, low, cell, free) -> bool:
    """Whether the float32 point (x, y, z) lies in a free cell of ``free`` (nx, ny, nz)."""
    rx, ry, rz = (x - low[0]) / cell, (y - low[1]) / cell, (z - low[2]) / cell
    if rx <= -1.0 or ry <= -1.0 or rz <= -1.0:
        return False
    # int() truncates toward zero, as GADEN's cast: (low - cell, low) maps to 0
    i, j, k = int(rx), int(ry), int(rz)
    if i >= free.shape[0] or j >= free.shape[1] or k >= free.shape[2]:
        return False
    return free[i, j, k]


@njit(cache=True)
def filament_ppm(
    points: np.ndarray,
    filaments: np.ndarray,
    free: np.ndarray,
    low: np.ndarray,
    cell: np.float32,
    inside: np.ndarray,
    moles_ratio: float,
    out: np.ndarray,
) -> None:
    """out[m] = ppm at points[m] (M, 3) float32 from ``filaments`` (N, 4) float32 (x, y, z m;
    σ cm); ``free`` (nx, ny, nz) bool, ``low`` (3,) float32 m, ``cell`` m; ``inside`` (M,)
    whether each point lies in the grid; ``moles_ratio`` = 10⁶ n_filament / n_air."""
    three, hundred = np.float32(3.0), np.float32(100.0)
    for m in range(points.shape[0]):
        out[m] = 0.0
        if not inside[m]:
            continue
        px, py, pz = points[m, 0], points[m, 1], points[m, 2]
        start_free = _free_cell(px, py, pz, low, cell, free)
        acc = 0.0
        for f in range(filaments.shape[0]):
            dx = filaments[f, 0] - px
            dy = filaments[f, 1] - py
            dz = filaments[f, 2] - pz
            d2 = dx * dx + dy * dy + dz * dz
            limit = filaments[f, 3] * three / hundred
            if not d2 < limit * limit:
                continue
            if not start_free:
                continue
            if not _free_cell(filaments[f, 0], filaments[f, 1], filaments[f, 2], low, cell, free):
                continue
            dist = np.float32(np.sqrt(d2))
            steps = int(dist / cell) if dist > 0 else 0
            clear = True
            if steps > 1:
                ux, uy, uz = dx / dist, dy / dist, dz / dist
                increment = dist / np.float32(steps)
                for i in range(1, steps):
                    s = increment * np.float32(i)
                    if not _free_cell(px + ux * s, py + uy * s, pz + uz * s, low, cell, free):
                        clear = False
                        break
            if not clear:
                continue
            sigma = np.float64(filaments[f, 3])
            d_cm = 100.0 * math.sqrt(np.float64(d2))
            center = moles_ratio * _NORM / (sigma * sigma * sigma)
            acc += center * math.exp(-(d_cm * d_cm) / (2.0 * sigma * sigma))
        out[m] = acc
