"""The ``[volume]`` and ``[truth]`` sections: where the search happens, the true source term and
what the sensor really sees (``truth.model``: the registry of truth kinds)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, Field, field_validator, model_validator

from dcee.recordings import recording_layout
from dcee.scenarios.schema.common import FIELD_MARK, FROZEN, Finite, Positive, phi_fields

TURBULENT_HOLD = 4.0
"""Default hold (s) at each waypoint for a time-varying truth, over which a reading averages.
On the filament truth (paper:1 centreline, 5-30 m downwind) a 5 s average cuts the share of
below-threshold readings from 66-84 % to 10-25 % and the p99/mean ratio from 14-27 to 4-5; a
longer hold gives fewer readings in the budget. Chosen by search success (infotaxis, filament
truth, full unknown, 12 × 3, 10,000 particles): hold 2 / 3 / 4 / 5 / 7 s acquired the source in
4/12 / 5/12 / 33/36 / 26/36 / 23/36 (docs/scenarios.md)."""


class Volume(BaseModel):
    """The search volume (m); the source-location prior is uniform over it."""

    model_config = FROZEN
    low: tuple[Finite, Finite, Finite]
    """lower corner (x, y, z), m"""
    high: tuple[Finite, Finite, Finite]
    """upper corner (x, y, z), m; moves that leave the volume are inadmissible"""

    @model_validator(mode="after")
    def _ordered(self) -> Volume:
        for k, (lo, hi) in enumerate(zip(self.low, self.high, strict=True)):
            if hi < lo:
                raise ValueError(f"high[{k}] = {hi} must be >= low[{k}] = {lo}")
        return self


class FilamentSpec(BaseModel):
    """Turbulent filament (puff) truth after Farrell et al. (2002); see
    :mod:`dcee.simulation.filament` for the model and docs/scenarios.md for why each default."""

    model_config = FROZEN
    kind: Literal["filament"] = "filament"
    puff_rate: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 10.0
    """puffs released per second (Farrell: 10/s)"""
    dt: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.1
    """integration step of the puff dynamics, s"""
    puff_radius: Annotated[float, Field(gt=0, allow_inf_nan=False)] = 0.1
    """initial puff radius (Gaussian σ), m"""
    puff_share: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.03
    """share of the diffusivity ζ1 that grows each puff; the rest moves puff centres at random"""
    meander_intensity: Annotated[float, Field(ge=0, le=2, allow_inf_nan=False)] = 0.2
    """standard deviation of each horizontal meander velocity component / mean wind speed"""
    meander_bandwidth: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.2
    """natural frequency ω of the coloured-noise meander process, rad/s (Farrell: 0.2-0.71)"""
    meander_damping: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.1
    """damping ratio ζ of the meander process (Farrell: 0.07-0.1)"""

    @property
    def name(self) -> str:
        return "filament"


class PuffsSpec(BaseModel):
    """Puff plume in a meandering, spatially correlated wind field after Farrell et al. (2002),
    written apart from the filament truth; see :mod:`dcee.simulation.puffs` for the model and
    docs/scenarios.md for why each default. It ignores the truth's ζ1 and ζ2."""

    model_config = FROZEN
    kind: Literal["puffs"] = "puffs"
    puff_rate: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 10.0
    """mean puffs released per second, a Poisson process (Farrell: 10/s)"""
    dt: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.1
    """integration step of the puffs and the wind field, s"""
    puff_radius: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.1
    """initial puff radius (Gaussian σ), m"""
    puff_diffusivity: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.02
    """growth of each puff, σ² = radius² + 2 · this · age, m²/s"""
    centre_diffusivity: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.6
    """random walk of the puff centres (Farrell's centre-relative dispersion), m²/s"""
    meander_intensity: Annotated[float, Field(ge=0, le=2, allow_inf_nan=False)] = 0.5
    """standard deviation of each boundary wind component's noise / mean wind speed (inside
    the search area the wind's fluctuation is about half of it: carried in and smoothed)"""
    meander_time: Annotated[float, Field(gt=0, le=600, allow_inf_nan=False)] = 5.0
    """correlation time of the boundary wind noise (Ornstein-Uhlenbeck), s"""
    boundary_spacing: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 20.0
    """distance between independent noise anchors round the wind grid's boundary, m"""
    wind_spacing: Annotated[float, Field(gt=0, le=100, allow_inf_nan=False)] = 5.0
    """wind grid spacing, m"""
    wind_diffusivity: Annotated[float, Field(ge=0, le=1000, allow_inf_nan=False)] = 2.0
    """diffusivity K_w smoothing the wind field, m²/s"""
    margin: Annotated[float, Field(ge=0, le=1000, allow_inf_nan=False)] = 20.0
    """the wind grid extends this far beyond the search area on every side, m"""

    @property
    def name(self) -> str:
        return "puffs"


