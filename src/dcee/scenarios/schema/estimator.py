"""The ``[prior]``, ``[sensor]`` and ``[estimator]`` sections: what is believed before the search,
the instrument, and the reading model of the filter and the planners."""

from __future__ import annotations

import math
from typing import Annotated, Literal, get_args

from pydantic import BaseModel, Field, field_validator, model_validator

from dcee.models.sensor import OUTLIER_DEFAULT
from dcee.scenarios.schema.common import FROZEN, Finite, Positive
from dcee.scenarios.schema.learned_settings import LearnedName
from dcee.scenarios.schema.truth import MAX_SOURCES

PHYSICAL_TRUNCATION = {"u": 0.0, "zeta1": 0.0, "zeta2": 0.0}


class PriorSpec(BaseModel):
    """The prior of one unknown parameter (``[prior] q = { kind = "gamma", shape = 2.0,
    scale = 5.0 }``); degrees for phi. x, y, z default to uniform over the volume."""

    model_config = FROZEN
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


def default_priors() -> dict[str, PriorSpec]:
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

    model_config = FROZEN
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

OLD_OUTLIER_DEFAULT: dict[str, float] = {"paper": 0.0, "fluctuation": 0.01}
"""What an unset (null) ``estimator.outlier`` meant in a scenario stored before issue 29 (0 for
the paper's likelihood, 0.01 for the fluctuation likelihood; since then
:data:`~dcee.models.sensor.OUTLIER_DEFAULT` for every likelihood)."""


READING_WEIGHT_DEFAULT: dict[str, float] = {"paper": 1.0, "fluctuation": 0.5}
"""``estimator.reading_weight`` per likelihood when not given: 1 for the paper's model (its
readings are independent given the source term: the paper's update); 0.5 for the fluctuation
model, meant for turbulent plumes, whose successive holds are not. Chosen with
``near_source_length`` 5 m on the tuning configurations random:1-12 (both turbulent truths) and
checked on held-out random:1000-1023 with dcee-cl and infotaxis: the truth inside the 95 % region
in 29 more searches and 10 fewer of 96 paired ones (exact McNemar p = 0.003), acquisition and
final error no worse (docs/turbulent.md)."""

REGION_FLOOR_DEFAULT: dict[str, float] = {"paper": 0.0, "fluctuation": 0.25}
"""``estimator.region_floor`` (m) per likelihood when not given, in open terrain: 0 for the
paper's model (the isotropic truth's own model: no discrepancy to allow for); 0.25 m for the
fluctuation model, chosen on the tuning range random:13-40 (dcee-cl, filament + puffs, 56
searches) by the rule of docs/results/tuning-region-floor-13-40, written before its run: the
smallest floor of the grid 0-0.5 m at which the truth lies in the 95 % region in ≥ 95 % of
each truth's searches (filament 25/28 up to 0.2 m, 27/28 at 0.25 m; puffs 28/28 from 0); the
region's median RMS radius 0.33 → 0.55 m. The wall-aware plume (``plume = "walls"``), on which
no floor was chosen, keeps 0."""


def unset_region_floor(likelihood: str, plume: str = "open") -> float:
    """What an unset ``estimator.region_floor`` resolves to (:data:`REGION_FLOOR_DEFAULT`)."""
    return REGION_FLOOR_DEFAULT[likelihood] if plume == "open" else 0.0


REPEAT_DEFAULT: dict[str, tuple[float, float]] = {"paper": (0.0, 1.0), "fluctuation": (2.0, 0.5)}
"""(``repeat_radius`` m, ``repeat_power``) per likelihood when not given: off for the paper's
model (independent readings, the paper's update); for the fluctuation model a run of readings
within 2 m weighs 1 / (1 + m)^0.5 each (n readings at one spot add up like 2 √n). Chosen with
``near_source_length`` 0.5 m on the tuning range random:13-40 (dcee-cl, filament + puffs, 56
paired searches, rule written before the run; issue 42): acquisition 56/56 either way, the final
error 0.30 m smaller at the median pair (Wilcoxon p = 5e-8), the truth in the 95 % region in
95 % of searches against 96 % (bound: 2 points). Power 1/4 (2026-11-23 to 11-27, with the 2.5 m
fall) was chosen on the same range; with the 0.5 m fall it left the region too narrow
(docs/plumes.md, docs/turbulent.md)."""

