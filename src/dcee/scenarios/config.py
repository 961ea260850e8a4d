"""Scenario configuration: validated on load into immutable objects.

A scenario is a TOML file (or a built-in, see :mod:`dcee.scenarios.builtin`)::

    name = "my-site"
    dimensions = 3                 # 3: source z unknown in "source"; 2: z known, planar search
    unknown = "source"             # "source": x, y, (z), q unknown; "full": all parameters unknown

    [volume]                       # search volume in m; the location prior is uniform over it
    low = [0.0, 0.0, 0.0]
    high = [50.0, 50.0, 5.0]

    [truth]                        # ground-truth source term (angles in degrees)
    x = 37.5
    y = 12.5
    z = 1.0
    q = 5.0                        # g/s
    u = 4.0                        # m/s
    phi = 0.0                      # deg; wind comes FROM this direction
    zeta1 = 1.0
    zeta2 = 8.0
    model = "isotropic"            # or "filament", or { file = "plume.h5" } (recorded plume)

    [prior]                        # used for unknown parameters; degrees for phi
    q = { kind = "gamma", shape = 2.0, scale = 5.0 }
    u = { kind = "normal", mean = 4.0, sd = 1.414 }
    phi = { kind = "normal", mean = 0.0, sd = 3.162 }
    zeta1 = { kind = "normal", mean = 1.0, sd = 1.414 }
    zeta2 = { kind = "normal", mean = 8.0, sd = 1.414 }

    [sensor]                       # g/m³
    threshold = 5e-4
    pd = 0.7
    sigma_min = 1e-4
    sigma_frac = 0.5
    false_alarm = 0.0
    max_reading = 1e4              # physical maximum; larger readings are refused
    dropout = 0.0                  # simulated misses [default: 1 - pd isotropic, 0 turbulent]
    average = 5.0                  # s averaged at the end of each hold [default: see SensorSpec]

    [estimator]                    # the reading model of the filter and the planners
    likelihood = "paper"           # or "fluctuation" (intermittent log-normal, for real plumes)
    intermittency = 0.93           # fluctuation only
    log_sd = 1.3                   # fluctuation only
    near_source_length = 5.0       # fluctuation only, m
    calm_prior = 0.1               # fluctuation only: prior probability of a calm plume (0: off)
    meander = 0.15                 # plume broadening [default: 0 paper, 0.15 fluctuation]
    outlier = 0.01                 # outlier weight [default: 0.01 for every likelihood]

    [agent]
    start = [2.0, 2.0, 4.0]        # m; the agent flies at the start altitude
    step = 2.0                     # m
    speed = 2.0                    # m/s
    dwell = 1.0                    # s held at each waypoint [default: 1, 5 if time-varying]

    [search]
    particles = 20000
    hypotheses = 40                # hypothesised readings per candidate move
    budget = 900.0                 # s of flight
    acquired_rmse = 3.0            # m; "source acquired" when the final RMSE is below this
    stop_spread = 0.0              # m; > 0 stops early once the posterior spread is below it
    stall_guard = 30.0             # s within one step of one spot before a move must leave it

Normal priors are truncated to physical values (u ≥ 0, ζ1 > 0, ζ2 > 0) automatically.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Annotated, Any, Literal, get_args

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from dcee.errors import DceeInputError
from dcee.estimation.priors import Distribution, Fixed, Gamma, Normal, SourcePrior, Uniform
from dcee.models.agent import GridAgent, SearchVolume
from dcee.models.motion import MotionModel, make_motion
from dcee.models.plume import PARAMETER_NAMES, IsotropicPlume
from dcee.models.sensor import Sensor

_FROZEN = ConfigDict(frozen=True, extra="forbid", use_attribute_docstrings=True)
Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]

PHYSICAL_TRUNCATION = {"u": 0.0, "zeta1": 0.0, "zeta2": 0.0}

TURBULENT_HOLD = 4.0
"""Default hold (s) at each waypoint for a time-varying truth, over which a reading averages.
On the filament truth (paper:1 centreline, 5-30 m downwind) a 5 s average cuts the share of
below-threshold readings from 66-84 % to 10-25 % and the p99/mean ratio from 14-27 to 4-5; a
longer hold gives fewer readings in the budget. Chosen by search success (infotaxis, filament
truth, full unknown, 12 × 3, 10,000 particles): hold 2 / 3 / 4 / 5 / 7 s acquired the source in
4/12 / 5/12 / 33/36 / 26/36 / 23/36 (docs/scenarios.md)."""


class Volume(BaseModel):
    """The search volume (m); the source-location prior is uniform over it."""

    model_config = _FROZEN
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

    model_config = _FROZEN
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

    model_config = _FROZEN
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


class PlaybackSpec(BaseModel):
    """A recorded or externally simulated plume played back as truth
    (:mod:`dcee.simulation.playback`)."""

    model_config = _FROZEN
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


TRUTH_KINDS = ("filament", "puffs", "playback")
TruthModelSpec = Annotated[FilamentSpec | PuffsSpec | PlaybackSpec, Field(discriminator="kind")]


class Truth(BaseModel):
    """The true source term (what the search must find) and what the sensor sees."""

    model_config = _FROZEN
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
    phi: Finite = Field(description="wind direction in degrees (wind comes from it)")
    zeta1: Positive
    """diffusivity ζ1 of the isotropic plume model, m²/s"""
    zeta2: Positive
    """lifetime ζ2 of the released particles, s"""
    model: Literal["isotropic"] | TruthModelSpec = "isotropic"
    """what the sensor really sees: "isotropic" (the estimator's own model, the paper's
    simulation), "filament" or "puffs" (or a table with that kind and parameters: two turbulent
    truths written apart), or a table ``{file = "plume.h5"}`` to play a recording back"""

    @field_validator("model", mode="before")
    @classmethod
    def _model_shorthand(cls, value: Any) -> Any:
        # "filament" is short for the filament table with every default, so that the resolved
        # configuration saved beside results records every parameter; {file = ...} needs no kind.
        if value in ("filament", "puffs"):
            return {"kind": value}
        if isinstance(value, dict) and "kind" not in value:
            kind = "playback" if "file" in value else "filament"
            return {"kind": kind, **value}
        if isinstance(value, str) and value != "isotropic":
            raise ValueError(
                f'must be "isotropic", "filament", "puffs" or {{file = "..."}} (got {value!r})'
            )
        return value

    @property
    def model_name(self) -> str:
        """ "isotropic", "filament", "puffs" or "playback:<file name>" (for tables and
        reports)."""
        return self.model if isinstance(self.model, str) else self.model.name


class PriorSpec(BaseModel):
    """The prior of one unknown parameter (``[prior] q = { kind = "gamma", shape = 2.0,
    scale = 5.0 }``); degrees for phi. x, y, z default to uniform over the volume."""

    model_config = _FROZEN
    kind: Literal["uniform", "gamma", "normal"]
    """distribution family"""
    low: float | None = None
    """uniform: lower bound (finite); normal: truncation below (default: the physical bound,
    0 for u, ζ1, ζ2)"""
    high: float | None = None
    """uniform: upper bound (finite); normal: truncation above (default none)"""
    shape: Positive | None = None
    """gamma: shape k"""
    scale: Positive | None = None
    """gamma: scale θ"""
    mean: Finite | None = None
    """normal: mean"""
    sd: Positive | None = None
    """normal: standard deviation (the paper's N(m, δ) has variance δ, so sd = √δ)"""

    @field_validator("low", "high")
    @classmethod
    def _not_nan(cls, value: float | None) -> float | None:
        if value is not None and math.isnan(value):
            raise ValueError("must be a number or ±inf, got nan")
        return value

    @model_validator(mode="after")
    def _complete(self) -> PriorSpec:
        need = {"uniform": ("low", "high"), "gamma": ("shape", "scale"), "normal": ("mean", "sd")}
        missing = [f for f in need[self.kind] if getattr(self, f) is None]
        if missing:
            raise ValueError(f"a {self.kind} prior needs {', '.join(missing)}")
        if self.kind == "uniform" and not (math.isfinite(self.low) and math.isfinite(self.high)):
            raise ValueError(
                f"a uniform prior needs finite low and high (got [{self.low}, {self.high}]): "
                "no uniform density spans an infinite range; use a normal or gamma prior"
            )
        if self.low is not None and self.high is not None and not self.high > self.low:
            raise ValueError(f"needs high > low, got [{self.low}, {self.high}]")
        return self


def _default_priors() -> dict[str, PriorSpec]:
    # The paper's table 1; N(m, δ) there has *variance* δ, so sd = √δ. The wind-direction prior
    # is centred on the truth in the paper, so it has no default: give ``prior.phi`` for "full".
    return {
        "q": PriorSpec(kind="gamma", shape=2.0, scale=5.0),
        "u": PriorSpec(kind="normal", mean=4.0, sd=math.sqrt(2.0)),
        "zeta1": PriorSpec(kind="normal", mean=1.0, sd=math.sqrt(2.0)),
        "zeta2": PriorSpec(kind="normal", mean=8.0, sd=math.sqrt(2.0)),
    }


class SensorSpec(BaseModel):
    """The instrument: what the (simulated) robot's sensor reports. The estimator's model of it
    is :class:`EstimatorSpec` (the two differ on a turbulent truth)."""

    model_config = _FROZEN
    threshold: Positive = 5e-4
    """g/m³: readings below it are non-detections"""
    pd: Annotated[float, Field(gt=0, le=1)] = 0.7
    """probability that a concentration above the threshold is detected (the paper's 0.7)"""
    sigma_min: Positive = 1e-4
    """g/m³: least standard deviation of a reading's noise"""
    sigma_frac: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.5
    """reading noise standard deviation as a share of the concentration (the paper's 0.5)"""
    false_alarm: Annotated[float, Field(ge=0, lt=1)] = 0.0
    """probability of a spurious detection where the concentration is below the threshold"""
    false_alarm_scale: Positive = 5e-4
    """g/m³: scale of the exponential distribution of false-alarm readings"""
    max_reading: Positive = 1e4
    """g/m³: physical maximum; a told reading above it is refused (a fault, not a measurement)"""
    dropout: Annotated[float | None, Field(ge=0, lt=1, allow_inf_nan=False)] = None
    """probability that the *simulated* instrument misses a reading above the threshold.
    None: 1 − ``pd`` on the isotropic truth (the paper's Pd stands for turbulent intermittency
    and missed detections together, and that truth simulates no turbulence), 0 on a time-varying
    truth (it makes the turbulence's gaps itself; an instrument's own dropout rate is not known).
    ``pd`` itself is the paper likelihood's (estimator side)."""
    average: Annotated[float | None, Field(ge=0, le=600, allow_inf_nan=False)] = None
    """s: each reading averages the truth over the last ``average`` seconds of the hold,
    sub-sampled at the truth's time step (no effect on the time-invariant isotropic truth).
    None: the whole hold (``agent.dwell``) for a time-varying truth, 0 for the isotropic one."""
    response_time: Annotated[float, Field(ge=0, le=600, allow_inf_nan=False)] = 0.0
    """s: first-order sensor response (time constant) applied before averaging; 0 = ideal"""


Likelihood = Literal["paper", "fluctuation"]
LIKELIHOODS: tuple[str, ...] = get_args(Likelihood)
"""The reading models of the filter and the planners, by name (`--likelihood`)."""

OUTLIER_DEFAULT = 0.01
"""Outlier weight ``estimator.outlier`` for every likelihood, the paper's included, so that one
reading no hypothesis can explain (a spike, a stuck or saturated sensor) never captures the
posterior. Chosen on the tuning configurations (random:1-6, dcee-cl, one 10⁶ × reading at 40,
60 or 100 s, ``scripts/spike_study.py``): weight 0 lost 14 of 18 acquired searches to the spike,
0.001 and 0.01 none; 0.01, the larger, bounds a reading's likelihood ratio 10× tighter. Set 0
for the paper's exact likelihood (docs/scenarios.md: the held-out check and the public study
with this default). Before issue 29 the default was 0 for the paper's likelihood and 0.01 for
the fluctuation likelihood (:data:`OLD_OUTLIER_DEFAULT`, for stored campaigns)."""

OLD_OUTLIER_DEFAULT: dict[str, float] = {"paper": 0.0, "fluctuation": 0.01}
"""What an unset (null) ``estimator.outlier`` meant in a scenario stored before issue 29."""


READING_WEIGHT_DEFAULT: dict[str, float] = {"paper": 1.0, "fluctuation": 0.5}
"""``estimator.reading_weight`` per likelihood when not given: 1 for the paper's model (its
readings are independent given the source term: the paper's update); 0.5 for the fluctuation
model, meant for turbulent plumes, whose successive holds are not. Chosen with
``near_source_length`` 5 m on the tuning configurations random:1-12 (both turbulent truths) and
checked on held-out random:1000-1023 with dcee-cl and infotaxis: the truth inside the 95 % region
in 29 more searches and 10 fewer of 96 paired ones (exact McNemar p = 0.003), acquisition and
final error no worse (docs/turbulent.md)."""

MEANDER_DEFAULT: dict[str, float] = {"paper": 0.0, "fluctuation": 0.15}
"""Meander broadening per likelihood when ``estimator.meander`` is not given: none for the
paper's model; 0.15 for the fluctuation model, the crosswind turbulence intensity that fits the
filament truth's time mean best (docs/scenarios.md). The calm member of the fluctuation
likelihood (``calm_prior``) never meanders."""


class EstimatorSpec(BaseModel):
    """The reading model the filter and every planner use (one :class:`Sensor` for both).

    ``likelihood = "paper"``: the paper's eq. 3 with the ``[sensor]`` parameters.
    ``likelihood = "fluctuation"``: an intermittent log-normal reading about the isotropic
    plume's time mean (Yee & Chan 1997; see :mod:`dcee.models.sensor`), with the sensor's
    threshold, ``intermittency``, ``log_sd`` and ``near_source_length`` (intermittency and
    log_sd fitted by maximum likelihood to 4 s hold averages of the filament truth, readings as
    the instrument reports them there — without random misses, ``sensor.dropout``'s default on
    a turbulent truth: ``scripts/fluctuation_stats.py --hold 4 --pd 1``; the near-source length
    chosen by the searches' calibration, docs/scenarios.md).
    With ``calm_prior`` > 0 the fluctuation likelihood estimates the turbulence level online: a
    second filter runs the paper's calm model (the ``[sensor]`` parameters, no meander) on the
    same readings, with prior probability ``calm_prior``, and the planners and the estimate use
    whichever model is the more probable given the readings
    (:mod:`dcee.estimation.model_bank`); a calm plume is then searched with the paper's model,
    a turbulent one with the fluctuation model.
    """

    model_config = _FROZEN
    likelihood: Likelihood = "paper"
    intermittency: Annotated[float, Field(gt=0, le=1)] = 0.93
    """fluctuation: probability that a reading well inside the plume is not zero"""
    log_sd: Annotated[float, Field(gt=0, le=5)] = 1.3
    """fluctuation: standard deviation s of ln(reading) about ln(mean) − s²/2 (far from the
    source when ``log_sd_length`` > 0)"""
    log_sd_near: Annotated[float, Field(ge=0, le=10)] = 0.0
    """fluctuation: the extra spread at the source, s(r) = log_sd + log_sd_near ·
    exp(−r / log_sd_length) (r: sensor to hypothesised source)"""
    log_sd_length: Annotated[float, Field(ge=0, le=1000, allow_inf_nan=False)] = 0.0
    """fluctuation: m; how fast the extra spread decays with distance; 0 = s the same
    everywhere"""
    near_source_length: Annotated[float, Field(ge=0, le=1000, allow_inf_nan=False)] = 5.0
    """fluctuation: m; the intermittency falls near the source as 1 − exp(−r / this)
    (r: sensor to hypothesised source); 0 = the same everywhere. 5 m (the maximum-likelihood fit
    at fixed points gave 5.4 m), chosen with ``reading_weight`` 0.5 on the tuning configurations
    random:1-12 and checked on held-out ones (docs/turbulent.md); 10 m, the value before, set the
    final estimate about 1 m upwind of the source there"""
    meander: Annotated[float | None, Field(ge=0, le=2)] = None
    """crosswind turbulence intensity of the plume model's time-mean meander broadening
    (:mod:`dcee.models.plume`); None: the likelihood's default, :data:`MEANDER_DEFAULT`"""
    outlier: Annotated[float, Field(ge=0, lt=1)] = OUTLIER_DEFAULT
    """weight of the outlier component (log-uniform up to sensor.max_reading), every likelihood:
    a reading no hypothesis explains then weighs at most ~13 / outlier against any other
    (:data:`OUTLIER_DEFAULT`); 0 = the paper's exact likelihood"""
    reading_weight: Annotated[float | None, Field(gt=0, le=1)] = None
    """how many independent readings one reading counts as in the filter: its log-likelihood
    is multiplied by this (a power likelihood). Below 1 for readings that are not independent
    (a turbulent plume's successive holds see the same puffs and gusts), so the posterior is not
    narrower than the evidence; the planners still predict with the plain likelihood. 1: the
    plain Bayes update. None: the likelihood's default, :data:`READING_WEIGHT_DEFAULT`"""
    calm_prior: Annotated[float, Field(ge=0, lt=1)] = 0.1
    """fluctuation: prior probability that the plume is calm (the paper's model, run in a second
    filter and selected by the readings' evidence: the turbulence level estimated online); 0: the
    turbulent model alone. 0.1: choosing the fluctuation likelihood says turbulence is expected;
    measured, the calm model then still wins every isotropic search and is (almost) never
    selected on the filament truth, where 0.5 let it lead 3 % of the steps (docs/scenarios.md)"""


def team_starts(
    start: np.ndarray, step: float, count: int, low: np.ndarray, high: np.ndarray
) -> np.ndarray | None:
    """(count, 3) start positions: robot k at ``start`` + k · step along +y, or along −y where
    the row would leave [low, high]; None when neither fits."""
    for sign in (1.0, -1.0):
        rows = np.repeat(np.asarray(start, dtype=np.float64)[None, :], count, axis=0)
        rows[:, 1] += sign * step * np.arange(count)
        if np.all(rows >= low - 1e-9) and np.all(rows <= high + 1e-9):
            return rows
    return None


class UnicycleSpec(BaseModel):
    """The differential-drive robot of ``agent.model = "unicycle"`` (:mod:`dcee.models.motion`).
    Its top speed is ``agent.speed``. Defaults: a Turtlebot-2-class robot as Nav2 drives it
    (0.5 m/s² and 60°/s, 180°/s²); a 0.3 m move then takes 1.9-4.4 s depending on the heading
    change, against 1.5 s for the grid agent at 0.2 m/s."""

    model_config = _FROZEN
    max_accel: Positive = 0.5
    """m/s², forward acceleration and braking"""
    max_turn_rate: Annotated[float, Field(gt=0, le=720, allow_inf_nan=False)] = 60.0
    """°/s"""
    max_turn_accel: Annotated[float, Field(gt=0, le=7200, allow_inf_nan=False)] = 180.0
    """°/s²"""
    lookahead: Positive = 0.15
    """m, pure-pursuit look-ahead along the segment to the waypoint"""
    turn_in_place: Annotated[float, Field(gt=0, le=180, allow_inf_nan=False)] = 45.0
    """°: a waypoint further off the heading is first faced by turning on the spot"""
    goal_tolerance: Positive = 0.02
    """m: settled within this distance of the waypoint (and nearly still)"""
    control_dt: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.05
    """s, control and integration period"""


class AgentSpec(BaseModel):
    """The mobile sensor: where it starts and how it moves (one step along one of
    ``headings`` directions per decision, at the start altitude)."""

    model_config = _FROZEN
    start: tuple[Finite, Finite, Finite]
    """start position (x, y, z), m; inside the volume"""
    step: Positive = 2.0
    """m per move; at least one heading from the start must stay inside the volume"""
    speed: Positive = 2.0
    """m/s; a move takes step / speed + dwell seconds"""
    dwell: Annotated[float | None, Field(ge=0, le=600, allow_inf_nan=False)] = None
    """s held at each waypoint to take a reading; None: 1 s for the isotropic truth,
    :data:`TURBULENT_HOLD` for a time-varying one"""
    headings: Annotated[int, Field(ge=1, le=64)] = 8
    """number of equally spaced move directions (0°, 45°, … for 8)"""
    count: Annotated[int, Field(ge=1, le=16)] = 1
    """robots searching together with one shared belief; robot k starts k · step metres from
    ``start`` along +y (along −y where +y would leave the area)"""
    model: Literal["grid", "unicycle"] = "grid"
    """how the robot drives to a waypoint (:mod:`dcee.models.motion`): "grid", every move takes
    step / speed s and ends on the waypoint (the paper's); "unicycle", a differential-drive
    robot with the limits of [agent.unicycle], so the time per move comes from its dynamics"""
    unicycle: UnicycleSpec = UnicycleSpec()
    """the unicycle robot's limits and path follower, see [agent.unicycle]"""
    heading: Finite = 0.0
    """start heading, ° counter-clockwise from +x"""
    localisation_sd: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.0
    """m: standard deviation of the localisation error (per axis, horizontal) on the position
    told to the estimator with every reading; the reading itself is taken at the true position"""


class SearchSpec(BaseModel):
    """The estimator's and planners' scale, the flight budget and the success criterion."""

    model_config = _FROZEN
    particles: Annotated[int, Field(ge=2, le=10_000_000)] = 20_000
    """particles of the filter (the paper's 20,000)"""
    hypotheses: Annotated[int, Field(ge=1, le=10_000)] = 40
    """hypothesised readings per candidate move (the paper's 40); a planner spec's own
    ``hypotheses=`` overrides it"""
    budget: Positive = 900.0
    """s of flight (the paper's 900)"""
    acquired_rmse: Positive = 3.0
    """m: "source acquired" when the final RMSE is below it"""
    stop_spread: Annotated[float, Field(ge=0, allow_inf_nan=False)] = 0.0
    """m: > 0 stops the search once the posterior spread is below it"""
    stall_guard: Annotated[float, Field(ge=0, le=1e6, allow_inf_nan=False)] = 30.0
    """s: after this long within one step of one position while the posterior spread exceeds
    ``acquired_rmse``, the next move must leave that position (0: off; docs/held-out.md)"""
    resample_threshold: Annotated[float, Field(gt=0, le=1)] = 0.5
    """resample when the effective sample size falls below this share of the particles"""
    mcmc_steps: Annotated[int, Field(ge=0, le=100)] = 1
    """least Metropolis-Hastings sweeps after a resampling"""
    global_share: Annotated[float, Field(ge=0, le=1)] = 0.2
    """share of particles proposing a source location from the prior in each sweep (keeps
    separated modes alive; 0 = random walk only)"""
    diversify: Annotated[float, Field(ge=0, le=1)] = 0.5
    """sweep until this share of the particles has moved since the resampling"""
    max_sweeps: Annotated[int, Field(ge=1, le=100)] = 8
    """most sweeps after one resampling"""


class Scenario(BaseModel):
    """A validated, immutable scenario."""

    model_config = _FROZEN
    name: str = "custom"
    """shown in results; a file's name defaults to its stem"""
    description: str = ""
    """free text"""
    dimensions: Literal[2, 3] = 3
    """3: the source height is unknown in "source"; 2: it is known (planar search)"""
    unknown: Literal["source", "full"] = "source"
    """"source": x, y, (z), q unknown; "full": wind and dispersion (u, phi, zeta1, zeta2) too"""
    volume: Volume
    """the search volume, see [volume]"""
    truth: Truth
    """the true source term and the truth model, see [truth]"""
    prior: dict[str, PriorSpec] = Field(default_factory=_default_priors)
    """priors of the unknown parameters by name (q, u, phi, zeta1, zeta2; x, y, z uniform over
    the volume unless given); defaults: the paper's table 1 (phi has none)"""
    sensor: SensorSpec = SensorSpec()
    """the instrument, see [sensor]"""
    estimator: EstimatorSpec = EstimatorSpec()
    """the reading model of the filter and the planners, see [estimator]"""
    agent: AgentSpec
    """the mobile sensor, see [agent]"""
    search: SearchSpec = SearchSpec()
    """scale, budget and success criterion, see [search]"""

    @model_validator(mode="after")
    def _consistent(self) -> Scenario:
        lo, hi = np.array(self.volume.low), np.array(self.volume.high)
        src = np.array([self.truth.x, self.truth.y, self.truth.z])
        if np.any(src < lo) or np.any(src > hi):
            raise ValueError(
                f"truth: source ({src[0]}, {src[1]}, {src[2]}) is outside the search volume "
                f"{tuple(self.volume.low)}..{tuple(self.volume.high)}"
            )
        start = np.array(self.agent.start)
        if np.any(start < lo) or np.any(start > hi):
            raise ValueError(
                f"{FIELD_MARK}agent.start: {tuple(self.agent.start)} is outside the search volume"
            )
        if self.dimensions == 3 and not hi[2] > lo[2]:
            raise ValueError("volume: a 3-D scenario needs high z > low z")
        for k in (0, 1):
            if not hi[k] > lo[k]:
                raise ValueError(f"volume: high[{k}] must be > low[{k}]")
        unknown_env = ("q",) if self.unknown == "source" else ("q", "u", "phi", "zeta1", "zeta2")
        missing = [p for p in unknown_env if p not in self.prior]
        if missing:
            raise ValueError(f"prior: missing a prior for unknown parameter(s) {missing}")
        extra = [p for p in self.prior if p not in PARAMETER_NAMES]
        if extra:
            raise ValueError(f"prior: unknown parameter name(s) {extra}; allowed {PARAMETER_NAMES}")
        agent = GridAgent(
            SearchVolume(tuple(lo), tuple(hi)),
            self.agent.step,
            self.agent.speed,
            self.dwell,
            self.agent.headings,
        )
        starts = team_starts(start, self.agent.step, self.agent.count, lo, hi)
        if starts is None:
            raise ValueError(
                f"{FIELD_MARK}agent.count: {self.agent.count} robots {self.agent.step:g} m apart "
                f"along y from agent.start {tuple(self.agent.start)} do not fit in the area"
            )
        if len(agent.candidates(start)[0]) == 0:
            raise ValueError(
                f"{FIELD_MARK}agent.step: {self.agent.step:g} m leaves the search area from "
                f"agent.start {tuple(self.agent.start)} in every heading (the area is "
                f"{hi[0] - lo[0]:g} m × {hi[1] - lo[1]:g} m); use a shorter step"
            )
        if self.search.budget < self.agent.step / self.agent.speed + self.dwell:
            raise ValueError(
                f"{FIELD_MARK}search.budget: {self.search.budget:g} s is shorter than one move "
                f"({self.agent.step / self.agent.speed + self.dwell:g} s: step / speed + dwell)"
            )
        if self.sensor.average is not None and self.sensor.average > self.dwell + 1e-9:
            raise ValueError(
                f"sensor.average = {self.sensor.average:g} s is longer than the hold "
                f"agent.dwell = {self.dwell:g} s (a reading averages while the robot holds)"
            )
        if self.sensor.max_reading <= self.sensor.threshold:
            raise ValueError("sensor.max_reading must be above sensor.threshold")
        return self

    # --- settings that depend on the truth ----------------------------------------------------

    @property
    def time_varying_truth(self) -> bool:
        return self.truth.model != "isotropic"

    @property
    def dwell(self) -> float:
        """Hold at each waypoint, s (``agent.dwell``, or its default for the truth)."""
        if self.agent.dwell is not None:
            return self.agent.dwell
        return TURBULENT_HOLD if self.time_varying_truth else 1.0

    @property
    def average(self) -> float:
        """Seconds each reading averages (``sensor.average``, or its default for the truth)."""
        if self.sensor.average is not None:
            return self.sensor.average
        return self.dwell if self.time_varying_truth else 0.0

    @property
    def instrument_pd(self) -> float:
        """P(the simulated instrument reports a concentration above the threshold): 1 −
        ``sensor.dropout``, or its default for the truth (see :class:`SensorSpec`)."""
        if self.sensor.dropout is not None:
            return 1.0 - self.sensor.dropout
        return 1.0 if self.time_varying_truth else self.sensor.pd

    @property
    def meander(self) -> float:
        e = self.estimator
        return e.meander if e.meander is not None else MEANDER_DEFAULT[e.likelihood]

    @property
    def outlier(self) -> float:
        return self.estimator.outlier

    @property
    def reading_weight(self) -> float:
        e = self.estimator
        return (
            e.reading_weight
            if e.reading_weight is not None
            else READING_WEIGHT_DEFAULT[e.likelihood]
        )

    def resolved_settings(self) -> dict[str, Any]:
        """The defaults resolved for this truth (stored with every result)."""
        return {
            "dwell": self.dwell,
            "average": self.average,
            "dropout": round(1.0 - self.instrument_pd, 12),
            "likelihood": self.estimator.likelihood,
            "reading_models": "+".join(self.reading_models),
            "outlier": self.outlier,
            "meander": self.meander,
            "reading_weight": self.reading_weight,
        }

    # --- conversion to model objects ----------------------------------------------------------

    def search_volume(self) -> SearchVolume:
        return SearchVolume(tuple(self.volume.low), tuple(self.volume.high))

    def make_sensor(self) -> Sensor:
        """The instrument that produces the (simulated) real readings: the ``[sensor]``
        parameters with its detection probability :attr:`instrument_pd`."""
        return dataclasses.replace(self._paper_sensor(), pd=self.instrument_pd)

    def _paper_sensor(self) -> Sensor:
        """The paper's eq. 3 with the ``[sensor]`` parameters (its Pd included)."""
        return Sensor(**self.sensor.model_dump(exclude={"average", "response_time", "dropout"}))

    @property
    def reading_models(self) -> tuple[str, ...]:
        """The reading models the filter runs, the preferred first: ``("paper",)``,
        ``("fluctuation",)``, or with ``estimator.calm_prior`` > 0 ``("fluctuation", "paper")``."""
        e = self.estimator
        if e.likelihood == "fluctuation" and e.calm_prior > 0:
            return ("fluctuation", "paper")
        return (e.likelihood,)

    @property
    def reading_model_priors(self) -> tuple[float, ...]:
        """Prior probability of each of :attr:`reading_models`."""
        if len(self.reading_models) == 1:
            return (1.0,)
        return (1.0 - self.estimator.calm_prior, self.estimator.calm_prior)

    def make_estimator_sensor(self, model: str | None = None) -> Sensor:
        """The reading model ``model`` (one of :attr:`reading_models`; None: the first) of the
        filter and the planners (``[estimator]``)."""
        s, e = self.sensor, self.estimator
        model = self._reading_model(model)
        if model == "paper":
            return dataclasses.replace(self._paper_sensor(), outlier=self.outlier)
        return Sensor(
            threshold=s.threshold,
            pd=e.intermittency,
            family="lognormal",
            log_sd=e.log_sd,
            log_sd_near=e.log_sd_near,
            log_sd_length=e.log_sd_length,
            near_length=e.near_source_length,
            outlier=self.outlier,
            max_reading=s.max_reading,
        )

    def make_plume(self, model: str | None = None) -> IsotropicPlume:
        """The dispersion model of the filter and the planners under reading model ``model``
        (None: the first of :attr:`reading_models`)."""
        model = self._reading_model(model)
        if self.estimator.likelihood != model:  # the fluctuation likelihood's calm member
            return IsotropicPlume(meander=0.0)
        return IsotropicPlume(meander=self.meander)

    def _reading_model(self, model: str | None) -> str:
        if model is None:
            return self.reading_models[0]
        if model not in self.reading_models:
            raise DceeInputError("model", f"must be one of {', '.join(self.reading_models)}")
        return model

    def starts(self) -> np.ndarray:
        """(count, 3) start positions of the robots, m (row 0 is ``agent.start``)."""
        lo, hi = np.array(self.volume.low), np.array(self.volume.high)
        a = self.agent
        out = team_starts(np.array(a.start, dtype=np.float64), a.step, a.count, lo, hi)
        assert out is not None  # checked at validation
        return out

    def make_agent(self) -> GridAgent:
        """The planner's move set."""
        a = self.agent
        return GridAgent(self.search_volume(), a.step, a.speed, self.dwell, a.headings)

    def make_motion(self) -> MotionModel:
        """How the robots drive to the planner's waypoints (``agent.model``)."""
        a = self.agent
        if a.model == "grid":
            return make_motion("grid", step=a.step, speed=a.speed)
        u = a.unicycle
        return make_motion(
            "unicycle",
            max_speed=a.speed,
            max_accel=u.max_accel,
            max_turn_rate=math.radians(u.max_turn_rate),
            max_turn_accel=math.radians(u.max_turn_accel),
            lookahead=u.lookahead,
            turn_in_place=math.radians(u.turn_in_place),
            goal_tolerance=u.goal_tolerance,
            control_dt=u.control_dt,
        )

    def truth_theta(self) -> np.ndarray:
        """(8,) true source term (φ in radians)."""
        t = self.truth
        return np.array([t.x, t.y, t.z, t.q, t.u, math.radians(t.phi), t.zeta1, t.zeta2])

    @property
    def unknown_names(self) -> tuple[str, ...]:
        loc = ("x", "y", "z") if self.dimensions == 3 else ("x", "y")
        env = ("q",) if self.unknown == "source" else ("q", "u", "phi", "zeta1", "zeta2")
        return loc + env

    def make_prior(self) -> SourcePrior:
        truth = self.truth_theta()
        dists: dict[str, Distribution] = {}
        for k, name in enumerate(PARAMETER_NAMES):
            if name not in self.unknown_names:
                dists[name] = Fixed(float(truth[k]))
            elif k < 3 and name not in self.prior:
                dists[name] = Uniform(self.volume.low[k], self.volume.high[k])
            else:
                dists[name] = _distribution(name, self.prior[name])
        return SourcePrior.from_dict(dists)

    def with_overrides(self, **changes: Any) -> Scenario:
        """A re-validated copy; keys are dotted paths, e.g. ``{"search.particles": 2000}``."""
        scenario = self
        for path, value in changes.items():
            if value is None:
                continue
            # one at a time, so that a later path may go into what an earlier one set
            # (e.g. truth.model = "filament", then truth.model.meander_intensity)
            data = scenario.model_dump()
            node = data
            *parents, leaf = path.split(".")
            for p in parents:
                if not isinstance(node.get(p), dict):
                    raise DceeInputError(path, f"no such setting ({p!r} is not a section)")
                node = node[p]
            node[leaf] = value
            scenario = validate_scenario(data)
        return scenario


def _distribution(name: str, spec: PriorSpec) -> Distribution:
    to_rad = math.radians if name == "phi" else (lambda v: v)
    if spec.kind == "uniform":
        return Uniform(to_rad(spec.low), to_rad(spec.high))
    if spec.kind == "gamma":
        return Gamma(spec.shape, spec.scale)
    low = spec.low if spec.low is not None else PHYSICAL_TRUNCATION.get(name, -math.inf)
    high = spec.high if spec.high is not None else math.inf
    return Normal(to_rad(spec.mean), to_rad(spec.sd), to_rad(low), to_rad(high))


def truth_choice(value: str) -> str | dict[str, str]:
    """The ``truth.model`` a ``--truth`` option names: "isotropic", "filament", or the path of a
    recording (``.npy``/``.h5``), made absolute so that it means the same file wherever the
    configuration is used later."""
    if value in ("isotropic", "filament", "puffs"):
        return value
    path = Path(value).expanduser()
    if path.suffix.lower() not in (".npy", ".h5", ".hdf5", ".nc", ".nc4", ".netcdf", ".cdf"):
        raise DceeInputError(
            "truth",
            f"must be isotropic, filament, puffs or a .npy/.h5/.nc recording (got {value!r})",
        )
    if not path.is_file():
        raise DceeInputError("truth", f"no such recording {value!r}")
    return {"file": str(path.resolve())}


def parse_setting(text: str) -> tuple[str, Any]:
    """``"estimator.log_sd=0.8"`` → ("estimator.log_sd", 0.8): a dotted scenario path and a
    TOML value (a bare word that is not TOML is taken as a string)."""
    import tomllib

    path, sep, raw = text.partition("=")
    path = path.strip()
    if not sep or not path or any(not part for part in path.split(".")):
        raise DceeInputError("set", f"must look like section.field=value, got {text!r}")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return path, value


FIELD_MARK = "@field "
"""Prefix of a cross-field check's message that names the field at fault (``@field
agent.step: …``): :func:`validate_scenario` reports that field instead of the model's."""


def validate_scenario(data: dict[str, Any]) -> Scenario:
    """Validate a raw mapping; errors become one-line :class:`DceeInputError`."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        errors = exc.errors()
        # a union (truth.model) reports every branch; the literal branch's complaint is noise
        # when a table was given, so report the error of the branch the input was meant for
        relevant = [e for e in errors if not any(str(p).startswith("literal[") for p in e["loc"])]
        err = (relevant or errors)[0]
        # drop pydantic's internal union labels ("tagged-union[...]"), keep the user's field path
        parts = [str(p) for p in err["loc"] if "[" not in str(p)]
        if len(parts) > 2 and parts[:2] == ["truth", "model"] and parts[2] in TRUTH_KINDS:
            del parts[2]  # the union's tag, not a field the user wrote
        loc = ".".join(parts) or "scenario"
        msg = err["msg"].removeprefix("Value error, ")
        if msg.startswith(FIELD_MARK):  # a cross-field check that names its own field
            loc, _, msg = msg.removeprefix(FIELD_MARK).partition(": ")
        if err["type"] == "extra_forbidden":
            msg = "unknown field"
        elif "input" in err and err["type"] != "value_error":
            msg = f"{msg} (got {err['input']!r})"
        raise DceeInputError(loc, msg) from None


def to_toml(scenario: Scenario) -> str:
    """The scenario as a TOML file that :func:`dcee.scenarios.load_scenario` reads back to an
    equal scenario (``dcee show NAME --format toml > my.toml``): every resolved setting, so the
    file is a complete record; optional values left unset (None), whose default depends on the
    truth or the likelihood, appear as comments with the value they resolve to."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    # settings left unset follow the truth or the likelihood: shown as comments with the value
    # this scenario resolves them to, so the file reads back with them still unset
    resolved = {
        ("sensor", "dropout"): round(1.0 - scenario.instrument_pd, 12),
        ("sensor", "average"): scenario.average,
        ("estimator", "meander"): scenario.meander,
        ("estimator", "reading_weight"): scenario.reading_weight,
        ("agent", "dwell"): scenario.dwell,
    }
    lines = [f"# dcee scenario {scenario.name}"]
    tables = []
    for key, value in data.items():
        if isinstance(value, dict):
            tables.append((key, value))
        else:
            lines.append(f"{key} = {_toml_value(value)}")
    for key, table in tables:
        lines.append("")
        lines.append(f"[{key}]")
        for k, v in table.items():
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
        for (section, k), v in resolved.items():
            if section == key and k not in table:
                lines.append(f"# {k} = {_toml_value(v)}  (unset: the default for this scenario)")
    return "\n".join(lines) + "\n"


def _toml_key(key: str) -> str:
    return key if key.replace("_", "").replace("-", "").isalnum() else json.dumps(key)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a JSON string is a TOML basic string
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        inner = ", ".join(
            f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items() if v is not None
        )
        return "{ " + inner + " }" if inner else "{}"
    raise TypeError(f"cannot write {type(value).__name__} as TOML")
