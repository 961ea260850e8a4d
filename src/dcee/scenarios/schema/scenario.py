"""The scenario: every section validated together into one immutable object, and the one-line
errors of a bad file (:func:`validate_scenario`). How a scenario becomes model objects is
:mod:`dcee.scenarios.builders`; reading and writing files is :mod:`dcee.scenarios.files`."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, Field, PrivateAttr, ValidationError, model_validator

from dcee.errors import DceeInputError
from dcee.models.agent import GridAgent
from dcee.models.plume import PARAMETER_NAMES
from dcee.scenarios.builders import ScenarioBuilders
from dcee.scenarios.schema.agent import (
    AgentSpec,
    SearchSpec,
    team_starts,
)
from dcee.scenarios.schema.common import FIELD_MARK, FROZEN, phi_prior_from_bearing
from dcee.scenarios.schema.estimator import (
    AnemometerSpec,
    EstimatorSpec,
    PriorSpec,
    SensorSpec,
    default_priors,
)
from dcee.scenarios.schema.messages import one_line_error
from dcee.scenarios.schema.reading_models import ReadingModelSettings
from dcee.scenarios.schema.resolved import ResolvedSettings
from dcee.scenarios.schema.truth import Truth, Volume
from dcee.scenarios.schema.world import WorldSpec, has_walls

GAS_MAP_MAX_CELL = 1.0
"""m: the coarsest map cell the gas round buildings is computed on (the lbm truth, the
wall-aware estimator): a 2 m street is then two cells wide at least."""

SITE_TRUTH = "lbm"
"""The truth of a site with walls when ``truth.model`` is unset (issue 84): the fluid solver's
plume, whose gas flows round the walls (planar, its source in the flight plane); elsewhere the
unset truth is the paper's isotropic plume."""


GAS_SOURCE_CLEARANCE = 2.0
"""m round the source within which a map may leave no cell unknown where the gas flows round
walls (what the gas meets first must be known)."""


