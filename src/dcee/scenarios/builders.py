"""How a scenario becomes the objects a search runs: the instrument, the estimator's reading
models and plume model, the prior, the move set and the motion model. :class:`ScenarioBuilders`
gives :class:`~dcee.scenarios.Scenario` these ``make_*`` methods; the schema itself only
validates."""

from __future__ import annotations

import dataclasses
import functools
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.estimation.priors import Distribution, Fixed, Gamma, Normal, SourcePrior, Uniform
from dcee.models.agent import GridAgent, SearchVolume
from dcee.models.anemometer import Anemometer
from dcee.models.motion import MotionModel, make_motion
from dcee.models.plume import PARAMETER_NAMES, IsotropicPlume
from dcee.models.room_plume import RoomFlow, RoomPlume, room_flow
from dcee.models.ros_map import load_ros_map
from dcee.models.sensor import Sensor
from dcee.models.site import SiteMap, compose_site
from dcee.models.site_flow import site_wind
from dcee.models.site_plume import SitePlume, site_grid
from dcee.scenarios.schema.agent import team_starts
from dcee.scenarios.schema.estimator import PHYSICAL_TRUNCATION, PriorSpec
from dcee.stopping import StopRule

if TYPE_CHECKING:
    from dcee.scenarios.schema.world import WorldSpec


@functools.lru_cache(maxsize=16)
def _site(
    low: tuple[float, float], high: tuple[float, float], world_json: str, mtime: float
) -> SiteMap:
    from dcee.scenarios.schema.world import WorldSpec, shapes_of

    world = WorldSpec.model_validate_json(world_json)
    maps = [load_ros_map(world.map)] if world.map is not None else []
    return compose_site(
        low,
        high,
        shapes_of(world.obstacles) + shapes_of(world.no_go),
        maps,
        float(world.resolution),
        world.clearance,
        name=Path(world.map).name if world.map else "world",
    )


@functools.lru_cache(maxsize=4)
def raw_map(path: str) -> SiteMap:
    """The map file as given (no clearance), read once per process."""
    return load_ros_map(path)


@functools.lru_cache(maxsize=4)
def _site_fluid(
    low: tuple[float, float],
    high: tuple[float, float],
    world_json: str,
    mtime: float,
    resolution: float,
) -> tuple[np.ndarray, tuple[float, float]]:
    """The site's air mask and its grid's origin (:func:`~dcee.models.site_plume.site_grid`)."""
    from dcee.scenarios.schema.world import WorldSpec

    world = WorldSpec.model_validate_json(world_json)
    return site_grid(low, high, resolution, lambda xy: inside_world(world, xy, no_go=False))


@functools.lru_cache(maxsize=4)
def _site_wind(
    site: tuple, u: float, phi: float, model: str, viscosity: float
) -> tuple[np.ndarray, np.ndarray]:
    """The wind round the site's walls (:mod:`dcee.models.site_flow`; ``viscosity`` m²/s, the
    wake wind's ν_t), computed once per process and shared by the models that differ only in K."""
    return site_wind(_site_fluid(*site)[0], site[-1], u, phi, model, viscosity)


@functools.lru_cache(maxsize=16)
def _wall_plume(
    site: tuple, environment: tuple[float, float, float, float], wind: tuple[str, float]
) -> SitePlume:
    """The wall-aware plume of one site (``(low, high, world_json, mtime, resolution)``), one
    (u, φ, K, ζ2) and one wind (model, eddy viscosity m²/s), built once per process and shared
    by the filter's members of that K and the planners (its receptor fields are cached in it)."""
    fluid, origin = _site_fluid(*site)
    u, phi = environment[:2]
    return SitePlume(fluid, origin, site[-1], *environment, wind=_site_wind(site, u, phi, *wind))


@functools.lru_cache(maxsize=4)
def gaden_room_flow(folder: str, start: float) -> RoomFlow:
    """The air of the GADEN room ``folder`` on the room plume's cubes
    (:func:`~dcee.models.room_plume.room_flow`): its occupancy grid and the wind state of the
    result file saved at ``start`` s, read once per process."""
    from dcee.recordings.gaden import FREE, GadenSimulation
    from dcee.recordings.gaden_files import OUTLET

    sim = GadenSimulation.open(folder)
    wind = sim.wind(sim.result(sim.iteration_at(start)).wind_index)
    occupancy = sim.occupancy
    return room_flow(occupancy == FREE, occupancy == OUTLET, wind, sim.grid.low, sim.grid.cell)


