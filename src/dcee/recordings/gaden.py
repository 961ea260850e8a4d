"""A GADEN simulation folder (:mod:`dcee.recordings.gaden_files` reads its files) and the
concentration at any point and time computed as GADEN's player computes it.

The concentration (ppm) at a point p inside the grid (0 outside it), as
``gaden::Simulation::CalculateConcentration`` computes it::

    C(p) = Σ_f [|p − x_f| < 3 σ_f / 100 and LOS(p, x_f)] · C0(σ_f) · exp(−d² / (2 σ_f²))
    d = 100 |p − x_f| (cm),   C0(σ) = 10⁶ n_f / (√(8π³) σ³) / n_air

with LOS false unless the cells of both ends are free, and then false if any of the points
p + (x_f − p)/L · (L/n) · i, i = 1 … n − 1, n = ⌊L / cell⌋, lies in a cell that is not free (a
filament reaches nothing through a wall, an outlet or the grid's edge). Cells are looked up as
GADEN does, ⌊(p − min) / cell⌋ per axis in float32, truncated toward zero; the sums are in
float64 (GADEN's float32 sum differs from it by under 4e-7 relative on the samples).
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from dcee.limits import read_text
from dcee.recordings.gaden_files import (
    FREE,
    GAS_MOLAR_MASS,
    GadenGrid,
    GadenResult,
    gaden_error,
    read_occupancy,
    read_result,
    read_wind,
    read_wind_csv,
)

__all__ = [
    "FREE",
    "GAS_MOLAR_MASS",
    "GadenGrid",
    "GadenResult",
    "GadenSimulation",
    "filament_concentration",
    "filament_concentration_reference",
    "read_occupancy",
    "read_result",
    "read_wind",
    "read_wind_csv",
]


def _line_of_sight(a: np.ndarray, b: np.ndarray, grid: GadenGrid, free: np.ndarray) -> np.ndarray:
    """(K,) whether the segments a → b (K, 3) m see each other (GADEN's ``CheckLineOfSight``,
    float32): both ends in free cells and every intermediate point at whole-cell steps too."""
    a32, b32 = a.astype(np.float32), b.astype(np.float32)
    ok = _free_at(a32, grid, free) & _free_at(b32, grid, free)
    vec = b32 - a32
    dist = np.sqrt((vec * vec).sum(axis=1, dtype=np.float32)).astype(np.float32)
    steps = np.zeros(len(a32), dtype=np.int64)
    nz = dist > 0
    steps[nz] = (dist[nz] / np.float32(grid.cell)).astype(np.int64)
    todo = ok & (steps > 1)
    if not todo.any():
        return ok
    a32, vec, dist, steps = a32[todo], vec[todo], dist[todo], steps[todo]
    unit = (vec / dist[:, None]).astype(np.float32)
    increment = (dist / steps.astype(np.float32)).astype(np.float32)
    clear = np.ones(len(a32), dtype=bool)
    for i in range(1, int(steps.max())):
        live = np.flatnonzero(clear & (i < steps))
        if live.size == 0:
            break
        where = a32[live] + unit[live] * (increment[live] * np.float32(i))[:, None]
        clear[live] = _free_at(where, grid, free)
    ok[np.flatnonzero(todo)] = clear
    return ok


def _free_at(points: np.ndarray, grid: GadenGrid, free: np.ndarray) -> np.ndarray:
    idx, inside = grid.cells(points)
    out = np.zeros(len(points), dtype=bool)
    i = idx[inside]
    out[inside] = free[i[:, 0], i[:, 1], i[:, 2]]
    return out


def filament_concentration(
    points: np.ndarray,
    result: GadenResult,
    occupancy: np.ndarray,
    grid: GadenGrid | None = None,
) -> np.ndarray:
    """(M,) ppm at ``points`` (M, 3) m from one result's filaments, as GADEN's player computes
    it (module docstring): 0 outside the grid, each filament within 3 σ and in line of sight
    through free cells of ``occupancy`` (nx, ny, nz) adding its Gaussian. The compiled kernel
    (:mod:`dcee.recordings.gaden_kernel`); :func:`filament_concentration_reference` is its NumPy
    reference."""
    grid = grid or result.grid
    return _compiled(points, result, np.ascontiguousarray(occupancy == FREE), grid)


def _compiled(
    points: np.ndarray, result: GadenResult, free: np.ndarray, grid: GadenGrid
) -> np.ndarray:
    """:func:`filament_concentration` with the free cells (nx, ny, nz) bool given."""
    from dcee.recordings.gaden_kernel import filament_ppm

    points = np.atleast_2d(np.asarray(points, dtype=np.float64))
    out = np.zeros(len(points))
    if len(points) == 0:
        return out
    _, inside = grid.cells(points)
    filament_ppm(
        points.astype(np.float32),
        result.filaments,
        free,
        grid.low.astype(np.float32),
        np.float32(grid.cell),
        inside,
        1e6 * result.moles_per_filament / result.moles_per_cm3,
        out,
    )
    return out


def filament_concentration_reference(
    points: np.ndarray,
    result: GadenResult,
    occupancy: np.ndarray,
    grid: GadenGrid | None = None,
) -> np.ndarray:
    """NumPy reference of :func:`filament_concentration` (the same arguments and result)."""
    grid = grid or result.grid
    points = np.atleast_2d(np.asarray(points, dtype=np.float64))
    out = np.zeros(len(points))
    fil = result.filaments
    if len(fil) == 0 or len(points) == 0:
        return out
    _, inside = grid.cells(points)
    free = occupancy == FREE
    # the cut-off test in float32 as GADEN's (squared distance against (3σ/100)²)
    diff = fil[None, :, :3] - points[:, None, :].astype(np.float32)
    dist2 = (diff * diff).sum(axis=2, dtype=np.float32)
    limit = fil[:, 3] * np.float32(3) / np.float32(100)
    near = (dist2 < limit * limit) & inside[:, None]
    pi, fi = np.nonzero(near)
    if pi.size == 0:
        return out
    seen = _line_of_sight(points[pi], fil[fi, :3].astype(np.float64), grid, free)
    pi, fi = pi[seen], fi[seen]
    sigma = fil[fi, 3].astype(np.float64)
    d_cm = 100.0 * np.sqrt(dist2[pi, fi].astype(np.float64))
    center = 1e6 * result.moles_per_filament / (math.sqrt(8 * math.pi**3) * sigma**3)
    center /= result.moles_per_cm3
    np.add.at(out, pi, center * np.exp(-(d_cm * d_cm) / (2 * sigma * sigma)))
    return out


_ITERATION = re.compile(r"iteration_(\d+)$")


@dataclass
class GadenSimulation:
    """A GADEN simulation folder: the occupancy grid, the result files by iteration and their
    times (s), the wind fields. Result files are read when first asked for and kept."""

    folder: Path
    grid: GadenGrid
    occupancy: np.ndarray
    iterations: np.ndarray
    times: np.ndarray
    _results: dict
    _free: np.ndarray | None = None
    _winds: dict = field(default_factory=dict)

    @classmethod
    def open(cls, folder: str | Path) -> GadenSimulation:
        folder = Path(folder)
        if not folder.is_dir():
            raise gaden_error(folder, "no such folder")
        grid, occupancy = read_occupancy(folder / "OccupancyGrid3D.csv")
        files = {}
        for p in (folder / "result").glob("iteration_*"):
            m = _ITERATION.search(p.name)
            if m:
                files[int(m.group(1))] = p
        if not files:
            raise gaden_error(folder, "no result/iteration_<k> files")
        iterations = np.array(sorted(files))
        missing = sorted(set(range(int(iterations[-1]) + 1)) - set(files))
        if missing:
            raise gaden_error(folder / "result", f"iteration_{missing[0]} is missing")
        times = _iteration_times(folder, iterations)
        first = read_result(files[int(iterations[0])])
        if not first.grid.matches(grid):
            raise gaden_error(
                files[int(iterations[0])],
                f"its grid ({first.grid.describe()}) is not the occupancy grid's "
                f"({grid.describe()})",
            )
        return cls(folder, grid, occupancy, iterations, times, {int(iterations[0]): first})

    def result(self, iteration: int) -> GadenResult:
        if iteration not in self._results:
            res = read_result(self.folder / "result" / f"iteration_{iteration}")
            if not res.grid.matches(self.grid):
                raise gaden_error(
                    f"result/iteration_{iteration}", "its grid is not the occupancy grid's"
                )
            self._results[iteration] = res
        return self._results[iteration]

    def wind(self, index: int = 0) -> np.ndarray:
        """(nx, ny, nz, 3) float32 m/s: GADEN's preprocessed wind state ``index``
        (``wind/wind_iteration_<index>``; a result file names the one it used)."""
        if index not in self._winds:
            path = self.folder / "wind" / f"wind_iteration_{index}"
            self._winds[index] = read_wind(path, self.grid)
        return self._winds[index]

    def iteration_at(self, time: float) -> int:
        """The latest iteration saved at or before ``time`` s (the first before it)."""
        k = int(np.searchsorted(self.times, time + 1e-9, side="right")) - 1
        return int(self.iterations[max(k, 0)])

    def concentration(self, points: np.ndarray, time: float) -> np.ndarray:
        """(M,) ppm at ``points`` (M, 3) m at simulated time ``time`` s (the result saved last
        at or before it)."""
        if self._free is None:
            self._free = np.ascontiguousarray(self.occupancy == FREE)
        return _compiled(points, self.result(self.iteration_at(time)), self._free, self.grid)


def _iteration_times(folder: Path, iterations: np.ndarray) -> np.ndarray:
    """Simulated time (s) of each result file: ``times.csv`` where present, else from
    ``sim.yaml`` (module docstring)."""
    table = folder / "times.csv"
    if table.exists():
        import pandas as pd

        try:
            frame = pd.read_csv(io.StringIO(read_text(table, "GADEN")))
            by_file = dict(zip(frame["file"], frame["t_s"].astype(float), strict=True))
        except (ValueError, KeyError, TypeError) as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise gaden_error(table, f"needs columns file and t_s ({first})") from None
        try:
            times = np.array([by_file[f"iteration_{k}"] for k in iterations], dtype=np.float64)
        except KeyError as exc:
            raise gaden_error(table, f"no time for {exc.args[0]}") from None
        if not (np.all(np.isfinite(times)) and np.all(np.diff(times) > 0)):
            raise gaden_error(table, "the times must be finite and increase with the iteration")
        return times
    sim = folder / "sim.yaml"
    if not sim.exists():
        raise gaden_error(folder, "neither times.csv nor sim.yaml: the result files carry no time")
    import yaml

    try:
        settings = yaml.safe_load(read_text(sim, "GADEN")) or {}
        dt, save = float(settings["deltaTime"]), float(settings["saveDeltaTime"])
    except (yaml.YAMLError, KeyError, TypeError, ValueError, RecursionError) as exc:
        raise gaden_error(sim, f"needs numbers deltaTime and saveDeltaTime ({exc})") from None
    if not (dt > 0 and save >= 0):
        raise gaden_error(sim, f"deltaTime {dt} must be > 0 and saveDeltaTime {save} ≥ 0")
    ratio = save / dt
    if abs(ratio - round(ratio)) < 1e-6:
        raise gaden_error(
            sim,
            f"saveDeltaTime / deltaTime = {ratio:g} is whole: GADEN's float32 clock decides "
            "which step saves; give the times as times.csv (file,t_s)",
        )
    steps = math.floor(ratio) + 1
    return iterations * steps * dt
