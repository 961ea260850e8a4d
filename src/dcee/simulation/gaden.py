"""A GADEN simulation played back as the truth (``truth.model = {kind = "gaden", folder =
...}``): the concentration at the sensor computed from GADEN's filaments as GADEN's player
computes it (:mod:`dcee.recordings.gaden`), in g/m³.

Time: search time t reads the result file saved last at or before simulated time
``start`` + t (GADEN's player holds each file until the next); past the last file the
playback starts again at ``start`` when ``loop`` is set (GADEN's player loops the same way).
Units: GADEN's ppm are mole fractions: C [g/m³] = ppm · 10⁻⁶ · n_air · M, with the air's
molar density n_air that GADEN wrote in the files (mol/cm³ · 10⁶ cm³/m³) and the gas's molar
mass M.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dcee.errors import DceeInputError
from dcee.recordings.gaden import FREE, GAS_MOLAR_MASS, GadenSimulation
from dcee.simulation.truth import TruthModel, register_truth

if TYPE_CHECKING:
    from dcee.scenarios import Scenario


class GadenTruth(TruthModel):
    """GADEN's filaments at search time t (module docstring). ``simulation``: the opened
    folder; ``start`` s of simulated time at t = 0; ``molar_mass`` g/mol."""

    name = "gaden"
    label = "GADEN simulation"

    def __init__(
        self, simulation: GadenSimulation, start: float, loop: bool, molar_mass: float
    ) -> None:
        self.simulation = simulation
        self.start = float(start)
        self.loop = loop
        times = simulation.times
        if self.start > times[-1]:
            raise DceeInputError(
                "truth.model.start",
                f"{start:g} s is after the last result file ({times[-1]:g} s)",
            )
        self.first_time = float(times[np.searchsorted(times, self.start + 1e-9, "right") - 1])
        self.end = float(times[-1])
        steps = np.diff(times)
        # s between files: read at every sample of every hold, so worked out once
        self._time_step = float(steps.min()) if len(steps) else None
        first = simulation.result(int(simulation.iterations[0]))
        # g/m³ per ppm: 1e-6 mole fraction × n_air (mol/cm³ → mol/m³) × M (g/mol)
        self.grams_per_ppm = 1e-6 * first.moles_per_cm3 * 1e6 * molar_mass

    @property
    def time_step(self) -> float | None:
        return self._time_step

    @property
    def duration(self) -> float:
        """s of search time before the files end (a looped playback goes on)."""
        return self.end - self.start

    def simulated_time(self, time: float) -> float:
        """The simulated time (s) that search time ``time`` reads."""
        t = self.start + float(time)
        if t > self.end + 1e-9 and self.loop:
            period = self.end - self.first_time + (self.time_step or 0.0)
            t = self.first_time + (t - self.first_time) % period if period > 0 else self.end
        return t

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        points = np.atleast_2d(np.asarray(positions, dtype=np.float64))
        ppm = self.simulation.concentration(points, self.simulated_time(time))
        return ppm * self.grams_per_ppm

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.field(np.asarray(position, dtype=np.float64)[None, :], time)[0])


def gaden_truth(
    folder: str | Path, start: float, loop: bool, molar_mass: float | None
) -> GadenTruth:
    """The GADEN folder opened and checked (one-line errors) as a truth."""
    simulation = GadenSimulation.open(folder)
    gas = simulation.result(int(simulation.iterations[0])).gas_type
    if molar_mass is None:
        if gas not in GAS_MOLAR_MASS:
            raise DceeInputError(
                "truth.model.molar_mass",
                f"the files name GADEN gas type {gas}; give its molar mass in g/mol",
            )
        molar_mass = GAS_MOLAR_MASS[gas]
    return GadenTruth(simulation, start, loop, molar_mass)


@register_truth("gaden")
def _gaden(scenario: Scenario, seed: int) -> GadenTruth:
    spec = scenario.truth.model
    truth = gaden_truth(spec.folder, spec.start, spec.loop, spec.molar_mass)
    source = truth.simulation.result(int(truth.simulation.iterations[0])).source_position
    theta = scenario.truth_theta()
    if not np.allclose(source, theta[:3], atol=1e-4):
        raise DceeInputError(
            "truth",
            f"the GADEN files release at {tuple(round(float(v), 4) for v in source)} m; the "
            f"scenario's x, y, z are {tuple(float(v) for v in theta[:3])}",
        )
    budget = scenario.search.budget
    if not spec.loop and budget > truth.duration + 1e-9:
        raise DceeInputError(
            "search.budget",
            f"{budget:g} s but the GADEN files last {truth.duration:g} s from "
            f"truth.model.start (set truth.model.loop = true or shorten the budget)",
        )
    start = np.asarray(scenario.agent.start, dtype=np.float64)
    idx, inside = truth.simulation.grid.cells(start[None, :])
    if inside[0] and truth.simulation.occupancy[tuple(idx[0])] != FREE:
        raise DceeInputError(
            "agent.start",
            f"{tuple(float(v) for v in start)} m lies in a wall or door cell of the GADEN room",
        )
    low, high = np.array(scenario.volume.low), np.array(scenario.volume.high)
    grid = truth.simulation.grid
    if np.any(low < grid.low - 1e-9) or np.any(high > grid.high + 1e-9):
        raise DceeInputError("volume", f"reaches outside the GADEN grid ({grid.describe()})")
    return truth