class LbmSpec(BaseModel):
    """A plume computed by a fluid solver from a well-kept library, not by code written here:
    the lattice Boltzmann method of lbmpy (cumulant collision with a Smagorinsky subgrid model)
    solves the incompressible Navier-Stokes equations in 2-D behind a grid of bars, whose wakes
    make the flow turbulent, and a second lattice carries a passive scalar from a continuous
    release downstream of it (:mod:`dcee.simulation.lbm`, docs/scenarios.md). It is computed
    once per parameter set in a canonical frame (source at the origin, wind along +x at 1 m/s),
    cached as a CF NetCDF recording and replayed through the playback truth, moved to the
    scenario's source, turned to its wind direction and run at its wind speed (the flow is the
    same at any speed at the same Reynolds number; time scales as 1/u). The plume is planar: one
    horizontal plane through the source, the same at every altitude, so the search is planar;
    the reading model takes the source at ``truth.z``, so set it to the flight height for the
    plane through the source (the studies do). It ignores the truth's ζ1 and ζ2.
    Lengths are metres in the canonical frame."""

    model_config = FROZEN
    kind: Literal["lbm"] = "lbm"
    spacing: Annotated[float, Field(gt=0.05, le=5, allow_inf_nan=False)] = 0.5
    """lattice spacing, m"""
    store_stride: Annotated[int, Field(ge=1, le=16)] = 2
    """every this many lattice cells is stored (and read back bilinearly), both ways"""
    lattice_speed: Annotated[float, Field(gt=0, le=0.15, allow_inf_nan=False)] = 0.1
    """mean inflow in lattice units (a Mach number times √3; the method needs it small)"""
    relaxation: Annotated[float, Field(gt=1.0, lt=2.0, allow_inf_nan=False)] = 1.99
    """relaxation rate ω of the flow lattice: kinematic viscosity (1/ω − 1/2)/3 lattice units
    (bar Reynolds number about 180 with the defaults, before the subgrid model)"""
    smagorinsky: Annotated[float, Field(ge=0, le=0.5, allow_inf_nan=False)] = 0.12
    """Smagorinsky constant of the subgrid model (0: none)"""
    scalar_relaxation: Annotated[float, Field(gt=1.0, lt=2.0, allow_inf_nan=False)] = 1.9
    """odd-moment relaxation rate of the scalar lattice: diffusivity (1/ω − 1/2)/3 lattice units
    (1.9: 0.044 m²/s at 1 m/s; 1.6 smeared the plume to a centreline intensity of 0.13-0.44)"""
    bar_diameter: Annotated[float, Field(gt=0, le=50, allow_inf_nan=False)] = 1.5
    """diameter of the turbulence grid's bars, m"""
    bar_spacing: Annotated[float, Field(gt=0, le=200, allow_inf_nan=False)] = 6.0
    """distance between the bars' centres, m (the grid's mesh)"""
    grid_distance: Annotated[float, Field(gt=0, le=500, allow_inf_nan=False)] = 40.0
    """how far upstream of the source the bars stand, m"""
    downstream: Annotated[float, Field(gt=0, le=2000, allow_inf_nan=False)] = 76.0
    """the domain reaches this far downwind of the source, m; beyond it, and upstream of the
    inflow or beyond half the width crosswind, the field is 0"""
    width: Annotated[float, Field(gt=0, le=2000, allow_inf_nan=False)] = 96.0
    """crosswind width of the domain, m (periodic)"""
    source_radius: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.5
    """radius of the release disc held at a fixed concentration, m"""
    spinup: Annotated[float, Field(ge=0, le=100_000, allow_inf_nan=False)] = 300.0
    """canonical seconds run before recording (the flow and the plume settle)"""
    duration: Annotated[float, Field(gt=0, le=100_000, allow_inf_nan=False)] = 1200.0
    """canonical seconds recorded; a search replays them in a loop from a seeded start"""
    frame_interval: Annotated[float, Field(gt=0, le=100, allow_inf_nan=False)] = 1.0
    """canonical seconds between stored frames (at 4 m/s wind: 0.25 s)"""
    layer_depth: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 2.0
    """m: the release spread over this depth gives the plane's concentration (g/m³) from
    the scenario's q (g/s): the plane carries q / layer_depth per metre of height"""
    realisation: Annotated[int, Field(ge=0, le=1_000_000)] = 0
    """seed of the initial perturbation: another realisation of the same turbulent flow"""

    @property
    def name(self) -> str:
        return "lbm"