class Scenario(ScenarioBuilders, ReadingModelSettings, ResolvedSettings, BaseModel):
    """A validated, immutable scenario."""

    model_config = FROZEN
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
    prior: dict[str, PriorSpec] = Field(default_factory=default_priors)
    """priors of the unknown parameters by name (q, u, phi, zeta1, zeta2; x, y, z uniform over
    the volume unless given); defaults: the paper's table 1 (phi has none)"""
    sensor: SensorSpec = SensorSpec()
    """the instrument, see [sensor]"""
    anemometer: AnemometerSpec = AnemometerSpec()
    """a measured wind, see [anemometer]"""
    estimator: EstimatorSpec = EstimatorSpec()
    """the reading model of the filter and the planners, see [estimator]"""
    agent: AgentSpec
    """the mobile sensor, see [agent]"""
    search: SearchSpec = SearchSpec()
    """scale, budget and success criterion, see [search]"""
    world: WorldSpec = WorldSpec()
    """obstacles, no-go zones and an occupancy-grid map, see [world]"""
    _layout: tuple[bool, float | None] = PrivateAttr(default=(False, None))

    @model_validator(mode="before")
    @classmethod
    def _prior_bearing_to_phi(cls, data: Any) -> Any:
        # prior.wind_from: the wind direction's prior as a compass bearing, stored as prior.phi
        prior = data.get("prior") if isinstance(data, dict) else None
        if not isinstance(prior, dict) or "wind_from" not in prior:
            return data
        if "phi" in prior:
            raise ValueError(f"{FIELD_MARK}prior.wind_from: give prior.phi or prior.wind_from")
        prior = {k: v for k, v in prior.items() if k != "wind_from"}
        prior["phi"] = phi_prior_from_bearing(data["prior"]["wind_from"])
        return {**data, "prior": prior}

    @model_validator(mode="before")
    @classmethod
    def _gas_round_walls(cls, data: Any) -> Any:
        # at a site with walls the gas goes round them: an unset truth model is the fluid
        # solver's plume, and an unset likelihood follows that turbulent truth (issue 84)
        if not isinstance(data, dict) or not has_walls(data.get("world")):
            return data
        truth = data.get("truth")
        if not isinstance(truth, dict):
            return data
        out = dict(data)
        if truth.get("model") is None:
            out["truth"] = truth = {**truth, "model": SITE_TRUTH}
        estimator = out.get("estimator")
        if isinstance(estimator, EstimatorSpec):
            return out
        estimator = dict(estimator or {})
        if truth.get("model") == SITE_TRUTH and estimator.get("likelihood") is None:
            out["estimator"] = {**estimator, "likelihood": "fluctuation"}
        return out

    @model_validator(mode="after")
    def _consistent(self) -> Scenario:
        lo, hi = np.array(self.volume.low), np.array(self.volume.high)
        for k, src in enumerate(self.truth.source_locations()):
            if np.any(src < lo) or np.any(src > hi):
                where = "truth: source" if k == 0 else f"{FIELD_MARK}truth.extra_sources: release"
                raise ValueError(
                    f"{where} ({src[0]:g}, {src[1]:g}, {src[2]:g}) is outside the search volume "
                    f"{tuple(self.volume.low)}..{tuple(self.volume.high)}"
                )
        start = np.array(self.agent.start)
        if np.any(start < lo) or np.any(start > hi):
            raise ValueError(
                f"{FIELD_MARK}agent.start: {tuple(self.agent.start)} is outside the search volume"
            )
        if self.dimensions == 3 and not hi[2] > lo[2]:
            raise ValueError("volume: a 3-D scenario needs high z > low z")
        self.agent.checked_min_altitude(float(lo[2]), float(hi[2]))
        for k in (0, 1):
            if not hi[k] > lo[k]:
                raise ValueError(f"volume: high[{k}] must be > low[{k}]")
        unknown_env = ("q",) if self.unknown == "source" else ("q", "u", "phi", "zeta1", "zeta2")
        missing = [p for p in unknown_env if p not in self.prior]
        if missing:
            raise ValueError(f"prior: missing a prior for unknown parameter(s) {missing}")
        phi = self.prior.get("phi")
        for key in ("mean", "sd", "low", "high"):  # degrees here, radians in the Python API
            value = getattr(phi, key, None) if phi is not None else None
            if value is not None and abs(value) > 360.0:
                raise ValueError(
                    f"{FIELD_MARK}prior.phi.{key}: degrees in scenario files, within "
                    f"[-360, 360], got {value:g}"
                )
        extra = [p for p in self.prior if p not in PARAMETER_NAMES]
        if extra:
            raise ValueError(f"prior: unknown parameter name(s) {extra}; allowed {PARAMETER_NAMES}")
        self._checked_learn()
        self._checked_source_count()
        self._checked_walls()
        self._checked_planar(start)
        site = self._checked_site(start, src)
        agent = GridAgent(
            self.search_volume(),
            self.agent.step,
            self.agent.speed,
            self.dwell,
            self.agent.headings,
            site=site,
            climb=self.climb,
        )
        if self.agent.climb is not None and self.agent.climb > 0 and self.agent.model != "grid":
            raise ValueError(
                f'{FIELD_MARK}agent.climb: {self.agent.climb:g} m needs agent.model = "grid" '
                f"(the {self.agent.model} robot drives on the ground); use climb = 0"
            )
        starts = team_starts(start, self.agent.step, self.agent.count, lo, hi)
        if starts is None:
            raise ValueError(
                f"{FIELD_MARK}agent.count: {self.agent.count} robots {self.agent.step:g} m apart "
                f"along y from agent.start {tuple(self.agent.start)} do not fit in the area"
            )
        if len(agent.candidates(start)[0]) == 0 and site is not None:
            raise ValueError(
                f"{FIELD_MARK}agent.start: every move from {tuple(self.agent.start)} enters or "
                "crosses an obstacle or no-go zone ([world])"
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

    def _checked_planar(self, start: np.ndarray) -> None:
        """Read the truth's layout once (a recording's header) and refuse what cannot work over
        a planar truth: a climbing agent (the readings do not change with height, the reading
        model does), an agent away from the plane the truth holds, and a source height the
        search could only take from the truth (the lbm plume's source off its plane)."""
        try:
            layout = self.truth.layout()
        except DceeInputError as exc:
            raise ValueError(f"{FIELD_MARK}{exc.field}: {exc.message}") from None
        object.__setattr__(self, "_layout", layout)
        planar, plane = layout
        if not planar:
            return
        what = f"the truth ({self.truth.model_name}) is planar: one horizontal plane, the same "
        if self.agent.climb is not None and self.agent.climb > 0:
            raise ValueError(
                f"{FIELD_MARK}agent.climb: {self.agent.climb:g} m cannot work: {what}at every "
                "altitude, so climbing reads nothing about height while the reading model "
                "predicts it; use climb = 0 (the default there) or a recording with a z axis"
            )
        if plane is not None and abs(start[2] - plane) > 1e-6:
            raise ValueError(
                f"{FIELD_MARK}agent.start: z = {start[2]:g} m is off the plane it holds: {what}"
                f"at every altitude, held at z = {plane:g} m; start the agent at that height"
            )
        if self.truth.model_name == "lbm" and abs(self.truth.z - start[2]) > 1e-6:
            raise ValueError(
                f"{FIELD_MARK}truth.z: {self.truth.z:g} m is off the flight plane: the lbm plume "
                f"(a site's truth where there are walls) is planar, its source in the plane the "
                f"agent flies (z = {start[2]:g} m), so set truth.z = {start[2]:g}, or for a "
                'source below the UAV truth.model = "lbm3d" (a 3-D plume, open terrain) or '
                '"isotropic" (gas that passes through walls)'
            )
        if plane is None:
            plane = float(start[2])
        if self.truth.model_name.startswith("lbm3d-slice") and self.truth.z > plane + 1e-9:
            raise ValueError(
                f"{FIELD_MARK}truth.model.plane: the slice at {plane:g} m is below the source "
                f"(truth.z = {self.truth.z:g} m); a slice of the plume lies at or above it"
            )
        if (
            self.dimensions == 3
            and "z" not in self.prior
            and self.truth.model_name != "lbm"
            and not plane > self.volume.low[2]
        ):
            raise ValueError(
                f"{FIELD_MARK}dimensions: the source height of a planar recording is estimated "
                f"between the ground (volume.low z = {self.volume.low[2]:g} m) and its plane "
                f"(z = {plane:g} m), which leaves no room; set dimensions = 2 to declare it known "
                "(truth.z)"
            )

    @property
    def explore_guard(self) -> bool:
        """``search.explore_guard`` resolved: as given, or on with several releases (a further
        one may be anywhere, far from every move) and on a site (walls and zones make regions
        where no move within reach is informative; issue 44), off in open terrain."""
        if self.search.explore_guard is not None:
            return self.search.explore_guard
        return self.estimator.max_sources > 1 or not self.world.empty

    @property
    def planar_truth(self) -> bool:
        """The truth holds one horizontal plane (a 2-D recording or the lbm solver plume): the
        agent stays at its altitude (an unset climb is 0)."""
        return self._layout[0]

    @property
    def reading_plane(self) -> float | None:
        """m, the height a planar truth holds (the file's, else the agent's start altitude);
        None for a truth with height."""
        if not self.planar_truth:
            return None
        plane = self._layout[1]
        return float(self.agent.start[2]) if plane is None else float(plane)

    @property
    def source_height_known(self) -> bool:
        """The source height is not estimated: ``dimensions = 2`` declares it known (it is then
        ``truth.z``), and the lbm solver plume's source lies in its plane, the plane the agent
        flies (``truth.z`` must equal the start altitude). Over a planar recording it is
        estimated, between the ground and the recording's plane, unless declared known."""
        return self.dimensions == 2 or self.truth.model_name == "lbm"

    @property
    def search_dimensions(self) -> int:
        """2 where the source height is known (:attr:`source_height_known`), else 3."""
        return 2 if self.source_height_known else 3

    def _checked_site(self, start: np.ndarray, src: np.ndarray) -> Any:
        """The ``[world]`` map, with the start outside every blocked cell, the source outside
        every obstacle (a no-go zone may hold it) and reachable from the start."""
        if self.world.empty:
            return None
        try:
            site = self.make_site()
        except DceeInputError as exc:
            raise ValueError(f"{FIELD_MARK}{exc.field}: {exc.message}") from None
        if site.is_blocked(start[None, :2])[0]:
            raise ValueError(
                f"{FIELD_MARK}agent.start: {tuple(self.agent.start)} lies inside an obstacle or "
                f"no-go zone of [world] (or within world.clearance of one)"
            )
        if self.in_obstacle(src[None, :2], no_go=False)[0]:
            raise ValueError(
                f"{FIELD_MARK}truth: the source ({src[0]:g}, {src[1]:g}) lies inside an "
                "obstacle of [world]; a source the robot must keep away from belongs in "
                "world.no_go"
            )
        if not site.reachable(start, src[None, :2])[0]:
            raise ValueError(
                f"{FIELD_MARK}world: the source area around ({src[0]:g}, {src[1]:g}) cannot be "
                f"reached from agent.start {tuple(self.agent.start)}: obstacles enclose it"
            )
        if self.truth.model_name == "lbm" or (
            self.plume_model == "walls" and self.wall_wind != "room"
        ):
            self._checked_gas_walls(src)
        return site

    def _checked_gas_walls(self, src: np.ndarray) -> None:
        """Where the gas flows round the site's walls (the lbm truth, ``estimator.plume =
        "walls"``): a map fine enough to hold a street, the walls round the source known, and a
        free path for the gas from the source out of the site."""
        from dcee.models.site_plume import open_to_edge, site_grid
        from dcee.scenarios.builders import raw_map

        if self.world.map is not None:
            raw = raw_map(self.world.map)
            if raw.resolution > GAS_MAP_MAX_CELL:
                raise ValueError(
                    f"{FIELD_MARK}world.map: {raw.name} has {raw.resolution:g} m cells; the gas "
                    f"round buildings needs at most {GAS_MAP_MAX_CELL:g} m (a street two cells "
                    "wide at least)"
                )
            ring = src[None, :2] + GAS_SOURCE_CLEARANCE * np.array(
                [[0, 0]] + [[np.cos(a), np.sin(a)] for a in np.linspace(0, 2 * np.pi, 16)]
            )
            if raw.is_unknown(ring).any():
                raise ValueError(
                    f"{FIELD_MARK}world.map: {raw.name} leaves cells within "
                    f"{GAS_SOURCE_CLEARANCE:g} m of the source ({src[0]:g}, {src[1]:g}) unknown; "
                    "the walls the gas meets there must be known"
                )
        fluid, origin = site_grid(
            tuple(self.volume.low[:2]),
            tuple(self.volume.high[:2]),
            float(self.site_resolution),
            lambda xy: self.in_obstacle(xy, no_go=False),
        )
        if not open_to_edge(fluid, origin, float(self.site_resolution), src[:2]):
            raise ValueError(
                f"{FIELD_MARK}world: the gas from the source ({src[0]:g}, {src[1]:g}) has no "
                "free path out of the site: obstacles enclose it"
            )

    @property
    def unknown_names(self) -> tuple[str, ...]:
        loc = ("x", "y", "z") if self.search_dimensions == 3 else ("x", "y")
        env = ("q",) if self.unknown == "source" else ("q", "u", "phi", "zeta1", "zeta2")
        return loc + env

    def with_overrides(self, **changes: Any) -> Scenario:
        """A re-validated copy; keys are dotted paths, e.g. ``{"search.particles": 2000}``.

        Applied in order, each on the validated result of the ones before (so that a later path
        may go into what an earlier one set: ``truth.model = "filament"``, then
        ``truth.model.meander_intensity``); a combination that is only invalid halfway (the
        count of releases raised before the reading models are cut to one) is carried on
        unvalidated, and only the final one must hold.

        Where every change goes into a section that exists already, all are applied at once and
        validated once, which gives the same scenario (the sections' values are validated and
        dumped ones either way): a study recipe's hundred settings cost one validation instead
        of a hundred (the test suite dry-runs 419 such commands). Anything else, or a
        combination that does not validate, takes the step-by-step path, which names the
        change that fails."""
        changes = {path: value for path, value in changes.items() if value is not None}
        data = self.model_dump()
        if _apply_at_once(data, changes):
            try:
                return validate_scenario(data)
            except DceeInputError:
                pass  # the step-by-step path below says why, as it always did
        return self._with_overrides_stepwise(changes)

    def _with_overrides_stepwise(self, changes: dict[str, Any]) -> Scenario:
        """:meth:`with_overrides` one change at a time, each on the validated result of the
        ones before."""
        scenario = self
        data = scenario.model_dump()
        pending: DceeInputError | None = None  # why the changes so far do not validate
        for path, value in changes.items():
            missing = _set_path(data, path, value)
            if missing is not None:
                if pending is not None:
                    raise pending  # the section would exist once the earlier change held
                raise DceeInputError(path, f"no such setting ({missing!r} is not a section)")
            try:
                scenario = validate_scenario(data)
            except DceeInputError as exc:
                pending = exc
                continue
            pending = None
            data = scenario.model_dump()
        if pending is not None:
            raise pending
        return scenario


def _apply_at_once(data: dict[str, Any], changes: dict[str, Any]) -> bool:
    """Apply every change (dotted path → value) to ``data`` in order, as
    :meth:`Scenario.with_overrides` does one at a time; False, ``data`` then partly changed,
    where a path goes through something that is not a section (yet)."""
    return all(_set_path(data, path, value) is None for path, value in changes.items())


def _set_path(data: dict[str, Any], path: str, value: Any) -> str | None:
    """Set the dotted ``path`` of ``data`` to ``value``; the name on the way that is not a
    section (nothing set), or None."""
    node = data
    *parents, leaf = path.split(".")
    for p in parents:
        if not isinstance(node.get(p), dict):
            return p
        node = node[p]
    node[leaf] = value
    if leaf == "wind_from" and parents in (["truth"], ["prior"]):
        node.pop("phi", None)  # the bearing replaces the angle it was given as
    return None


def validate_scenario(data: dict[str, Any]) -> Scenario:
    """Validate a raw mapping; errors become one-line :class:`DceeInputError`."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise one_line_error(exc, Scenario) from None
