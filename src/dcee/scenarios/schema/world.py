"""The ``[world]`` section: obstacles and no-go zones the robot may not enter or cross, as
shapes or as an occupancy-grid map in the ROS map-server format (:mod:`dcee.models.site`,
:mod:`dcee.models.ros_map`)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, model_validator

from dcee.models.site import Circle, Polygon, Rectangle, Shape
from dcee.scenarios.schema.common import FROZEN, Finite

Point = tuple[Finite, Finite]


class ShapeSpec(BaseModel):
    """One obstacle or no-go zone: ``kind`` "rectangle" (corners ``low``, ``high``), "circle"
    (``center``, ``radius``) or "polygon" (``points``, at least 3 vertices in order); m."""

    model_config = FROZEN
    kind: Literal["rectangle", "circle", "polygon"]
    """the shape"""
    low: Point | None = None
    """m: a rectangle's lower-left corner (x, y)"""
    high: Point | None = None
    """m: a rectangle's upper-right corner (x, y)"""
    center: Point | None = None
    """m: a circle's centre (x, y)"""
    radius: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None
    """m: a circle's radius"""
    points: tuple[Point, ...] | None = None
    """m: a polygon's vertices (x, y), in order"""

    @model_validator(mode="after")
    def _complete(self) -> ShapeSpec:
        needs = {
            "rectangle": ("low", "high"),
            "circle": ("center", "radius"),
            "polygon": ("points",),
        }[self.kind]
        missing = [k for k in needs if getattr(self, k) is None]
        if missing:
            raise ValueError(f"a {self.kind} needs {' and '.join(missing)}")
        extra = [
            k
            for k in ("low", "high", "center", "radius", "points")
            if k not in needs and getattr(self, k) is not None
        ]
        if extra:
            raise ValueError(f"a {self.kind} has no {', '.join(extra)} (it takes {needs})")
        if self.kind == "rectangle" and not all(
            h > lo
            for lo, h in zip(self.low, self.high, strict=True)  # type: ignore[arg-type]
        ):
            raise ValueError("a rectangle's high corner must lie above and right of its low one")
        if self.kind == "polygon":
            problem = Polygon(tuple(self.points)).problem()  # type: ignore[arg-type]
            if problem is not None:
                raise ValueError(problem)
        return self

    def shape(self) -> Shape:
        if self.kind == "rectangle":
            return Rectangle(self.low, self.high)  # type: ignore[arg-type]
        if self.kind == "circle":
            return Circle(self.center, float(self.radius))  # type: ignore[arg-type]
        return Polygon(tuple(self.points))  # type: ignore[arg-type]


class FrameSpec(BaseModel):
    """The local frame of a site given in geographic coordinates (:mod:`dcee.geo.frame`):
    transverse Mercator about (``latitude``, ``longitude``) degrees on WGS 84, shifted by
    (``x0``, ``y0``) m. Written when ``world.area`` is read; never given by hand."""

    model_config = FROZEN
    latitude: Annotated[float, Field(gt=-90, lt=90, allow_inf_nan=False)]
    longitude: Annotated[float, Field(ge=-180, le=180, allow_inf_nan=False)]
    x0: Finite = 0.0
    y0: Finite = 0.0

    def local_frame(self) -> Any:
        """The :class:`dcee.geo.frame.LocalFrame` it describes (one shared instance per frame:
        its pyproj transformer takes about 8 ms to build)."""
        from dcee.geo.frame import shared_frame

        return shared_frame(self.latitude, self.longitude, self.x0, self.y0)


class WorldSpec(BaseModel):
    """Obstacles and no-go zones. The robot never enters or crosses either (every planner
    chooses among the moves that stay clear; distance costs are travel distances around
    them); the difference is only what they mean to a user: an obstacle is a wall or a tank,
    a no-go zone a place the robot must keep out of, and the source may lie inside a no-go
    zone (the robot then localises it from outside) but not inside an obstacle. To the gas
    an obstacle (and an occupied cell of the map) is a wall on the fluid solver's truth
    (``truth.model = "lbm"``: the flow and the gas go round it,
    :func:`dcee.simulation.lbm.site_frame`) and nothing on the others (the isotropic truth
    is the paper's plume in open terrain, and the filament and puff truths' filaments pass
    through walls); a no-go zone is nothing to the gas on any truth."""

    model_config = FROZEN
    obstacles: tuple[ShapeSpec, ...] = ()
    """walls, tanks, buildings: e.g. ``[{kind = "rectangle", low = [20, 0], high = [21, 40]}]``"""
    no_go: tuple[ShapeSpec, ...] = ()
    """zones the robot must keep out of: e.g.
    ``[{kind = "circle", center = [30, 30], radius = 5}]``"""
    map: str | None = None
    """an occupancy-grid map in the ROS map-server format: the YAML file (``image``,
    ``resolution``, ``origin``, ``negate``, ``occupied_thresh``, ``free_thresh``) beside its
    PGM/PNG; occupied and unknown cells are obstacles (a relative path is taken from the
    working directory)"""
    resolution: Annotated[float, Field(gt=0, le=10, allow_inf_nan=False)] | None = None
    """m: cell side of the grid the shapes are drawn on and the paths are found on (a cell is
    blocked when a shape touches it); None: a quarter of
    ``agent.step`` (0.5 m at the paper's 2 m steps, 0.075 m in the lab)"""
    clearance: Annotated[float, Field(ge=0, le=100, allow_inf_nan=False)] = 0.0
    """m: every obstacle and zone grown by this much (the robot's radius plus a margin)"""
    area: str | None = None
    """a site in geographic coordinates: a GeoJSON file with the search area, buildings and
    no-go zones (:mod:`dcee.scenarios.geo_area`, docs/guide/on-a-map.md), read when the scenario
    is loaded into the local frame (``frame``) and these shapes; a relative path is taken from
    the scenario file's folder"""
    frame: FrameSpec | None = None
    """the local frame of ``area`` (written when it is read)"""

    @model_validator(mode="after")
    def _area_read(self) -> WorldSpec:
        if self.area is not None and self.frame is None:
            raise ValueError(
                "area: a map is read when the scenario is loaded: give it as [world] area in a "
                "scenario file or with dcee run --area FILE, not with --set"
            )
        return self

    @property
    def empty(self) -> bool:
        return not self.obstacles and not self.no_go and self.map is None

    @property
    def walls(self) -> bool:
        """Walls the gas flows round: obstacles or an occupancy-grid map (a no-go zone is
        nothing to the gas)."""
        return has_walls(self)


def has_walls(world: WorldSpec | dict[str, Any] | None) -> bool:
    """:attr:`WorldSpec.walls` of a ``[world]``, validated or as its raw (or stored) mapping."""
    if isinstance(world, WorldSpec):
        return bool(world.obstacles) or world.map is not None
    if not isinstance(world, dict):
        return False
    return bool(world.get("obstacles")) or world.get("map") is not None


def shapes_of(specs: tuple[ShapeSpec, ...]) -> list[Shape]:
    return [s.shape() for s in specs]


__all__ = ["FrameSpec", "ShapeSpec", "WorldSpec", "has_walls", "shapes_of"]