class Lbm3dSpec(BaseModel):
    """A 3-D plume computed by a fluid solver nobody here wrote: lbmpy's lattice Boltzmann
    large-eddy simulation (D3Q19 cumulant, Smagorinsky) of a neutral surface layer, the log-law
    wind over rough ground (lbmpy's wall function with the Monin-Obukhov wall model), with
    the surface layer's eddies entering at the inflow, carrying a passive scalar from a
    release at the scenario's source height (:mod:`dcee.simulation.lbm3d`, docs/plumes.md).
    Computed once per parameter set and source height (the height of the lattice cell the
    source lies in) in a canonical frame (source at x = y = 0, wind along +x at 1 m/s at
    4 m), cached as a 3-D CF NetCDF recording (time, z, y, x) and replayed moved to the
    scenario's source, turned to its wind direction and run at its wind speed. The readings
    change with altitude: the search is 3-D and the source height is estimated. It ignores
    the truth's ζ1 and ζ2. Lengths are metres in the canonical frame."""

    model_config = FROZEN
    kind: Literal["lbm3d"] = "lbm3d"
    spacing: Annotated[float, Field(gt=0.1, le=5, allow_inf_nan=False)] = 0.5
    """lattice spacing, m (every way)"""
    store_stride: Annotated[int, Field(ge=1, le=16)] = 2
    """horizontal cells stored as one block mean (vertically every cell is stored)"""
    lattice_speed: Annotated[float, Field(gt=0, le=0.12, allow_inf_nan=False)] = 0.08
    """mean wind at 4 m in lattice units (the wind at the lid is 1.2 times it)"""
    relaxation: Annotated[float, Field(gt=1.0, lt=2.0, allow_inf_nan=False)] = 1.99
    """relaxation rate ω of the flow lattice"""
    smagorinsky: Annotated[float, Field(ge=0, le=0.5, allow_inf_nan=False)] = 0.12
    """Smagorinsky constant of the subgrid model (0: none)"""
    scalar_relaxation: Annotated[float, Field(gt=1.0, lt=2.0, allow_inf_nan=False)] = 1.97
    """odd-moment relaxation rate of the scalar lattice: diffusivity (1/ω − 1/2)/3 lattice units
    (1.97: 0.016 m²/s at 1 m/s; 1.9, the lbm truth's, smoothed the plume to a centreline
    intensity of 0.5-0.8 and no time without gas within 40 m: one scratch run of each)"""
    roughness: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.03
    """m, the ground's roughness length z0 (0.03: open grassland, anchors.md)"""
    wall_filter: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.005
    """exponential filter weight per step of the wall model's reference velocity"""
    turbulence: Annotated[float, Field(ge=0, le=5, allow_inf_nan=False)] = 1.0
    """the inflow eddies' standard deviations over the neutral surface layer's (σu, σv, σw =
    2.4, 1.9, 1.25 u*; 0: a laminar inflow)"""
    eddy_length: Annotated[float, Field(gt=0, le=100, allow_inf_nan=False)] = 4.0
    """m, crosswind correlation length (Gaussian σ) of the inflow eddies (half of it vertically)"""
    eddy_time: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 8.0
    """canonical s, time constant of the inflow eddies"""
    inflow_distance: Annotated[float, Field(gt=0, le=500, allow_inf_nan=False)] = 15.0
    """how far upstream of the source the inflow is, m"""
    downstream: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 60.0
    """the domain reaches this far downwind of the source, m; beyond it, upstream of the
    inflow or beyond half the width crosswind, the field is 0"""
    width: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 48.0
    """crosswind width of the domain, m (periodic)"""
    height: Annotated[float, Field(gt=2, le=200, allow_inf_nan=False)] = 16.0
    """m from the ground to the free-slip lid"""
    store_height: Annotated[float, Field(gt=1, le=200, allow_inf_nan=False)] = 10.0
    """m: stored up to this height (above it the field reads 0)"""
    source_radius: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] = 0.5
    """radius of the ball of cells held at a fixed concentration, m"""
    spinup: Annotated[float, Field(ge=0, le=100_000, allow_inf_nan=False)] = 120.0
    """canonical seconds run before recording (the flow and the plume settle)"""
    duration: Annotated[float, Field(gt=0, le=100_000, allow_inf_nan=False)] = 240.0
    """canonical seconds recorded; a search replays them in a loop from a seeded start"""
    frame_interval: Annotated[float, Field(gt=0, le=100, allow_inf_nan=False)] = 1.0
    """canonical seconds between stored frames"""
    realisation: Annotated[int, Field(ge=0, le=1_000_000)] = 0
    """seed of the initial perturbation: another realisation of the same turbulent flow"""
    plane: Annotated[float | None, Field(ge=0, le=200, allow_inf_nan=False)] = None
    """m (the world's z): replay only this horizontal slice of the plume, the same at
    every altitude (a planar recording of it, as a 2-D measurement or simulation holds); the
    agent flies at this height and the source height is estimated below it. None: the 3-D
    plume"""

    @property
    def name(self) -> str:
        return "lbm3d" if self.plane is None else f"lbm3d-slice@{self.plane:g}m"