MEANDER_DEFAULT: dict[str, float] = {"paper": 0.0, "fluctuation": 0.15}
"""Meander broadening per likelihood when ``estimator.meander`` is not given: none for the
paper's model; 0.15 for the fluctuation model, the crosswind turbulence intensity that fits the
filament truth's time mean best (docs/scenarios.md). The calm member of the fluctuation
likelihood (``calm_prior``) never meanders."""


class AnemometerSpec(BaseModel):
    """A measured wind (:mod:`dcee.models.anemometer`): the robot's anemometer reports the
    wind's speed and the direction it comes from every ``period`` s, and the estimator takes
    each reading as Normal(u, ``speed_sd``²) × von Mises(φ, 1/``direction_sd``²) about the
    source term's wind. The simulated instrument reads the truth's mean wind with that noise
    (no gusts, no meander: the same model the estimator assumes). Off by default (the paper's
    robot had no anemometer). The noise defaults are chosen, not measured: a 1 s mean of a
    two-axis ultrasonic anemometer outdoors, whose error is dominated by the wind's own
    fluctuation, is within about 0.5 m/s and 10° of the mean wind."""

    model_config = FROZEN
    enabled: bool = False
    """the robot carries an anemometer and the estimator uses its readings"""
    period: Annotated[float, Field(gt=0, le=3600, allow_inf_nan=False)] = 1.0
    """s between two wind readings"""
    speed_sd: Annotated[float, Field(gt=0, le=50, allow_inf_nan=False)] = 0.5
    """m/s, standard deviation of a speed reading about the true wind speed"""
    direction_sd: Annotated[float, Field(gt=0, le=180, allow_inf_nan=False)] = 10.0
    """°, standard deviation of a direction reading about the true direction"""