@functools.lru_cache(maxsize=8)
def _room_plume(folder: str, start: float, diffusivity: float, lifetime: float) -> RoomPlume:
    """The plume in the GADEN room ``folder``'s own wind (:func:`gaden_room_flow`) at one K
    (m²/s) and τ (s), built once per process and shared by the filter's members of that K and
    the planners."""
    return RoomPlume(gaden_room_flow(folder, start), diffusivity, lifetime)


def inside_world(world: WorldSpec, xy: np.ndarray, no_go: bool = True) -> np.ndarray:
    """(K,) bool: the (K, 2) points lie inside an obstacle of ``world`` (a
    :class:`~dcee.scenarios.schema.world.WorldSpec`; with ``no_go``, or a no-go zone) itself
    (the shapes as given) or in an occupied or unknown cell of its map file."""
    from dcee.scenarios.schema.world import shapes_of

    xy = np.atleast_2d(np.asarray(xy, dtype=float))[:, :2]
    out = np.zeros(len(xy), bool)
    zones = shapes_of(world.no_go) if no_go else []
    for shape in shapes_of(world.obstacles) + zones:
        out |= shape.contains(xy)
    if world.map is not None:
        out |= raw_map(world.map).is_blocked(xy)
    return out


class ScenarioBuilders:
    """The ``make_*`` methods of a :class:`~dcee.scenarios.Scenario` (a mixin: every attribute
    it reads is a validated scenario field or property)."""

    def resolution_map(self) -> dict[tuple[str, str], Any]:
        """{(section, key): value} for each setting whose unset (None) default follows the
        truth, the likelihood, the count or the platform: the value this scenario resolves it to
        (whether set or not; :meth:`resolved_unset` keeps the unset ones)."""
        return {
            ("sensor", "dropout"): round(1.0 - self.instrument_pd, 12),
            ("sensor", "average"): self.average,
            ("estimator", "meander"): self.meander,
            ("estimator", "learn"): self.learn,
            ("estimator", "learn_prior"): self.learn_prior,
            ("estimator", "reading_weight"): self.reading_weight,
            ("estimator", "repeat_radius"): self.repeat_radius,
            ("estimator", "repeat_power"): self.repeat_power,
            ("estimator", "region_floor"): self.region_floor,
            ("agent", "dwell"): self.dwell,
            ("agent", "climb"): self.climb,
            ("world", "resolution"): self.site_resolution,
            ("search", "lookahead"): self.lookahead,
            ("search", "explore_guard"): self.explore_guard,
            ("estimator", "plume"): self.plume_model,
            ("estimator", "wall_diffusivity"): self.wall_diffusivity,
            ("estimator", "wall_wind"): self.wall_wind,
            ("estimator", "wall_viscosity"): self.wall_viscosity,
        }

    def unread_settings(self) -> dict[tuple[str, str], str]:
        """{(section, key): why}: the estimator's wall settings this scenario's reading model
        does not read (``dcee show`` says so instead of their provenance): the wall ones
        without the wall-aware plume, the wake wind's viscosity with another wind."""
        if self.plume_model != "walls":
            why = f'estimator.plume = "{self.plume_model}"'
            return {
                ("estimator", k): why for k in ("wall_diffusivity", "wall_wind", "wall_viscosity")
            }
        if self.wall_wind != "wake":
            return {("estimator", "wall_viscosity"): f'estimator.wall_wind = "{self.wall_wind}"'}
        return {}

    def resolved_unset(self) -> dict[str, Any]:
        """{"section.key": value}: each setting of :meth:`resolution_map` left unset, as the
        value it resolves to today. A campaign records it beside its scenarios, so that a later
        change of such a default is refused on resume instead of mixing the searches flown
        under the old and the new value (:func:`dcee.runs.identity.settings_identity`)."""
        dump = self.model_dump(mode="json")
        return {
            f"{section}.{key}": value
            for (section, key), value in self.resolution_map().items()
            if dump.get(section, {}).get(key) is None
        }

    def search_volume(self) -> SearchVolume:
        """The volume the agent may move in: the area, its floor raised to
        ``agent.min_altitude`` where that is set (the releases' prior keeps the whole area)."""
        low = list(self.volume.low)
        if self.agent.min_altitude is not None:
            low[2] = max(low[2], float(self.agent.min_altitude))
        return SearchVolume(tuple(low), tuple(self.volume.high))

    def make_sensor(self) -> Sensor:
        """The instrument that produces the (simulated) real readings: the ``[sensor]``
        parameters with its detection probability :attr:`instrument_pd`, never a spike of its
        own (spikes are injected on purpose: :class:`dcee.simulation.InjectedTruth`)."""
        return dataclasses.replace(self._paper_sensor(), pd=self.instrument_pd)

    def _paper_sensor(self) -> Sensor:
        """The paper's eq. 3 exactly with the ``[sensor]`` parameters (its Pd included)."""
        return Sensor.paper_exact(
            **self.sensor.model_dump(exclude={"average", "response_time", "dropout"})
        )

    def make_estimator_sensor(self, model: str | None = None) -> Sensor:
        """The reading model ``model`` (one of :attr:`reading_models`; None: the first) of the
        filter and the planners (``[estimator]``)."""
        s, e = self.sensor, self.estimator
        model = self._reading_model(model)
        if model == "paper":
            return dataclasses.replace(self._paper_sensor(), outlier=self.outlier)
        learned = dict(self.reading_model_variants)[model]
        return Sensor(
            threshold=s.threshold,
            pd=learned.get("intermittency", e.intermittency),
            family="lognormal",
            log_sd=learned.get("log_sd", e.log_sd),
            log_sd_near=learned.get("log_sd_near", e.log_sd_near),
            log_sd_length=e.log_sd_length,
            near_length=learned.get("near_source_length", e.near_source_length),
            magnitude=e.magnitude,
            conserve_mean=e.conserve_mean,
            outlier=self.outlier,
            max_reading=s.max_reading,
        )

    def make_plume(self, model: str | None = None) -> IsotropicPlume | SitePlume | RoomPlume:
        """The dispersion model of the filter and the planners under reading model ``model``
        (None: the first of :attr:`reading_models`): with ``estimator.plume = "walls"`` the
        site's wall-aware plume at the member's diffusivity (members of one diffusivity share
        it: it has no open-plume shape setting to learn); in a GADEN room with ``wall_wind =
        "room"`` the plume in the room's own wind field (:mod:`dcee.models.room_plume`)."""
        model = self._reading_model(model)
        if self.plume_model == "walls":
            u, phi = (float(v) for v in self.truth_theta()[4:6])
            lifetime = self.estimator.wall_lifetime
            zeta2 = math.inf if lifetime is None else float(lifetime)
            learned = dict(self.reading_model_variants).get(model, {})
            k = float(learned.get("wall_diffusivity", self.wall_diffusivity))
            if self.wall_wind == "room":
                spec = self.truth.model
                return _room_plume(str(spec.folder), float(spec.start), k, zeta2)
            mtime = Path(self.world.map).stat().st_mtime if self.world.map is not None else 0.0
            site = (
                tuple(self.volume.low[:2]),
                tuple(self.volume.high[:2]),
                self.world.model_dump_json(),
                mtime,
                float(self.site_resolution),
            )
            nu = float(learned.get("wall_viscosity", self.wall_viscosity))
            return _wall_plume(site, (u, phi, k, zeta2), (self.wall_wind, nu))
        e = self.estimator
        learned = dict(self.reading_model_variants).get(model, {})
        # the ground and the vertical spread are the air's, not a member's shape: every member
        world = {
            "vertical": learned.get("vertical_ratio", e.vertical_ratio),
            "ground": learned.get("ground", e.ground),
        }
        if e.likelihood == "paper":
            return IsotropicPlume(meander=self.meander, **world)
        if model == "paper":
            return IsotropicPlume(meander=0.0, **world)  # the fluctuation likelihood's calm member
        return IsotropicPlume(
            meander=learned.get("meander", self.meander),
            decay=learned.get("decay", e.decay),
            backflow=learned.get("backflow", e.backflow),
            radius=learned.get("source_radius", e.source_radius),
            meander_z=learned.get("vertical_meander", e.vertical_meander),
            **world,
        )

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

    def make_agent(self, on_robot: bool = False) -> GridAgent:
        """The planner's move set (clear of the ``[world]``'s obstacles and no-go zones;
        ``on_robot``: at one altitude unless ``agent.climb`` is set, :meth:`resolved_climb`)."""
        a = self.agent
        return GridAgent(
            self.search_volume(),
            a.step,
            a.speed,
            self.dwell,
            a.headings,
            site=self.make_site(),
            climb=self.resolved_climb(on_robot),
        )

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
        """(8,) true source term (φ in radians): of the release at (truth.x, y, z)."""
        t = self.truth
        return np.array([t.x, t.y, t.z, t.q, t.u, math.radians(t.phi), t.zeta1, t.zeta2])

    def truth_thetas(self) -> np.ndarray:
        """(K, 8) the source term of every release (``truth.extra_sources`` after the first):
        its own location and rate, the wind and dispersion shared."""
        out = np.tile(self.truth_theta(), (1 + len(self.truth.extra_sources), 1))
        out[:, :3] = self.truth.source_locations()
        out[:, 3] = self.truth.source_rates()
        return out

    def make_anemometer(self) -> Anemometer | None:
        """The ``[anemometer]``'s reading model, or None when the robot has none."""
        a = self.anemometer
        if not a.enabled:
            return None
        return Anemometer(a.speed_sd, math.radians(a.direction_sd))

    def make_site(self) -> SiteMap | None:
        """The ``[world]`` section's obstacles, no-go zones and map as one
        :class:`~dcee.models.site.SiteMap` over the search area (None when the section is
        empty: open terrain, and every search exactly as without it). Built once per distinct
        world and area and shared (its path fields are cached inside it)."""
        if self.world.empty:
            return None
        mtime = 0.0
        if self.world.map is not None:
            try:
                mtime = Path(self.world.map).stat().st_mtime
            except OSError:
                mtime = -1.0  # missing: load_ros_map names the problem
        return _site(
            tuple(self.volume.low[:2]),
            tuple(self.volume.high[:2]),
            self.world.model_copy(update={"resolution": self.site_resolution}).model_dump_json(),
            mtime,
        )

    @property
    def site_resolution(self) -> float:
        """m, the cell side of the site's grid: ``world.resolution``, or a quarter step."""
        return self.world.resolution or self.agent.step / 4.0

    def in_obstacle(self, xy: np.ndarray, no_go: bool = True) -> np.ndarray:
        """(K,) bool: the (K, 2) points lie inside an obstacle (or, with ``no_go``, a no-go
        zone) itself (the shapes as given, not grown to the grid's cells or by
        ``clearance``) or in an occupied or unknown cell of the map file: what a robot's drive
        must never touch."""
        return inside_world(self.world, xy, no_go)

    def stop_rule(self, on_robot: bool) -> StopRule | None:
        """When this search ends early (:class:`~dcee.stopping.StopRule`): ``search.stop_spread``
        held for ``search.stop_hold`` s; unset, the default rule on a robot (``on_robot``) and
        none in a simulation; 0, none."""
        search = self.search
        if search.stop_spread is None:
            return StopRule.for_scale(search.acquired_rmse, search.stop_hold) if on_robot else None
        if search.stop_spread == 0:
            return None
        return StopRule(search.stop_spread, search.stop_hold)

    def make_prior(self) -> SourcePrior:
        """The filter's prior. A known parameter is fixed at the truth's value only where the
        scenario declares it known: the environment (u, φ, ζ1, ζ2) with ``unknown = "source"``,
        the source height with ``dimensions = 2``; the lbm plume's source height is its plane,
        the agent's altitude. Over a planar recording the source height's default prior is
        uniform between the ground and the recording's plane (a slice holds the gas of a
        release at or below it)."""
        truth = self.truth_theta()
        dists: dict[str, Distribution] = {}
        for k, name in enumerate(PARAMETER_NAMES):
            if name not in self.unknown_names:
                if name == "z" and self.dimensions == 3:  # the lbm plume: the flight plane
                    dists[name] = Fixed(float(self.agent.start[2]))
                else:
                    dists[name] = Fixed(float(truth[k]))
            elif k < 3 and name not in self.prior:
                plane = self.reading_plane if k == 2 else None
                high = self.volume.high[k] if plane is None else plane
                dists[name] = Uniform(self.volume.low[k], high)
            else:
                dists[name] = _distribution(name, self.prior[name])
        return SourcePrior.from_dict(dists)


def _distribution(name: str, spec: PriorSpec) -> Distribution:
    to_rad = math.radians if name == "phi" else (lambda v: v)
    if spec.kind == "uniform":
        return Uniform(to_rad(spec.low), to_rad(spec.high))
    if spec.kind == "gamma":
        return Gamma(spec.shape, spec.scale)
    low = spec.low if spec.low is not None else PHYSICAL_TRUNCATION.get(name, -math.inf)
    high = spec.high if spec.high is not None else math.inf
    return Normal(to_rad(spec.mean), to_rad(spec.sd), to_rad(low), to_rad(high))