class PlaybackSpec(BaseModel):
    """A recorded or externally simulated plume played back as truth
    (:mod:`dcee.simulation.playback`)."""

    model_config = FROZEN
    kind: Literal["playback"] = "playback"
    file: str = Field(min_length=1)
    """.npy (metadata in a .json beside it), .h5, or a CF-convention NetCDF file (.nc; or .h5
    with ``variable`` or ``axes`` set); relative to the scenario file"""
    variable: str | None = None
    """NetCDF: the concentration variable; None: found by its units (docs/scenarios.md)"""
    axes: dict[Literal["t", "x", "y", "z"], str] = Field(default_factory=dict)
    """NetCDF: dimension name of each axis where the file's CF attributes do not tell, e.g.
    ``{t = "time", x = "easting"}``"""
    units: str | None = None
    """NetCDF: concentration units overriding the file's (g/m3, kg m-3, mg/m3, ug/m3, ppm,
    ppb, mol/mol)"""
    molar_mass: Annotated[float | None, Field(gt=0, le=1000, allow_inf_nan=False)] = None
    """g/mol of the released gas: needed to convert a mixing ratio (ppm, ppb) to g/m³"""
    temperature: Annotated[float, Field(gt=0, le=1000, allow_inf_nan=False)] = 293.15
    """K, for a mixing ratio's conversion (ideal gas)"""
    pressure: Annotated[float, Field(gt=0, le=1e7, allow_inf_nan=False)] = 101325.0
    """Pa, for a mixing ratio's conversion (ideal gas)"""
    time_interpolation: Literal["nearest", "linear"] = "linear"
    loop: bool = False
    """replay from the first frame when the recording ends (else the budget must fit in it)"""

    @property
    def name(self) -> str:
        return f"playback:{Path(self.file).name}"


