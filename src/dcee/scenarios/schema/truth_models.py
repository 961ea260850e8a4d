"""The kinds of ``truth.model`` (what the sensor really sees) and their parameter tables: the
one registry of truth kinds, :data:`TRUTH_KINDS`, whose factories :mod:`dcee.simulation`
registers. :mod:`dcee.scenarios.schema.truth` holds the ``[truth]`` section that names one."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field

from dcee.scenarios.schema.common import FROZEN


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
    store_stride: Annotated[int, Field(ge=1, le=16)] = 1
    """horizontal cells stored as one block mean (vertically every cell is stored). 1, every
    cell (0.5 m): stored as 1 m blocks (2, the default until 2026-12-05) the replayed field held
    20 % of its peak 0.75 m upwind of the release and gas up to 1.75 m upwind (the block
    centred upwind averages the release ball's upwind half; the replay interpolates to the next
    centre), an upwind release that no point release has: on 17 searches of the tuning range
    (release cells 1.25 and 1.75 m, ``dcee-cl``) the estimate's error along the wind fell from
    −0.66 to −0.30 m at the median and the final RMSE from 0.73 to 0.37 m with every cell
    stored (docs/three-d.md). A recording of 0.19 GB instead of 0.05 GB"""
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