class EstimatorSpec(BaseModel):
    """The reading model the filter and every planner use (one :class:`Sensor` for both).

    ``likelihood = "paper"``: the paper's eq. 3 with the ``[sensor]`` parameters.
    ``likelihood = "fluctuation"``: an intermittent log-normal reading about the isotropic
    plume's time mean (Yee & Chan 1997; see :mod:`dcee.models.sensor`), with the sensor's
    threshold, ``intermittency``, ``log_sd`` and ``near_source_length`` (intermittency and
    log_sd fitted by maximum likelihood to 4 s hold averages of the filament truth, readings as
    the instrument reports them there — without random misses, ``sensor.dropout``'s default on
    a turbulent truth: ``studies/fluctuation_stats.py --hold 4 --pd 1``; the near-source length
    chosen by the searches' calibration, docs/scenarios.md).
    With ``calm_prior`` > 0 the fluctuation likelihood estimates the turbulence level online: a
    second filter runs the paper's calm model (the ``[sensor]`` parameters, no meander) on the
    same readings, with prior probability ``calm_prior``, and the planners and the estimate use
    whichever model is the more probable given the readings
    (:mod:`dcee.estimation.model_bank`); a calm plume is then searched with the paper's model,
    a turbulent one with the fluctuation model.
    """

    model_config = FROZEN
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
    near_source_length: Annotated[float, Field(ge=0, le=1000, allow_inf_nan=False)] = 0.5
    """fluctuation: m; the intermittency falls near the source as 1 − exp(−r / this)
    (r: sensor to hypothesised source); 0 = the same everywhere. 0.5 m, chosen with the repeat
    discount's power 1/2 on the tuning range random:13-40 (filament + puffs, dcee-cl; issue 42):
    the filter alone, on a fixed pattern of readings round each source, sits 0.72 m (filament)
    and 0.94 m (puffs) upwind with 2.5 m and +0.06 / +0.05 m with 0.5 m; the searches end 0.30 m
    closer at the median pair (p = 5e-8), the truth in the 95 % region in 95 % against 96 %.
    2.5 m (2026-11-23 to 11-27) and 5 m before it were chosen on the same truths
    (docs/plumes.md, docs/turbulent.md)"""
    magnitude: bool = True
    """fluctuation: a detection weighs by its magnitude's log-normal density (True) or only by
    its probability, whatever its size (False: detection-only readings, as Vergassola et
    al.'s infotaxis counts hits); the calm member and the paper's likelihood always use the
    magnitude. The planners predict with the magnitude either way"""
    conserve_mean: bool = True
    """fluctuation: a detection's mean is C / Pd(r), so a reading's mean, the zeros included, is
    the plume's time mean C (True; Yee & Chan 1997: the in-plume mean is the mean over the
    intermittency factor), or it is C and the reading's mean Pd(r) · C (False, before the fourth
    tuning round). True on the tuning range random:13-40 (dcee-cl, both turbulent truths, 56
    searches): final error −0.11 m at the median pair (Wilcoxon p = 0.007; puffs −0.16 m,
    p = 0.001), the along-wind bias halved on the puffs (−0.45 → −0.20 m) and turned downwind
    on the filament (−0.22 → +0.24 m), acquisition 56/56 either way, the truth in the 95 %
    region as often (86 % against 88 %) (docs/turbulent.md)"""
    decay: Annotated[float, Field(ge=0.25, le=2.0, allow_inf_nan=False)] = 1.0
    """fluctuation: the plume model's fall with distance, 1/r^decay (:mod:`dcee.models.plume`):
    1, a point source in 3-D (the paper's model); 1/2, a planar plume's far field. The paper's
    likelihood and the calm member always use 1"""
    backflow: Annotated[float, Field(ge=0.0, le=0.5, allow_inf_nan=False)] = 0.0
    """fluctuation: the share w of the time the plume model's wind blows against its mean
    direction, (1 − w) · C(φ) + w · C(φ + π) (:mod:`dcee.models.plume`): gas upwind of the
    release, as near a source in strong turbulence. 0: none (the paper's model). The paper's
    likelihood and the calm member always use 0"""
    source_radius: Annotated[float, Field(ge=0.0, le=10.0, allow_inf_nan=False)] = 0.0
    """fluctuation: m, the plume model's release spread evenly over a horizontal disc of this
    radius about the source location (:mod:`dcee.models.plume`): a pool, a vent, or a point
    release recorded on a coarse grid. 0: a point source (the paper's model). The paper's
    likelihood and the calm member always use 0"""
    vertical_ratio: Annotated[float, Field(ge=0.1, le=10.0, allow_inf_nan=False)] = 1.0
    """the plume model's vertical spread over its horizontal spread, a = √(K_z / K_h)
    (:mod:`dcee.models.plume`): 1, isotropic (the paper's model); about 0.66 in a neutral
    surface layer, where σ_w / σ_v = 1.25 / 1.9 (Panofsky & Dutton 1984). Every member of the
    bank, the calm one included"""
    ground: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = 0.0
    """the weight of the release's mirror image below the ground z = 0 in the plume model
    (:mod:`dcee.models.plume`): 1, a ground that reflects the gas (a release near the ground
    doubles its concentration there); 0, the paper's unbounded air. Every member of the bank,
    the calm one included"""
    vertical_meander: Annotated[float, Field(ge=0.0, le=2.0, allow_inf_nan=False)] = 0.0
    """fluctuation: the vertical turbulence intensity i_z = σ_w / u of the plume model's
    meander broadening (:mod:`dcee.models.plume`): the plume grows upwards by i_z · d at d m
    downwind, as a real plume's near field does. 0: none, the plume grows upwards by diffusion
    alone (the paper's model). The paper's likelihood and the calm member always use 0"""
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
    repeat_radius: Annotated[float | None, Field(ge=0, le=100, allow_inf_nan=False)] = None
    """m: a reading taken within this distance of the readings just before it (an unbroken run
    of m of them) counts as ``reading_weight`` / (1 + m)^``repeat_power``: a robot holding one
    spot sees the same puffs again, so its readings there add up more slowly than a count.
    0: off (every reading ``reading_weight``). None: the likelihood's default,
    :data:`REPEAT_DEFAULT` (0 for the paper's, 2 m for the fluctuation likelihood)"""
    repeat_power: Annotated[float | None, Field(gt=0, le=2, allow_inf_nan=False)] = None
    """the repeat discount's power p: a reading in a run of m counts as ``reading_weight`` /
    (1 + m)^p (only with ``repeat_radius`` > 0); 1: n readings at one spot add up like ln n,
    1/2: like 2 √n, 1/4: like (4/3) n^(3/4). None: the likelihood's default,
    :data:`REPEAT_DEFAULT` (1 for the paper's, 0.25 for the fluctuation likelihood)"""
    learn: dict[LearnedName, Annotated[list[float], Field(min_length=1, max_length=8)]] | None = (
        None
    )
    """fluctuation: nuisance parameters of the reading model learned during the search instead
    of fixed, each with the values to weigh, e.g. ``{meander = [0.15, 0.3, 0.5]}``: one filter
    per combination (the grid's product, at most
    :data:`~dcee.scenarios.schema.learn.LEARN_MEMBERS_MAX`) on the same
    readings, with equal prior probability among them, selected by their evidence like the calm
    member (:mod:`dcee.estimation.model_bank`); the combination of the values above is the
    preferred (first) member and must be in the grid. Empty: every value fixed. None: the
    likelihood's default, :data:`LEARN_DEFAULT` (the fluctuation likelihood weighs
    ``backflow = [0, 0.05]`` and ``source_radius = [0, 1]``); a grid given replaces it"""
    learn_prior: (
        dict[LearnedName, Annotated[list[float], Field(min_length=1, max_length=8)]] | None
    ) = None
    """fluctuation: the prior probability of each value of a learned setting, in the order of
    its ``estimator.learn`` grid (normalised), e.g. ``{source_radius = [0.9, 0.1]}``: a member
    then leads only when the readings' evidence outweighs the prior odds. A setting not named
    weighs its values equally. None: with ``estimator.learn`` unset the likelihood's default,
    :data:`LEARN_PRIOR_DEFAULT` (the fluctuation likelihood: ``{source_radius = [0.9, 0.1]}``),
    with a grid given every value equally likely. Members' priors are the products"""
    max_sources: Annotated[int, Field(ge=1, le=MAX_SOURCES)] = 1
    """the most releases the estimator considers. 1: one release (the paper's filter). K > 1:
    the number of releases is unknown, 0 … K, estimated with the releases: one filter per count
    on the same readings, selected by their evidence (:mod:`dcee.estimation.source_count`); the
    planners and the stop rule follow the least-localised release of every plausible count. Needs
    one reading model (the paper's likelihood, or the fluctuation likelihood with
    ``calm_prior = 0`` and ``learn = {}``)"""
    count_prior: Annotated[list[Annotated[float, Field(gt=0)]], Field(min_length=2)] | None = None
    """with ``max_sources`` K > 1: the prior probability of 0, 1, …, K releases (K + 1 positive
    numbers, normalised); None: every count equally likely"""
    plume: Literal["open", "walls"] | None = None
    """the dispersion model of the filter and the planners: ``open``, the paper's plume in open
    terrain (:mod:`dcee.models.plume`); ``walls``, the wall-aware planar plume that flows round
    the ``[world]``'s obstacles and the map's occupied cells (:mod:`dcee.models.site_plume`: a
    wind round the walls, ``wall_wind``, and the advection-diffusion equation solved between
    them, source-receptor fields per sensor position). ``walls`` needs a ``[world]`` with
    obstacles or a map, the wind and ζ known (``unknown = "source"``: one flow), one release,
    and none of the open plume's shape settings learned (:data:`PLUME_SHAPE_SETTINGS`). None:
    ``walls`` wherever it applies, else ``open``
    (:func:`~dcee.scenarios.schema.reading_models.unset_plume`)"""
    wall_diffusivity: Annotated[float | None, Field(gt=0, le=1000, allow_inf_nan=False)] = None
    """m²/s: the wall-aware plume's diffusivity K (``plume = "walls"``); None: the scenario's
    ζ1. The fluctuation likelihood weighs it and 3 and 10 times it
    (:data:`~dcee.scenarios.schema.learned_settings.WALL_DIFFUSIVITY_FACTORS`) unless ``learn``
    says otherwise"""
    wall_lifetime: Annotated[float | None, Field(gt=0, le=1e6, allow_inf_nan=False)] = None
    """s: the wall-aware plume's gas lifetime τ (``plume = "walls"``), the decay term C/τ; None:
    no decay, a conserved gas (not the scenario's ζ2). Chosen on the tuning sites
    ``random-site:1-20`` (lbm truth, ``dcee-cl``, rule written before the run,
    docs/results/sites-walls-tune): without decay 11/20 acquired against 9/20 with ζ2 = 8 s
    (+3 / −1, McNemar p = 0.63; median final error 1.03 m against 4.32 m)"""
    wall_wind: Literal["wake", "potential", "room"] | None = None
    """the wall-aware plume's wind round the buildings (``plume = "walls"``,
    :mod:`dcee.models.site_flow`): ``wake``, the time-mean flow of a constant-eddy-viscosity
    Navier–Stokes model (a recirculating wake in a building's lee); ``potential``, the free wind
    made mass-consistent (turned along walls, no wake); ``room``, a GADEN room's own 3-D wind
    field and occupancy grid (its wind file, as a building's CFD model gives it; the plume in
    the room's volume, :mod:`dcee.models.room_plume`; needs a GADEN truth). None: ``room`` with
    a GADEN truth, else :data:`dcee.models.site_flow.WALL_WIND_DEFAULT`"""
    wall_viscosity: Annotated[float | None, Field(gt=0, le=100, allow_inf_nan=False)] = None
    """m²/s: the eddy viscosity ν_t of the wake wind (``wall_wind = "wake"``); None:
    :data:`dcee.models.site_flow.WAKE_VISCOSITY` (1 m²/s, kept against 0.25 and 0.5 on the
    tuning sites, docs/results/sites-walls-tune/viscosity). The fluctuation likelihood weighs
    it and 0.2 times it
    (:data:`~dcee.scenarios.schema.learned_settings.WALL_VISCOSITY_FACTORS`) unless ``learn``
    says otherwise"""
    region_floor: Annotated[float | None, Field(ge=0, le=10, allow_inf_nan=False)] = None
    """m: the model-discrepancy scale σ of the reported 95 % region (``truth_in_95``): the
    posterior of the source location convolved with N(0, σ² I), the error of a reading model
    that no reading removes (a point-source model of a plume that is not one). It widens what
    the estimator reports, never what it decides: the filter, the planners and the stop rule
    read the particles. 0: the particles' own region. None: the likelihood's default,
    :func:`unset_region_floor`"""
    calm_prior: Annotated[float, Field(ge=0, lt=1)] = 0.1
    """fluctuation: prior probability that the plume is calm (the paper's model, run in a second
    filter and selected by the readings' evidence: the turbulence level estimated online); 0: the
    turbulent model alone. 0.1: choosing the fluctuation likelihood says turbulence is expected;
    measured, the calm model then still wins every isotropic search and is (almost) never
    selected on the filament truth, where 0.5 let it lead 3 % of the steps (docs/scenarios.md)"""