class GadenSpec(BaseModel):
    """A simulation of GADEN, the field's filament dispersion simulator for indoor scenes
    (Monroy et al. 2017; gaden_core 3.0), played back as GADEN's player plays it
    (:mod:`dcee.simulation.gaden`): the folder holds its ``result/iteration_<k>`` files, its
    ``OccupancyGrid3D.csv`` and its ``wind/`` (docs/guide/plume-data.md). Concentrations in ppm
    are converted to g/m³ with the air's molar density that GADEN wrote in the files and the
    gas's molar mass; the scenario's source must be the release the files name."""

    model_config = FROZEN
    kind: Literal["gaden"] = "gaden"
    folder: str = Field(min_length=1)
    """the GADEN simulation folder (a relative path is taken from the scenario file)"""
    start: Annotated[float, Field(ge=0, le=1e6, allow_inf_nan=False)] = 60.0
    """s of simulated time at which the search begins (the gas has spread through the room by
    then: on the samples the plume crosses the 10 m room in about 25 s)"""
    loop: bool = True
    """past the last file, replay from ``start`` (GADEN's player loops the same way); else the
    search budget must end within the files"""
    molar_mass: Annotated[float | None, Field(gt=0, le=1000, allow_inf_nan=False)] = None
    """g/mol of the gas; None: from the gas type the files name (GADEN's gas type 0, ethanol,
    46.07 g/mol; another type must give it)"""

    @property
    def name(self) -> str:
        return f"gaden:{Path(self.folder).name}"


@dataclass
class TruthKind:
    """One kind of ``truth.model``: its parameter table (None: a bare name, no parameters) and
    the factory ``(scenario, seed) -> TruthModel`` that :mod:`dcee.simulation` registers for it
    with :func:`dcee.simulation.truth.register_truth` (None until that module is imported)."""

    spec: type[BaseModel] | None
    build: Any = None


TRUTH_KINDS: dict[str, TruthKind] = {
    "isotropic": TruthKind(None),
    "filament": TruthKind(FilamentSpec),
    "puffs": TruthKind(PuffsSpec),
    "playback": TruthKind(PlaybackSpec),
    "lbm": TruthKind(LbmSpec),
    "lbm3d": TruthKind(Lbm3dSpec),
    "gaden": TruthKind(GadenSpec),
}
"""The one registry of truth kinds, by the ``kind`` of ``truth.model`` (``"isotropic"`` for the
plain string): the scenario schema validates against the specs, :func:`dcee.simulation.make_truth`
builds with the factories. A new truth adds its spec class here and registers its factory in its
own module under :mod:`dcee.simulation`."""
TruthModelSpec = Annotated[
    FilamentSpec | PuffsSpec | PlaybackSpec | LbmSpec | Lbm3dSpec | GadenSpec,
    Field(discriminator="kind"),
]


MAX_SOURCES = 4
"""Most releases one truth may hold: the one at (``x``, ``y``, ``z``, ``q``) and three more."""
MIN_SOURCE_SEPARATION = 1.0
"""Closest two releases of one truth may be, m: nearer than this (half the paper's 2 m step)
no reading of the search can tell them from one release of their summed rate."""


class ExtraSource(BaseModel):
    """A further release of the truth (``[[truth.extra_sources]]``), in the same wind and the
    same truth model as the one at (``truth.x``, ``truth.y``, ``truth.z``)."""

    model_config = FROZEN
    x: Finite
    """release x, m"""
    y: Finite
    """release y, m"""
    z: Finite
    """release height, m"""
    q: Positive
    """release rate, g/s"""


class Truth(BaseModel):
    """The true source term (what the search must find) and what the sensor sees."""

    model_config = FROZEN
    x: Finite
    """source x, m"""
    y: Finite
    """source y, m"""
    z: Finite
    """source height, m"""
    q: Positive
    """release rate, g/s"""
    u: Annotated[float, Field(ge=0, allow_inf_nan=False)]
    """mean wind speed, m/s"""
    phi: Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)] = Field(
        description="wind direction in degrees, in [-360, 360], where the wind comes from, "
        "counter-clockwise from +x (east); or give wind_from"
    )
    wind_from: Annotated[float | None, Field(ge=0.0, le=360.0, allow_inf_nan=False)] = None
    """the wind direction as a meteorological (compass) bearing instead of ``phi``: degrees
    clockwise from north (+y), where the wind comes from (270 = a west wind); converted to
    ``phi`` = 90 − wind_from (:mod:`dcee.models.compass`) and not stored, so ``dcee show`` prints
    ``phi`` with the bearing beside it as a comment"""
    zeta1: Positive
    """diffusivity ζ1 of the isotropic plume model, m²/s"""
    zeta2: Positive
    """lifetime ζ2 of the released particles, s"""
    model: Literal["isotropic"] | TruthModelSpec = "isotropic"
    """what the sensor really sees: "isotropic" (the estimator's own model, the paper's
    simulation), "filament" or "puffs" (or a table with that kind and parameters: two turbulent
    truths written apart), or a table ``{file = "plume.h5"}`` to play a recording back"""
    extra_sources: tuple[ExtraSource, ...] = ()
    """further releases beside the one at (``x``, ``y``, ``z``) with rate ``q``, each its own
    position and rate, in the same wind (``[[truth.extra_sources]]``; at most
    :data:`MAX_SOURCES` releases in all, at least :data:`MIN_SOURCE_SEPARATION` m apart; not
    with a recording or the solver's plume, which hold their own releases). Empty: one source"""

    @model_validator(mode="after")
    def _releases(self) -> Truth:
        extra = self.extra_sources
        if not extra:
            return self
        if len(extra) + 1 > MAX_SOURCES:
            raise ValueError(
                f"{FIELD_MARK}truth.extra_sources: {len(extra) + 1} releases in all; at most "
                f"{MAX_SOURCES} (the one at truth.x, y, z and {MAX_SOURCES - 1} more)"
            )
        if isinstance(self.model, PlaybackSpec | LbmSpec | Lbm3dSpec | GadenSpec):
            raise ValueError(
                f"{FIELD_MARK}truth.extra_sources: a {self.model.kind} truth holds its own "
                "releases; further ones need truth.model isotropic, filament or puffs"
            )
        xyz = self.source_locations()
        for i in range(len(xyz)):
            for j in range(i):
                gap = float(np.linalg.norm(xyz[i] - xyz[j]))
                if gap < MIN_SOURCE_SEPARATION:
                    raise ValueError(
                        f"{FIELD_MARK}truth.extra_sources: releases {j} and {i} are {gap:.2g} m "
                        f"apart (0: the one at truth.x, y, z); at least "
                        f"{MIN_SOURCE_SEPARATION:g} m, or one release of their summed rate"
                    )
        return self

    def source_locations(self) -> np.ndarray:
        """(K, 3) every release's location, m: the one at (x, y, z) first."""
        rows = [(self.x, self.y, self.z), *((e.x, e.y, e.z) for e in self.extra_sources)]
        return np.array(rows, dtype=np.float64)

    def source_rates(self) -> np.ndarray:
        """(K,) every release's rate, g/s, in the order of :meth:`source_locations`."""
        return np.array([self.q, *(e.q for e in self.extra_sources)], dtype=np.float64)

    @model_validator(mode="before")
    @classmethod
    def _bearing_to_phi(cls, data: Any) -> Any:
        if not isinstance(data, dict) or data.get("wind_from") is None:
            return data
        return {**data, **phi_fields(data, "truth")}

    @field_validator("model", mode="before")
    @classmethod
    def _model_shorthand(cls, value: Any) -> Any:
        # "filament" is short for the filament table with every default, so that the resolved
        # configuration saved beside results records every parameter; {file = ...} needs no kind.
        if value in ("filament", "puffs", "lbm", "lbm3d"):
            return {"kind": value}
        if isinstance(value, dict) and "kind" not in value:
            kind = "playback" if "file" in value else "filament"
            return {"kind": kind, **value}
        if isinstance(value, str) and value != "isotropic":
            raise ValueError(
                f'must be "isotropic", "filament", "puffs", "lbm", "lbm3d" or {{file = "..."}} '
                f"(got {value!r})"
            )
        return value

    def layout(self) -> tuple[bool, float | None]:
        """(planar, plane height m or None): a planar truth holds one horizontal plane, the
        same at every altitude (a 2-D recording, whose file may say which height it holds;
        the solver plume); nothing in it can tell altitude, so the search on it is planar and
        the reading model takes the source at ``z`` (docs/scenarios.md)."""
        model = self.model
        if isinstance(model, PlaybackSpec):
            return recording_layout(model.file, model.variable, dict(model.axes))
        if isinstance(model, LbmSpec):
            return True, None
        if isinstance(model, Lbm3dSpec) and model.plane is not None:
            return True, model.plane
        return False, None

    @property
    def model_name(self) -> str:
        """ "isotropic", "filament", "puffs" or "playback:<file name>" (for tables and
        reports)."""
        return self.model if isinstance(self.model, str) else self.model.name
