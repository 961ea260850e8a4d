"""A scenario on a map in geographic coordinates (``[world] area = "site.geojson"`` in a
scenario file, ``dcee run --area FILE``, or the file alone as ``--scenario FILE.geojson``).

The site file (:mod:`dcee.geo.site_file`) is read when the scenario is loaded and becomes the
scenario's local frame and shapes; the saved scenario (``config.json``) holds both, with the
frame (``world.frame``) that writes every result back to longitude and latitude:

* **Frame**: transverse Mercator about the centre of the area's bounding box, its south-west
  corner at (0, 0) (:mod:`dcee.geo.frame` says why); x east, y north, metres.
* **Volume**: the area's bounding box, from the ground to the higher of 5 m and the start's
  height + 1 m. Outside the fence but inside the box is a no-go zone, and so are the area's
  holes and the file's no-go zones.
* **Buildings** become obstacles (walls to the gas on the solver truth and the wall-aware
  estimator, as every obstacle) where they reach the lowest altitude the agent may fly:
  ``agent.min_altitude`` if set, else the start's height for an agent at one altitude, else
  the ground (an agent that may descend, and every ground robot). A UAV at 4 m thus overflies a
  3 m shed and not a 12 m hall; a building without a height blocks every agent.
* **Start and release**: ``agent.start_geo`` / ``truth.source_geo`` (``{latitude, longitude,
  height}`` in a scenario file) or the file's ``start`` and ``source`` Points; the release
  Point's ``rate``, ``wind_from`` and ``wind_speed`` give the simulated truth's q, wind bearing
  and speed where the scenario does not.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.geo.frame import MAX_EXTENT, LocalFrame, frame_for_bounds
from dcee.geo.site_file import GeoPoint, GeoSite, read_site

SITES = Path(__file__).parent / "sites"
"""The site files that ship with dcee (``area:NAME`` is ``sites/NAME.geojson``)."""
MIN_CEILING = 5.0
"""m: the volume's least top (the random scenarios' 0-5 m)."""


def _geo_point(spec: Any, field: str) -> GeoPoint:
    keys = ("latitude", "longitude", "height")
    if (
        not isinstance(spec, dict)
        or set(spec) - set(keys)
        or not {"latitude", "longitude"} <= set(spec)
    ):
        raise DceeInputError(field, "must be {latitude = …, longitude = …, height = … m}")
    lat, lon, h = (spec.get(k, 0.0) for k in keys)
    for name, value, bound in (("latitude", lat, 90.0), ("longitude", lon, 180.0)):
        if isinstance(value, bool) or not isinstance(value, int | float) or abs(value) > bound:
            raise DceeInputError(f"{field}.{name}", f"must be degrees within ±{bound:g}")
    if isinstance(h, bool) or not isinstance(h, int | float) or not 0.0 <= h <= 1000.0:
        raise DceeInputError(f"{field}.height", "must be metres above the ground in [0, 1000]")
    return GeoPoint(field, float(lon), float(lat), float(h), {})


def _local_ring(frame: LocalFrame, ring: np.ndarray) -> list[list[float]]:
    x, y = frame.to_local(ring[:, 0], ring[:, 1])
    return [[round(float(a), 3), round(float(b), 3)] for a, b in zip(x[:-1], y[:-1], strict=True)]


def _polygon_spec(points: list[list[float]]) -> dict[str, Any]:
    return {"kind": "polygon", "points": points}


def _place(frame: LocalFrame, point: GeoPoint, area: Any, what: str) -> list[float]:
    """The point's local (x, y, height); refused outside the area, with a hint where it is
    far away (latitude and longitude swapped)."""
    from pyproj import Geod
    from shapely import Point

    x, y = frame.to_local(np.array([point.lon]), np.array([point.lat]))
    xy = Point(float(x[0]), float(y[0]))
    if not area.covers(xy):
        centre = frame.to_geo(np.array([area.centroid.x]), np.array([area.centroid.y]))
        _, _, km = Geod(ellps="WGS84").inv(point.lon, point.lat, centre[0][0], centre[1][0])
        hint = (
            "; latitude and longitude swapped? (GeoJSON positions are [longitude, latitude])"
            if km > 10_000.0
            else ""
        )
        raise DceeInputError(
            what,
            f"latitude {point.lat:.6f}°, longitude {point.lon:.6f}° lies outside the area, "
            f"{km / 1000.0:,.2f} km "
            f"from its centre{hint}",
        )
    return [round(float(x[0]), 3), round(float(y[0]), 3), point.height]


def expand_area(data: dict[str, Any], base: Path | None = None) -> dict[str, Any]:
    """The raw scenario ``data`` with its ``world.area`` read into the local frame (module
    doc); unchanged where it names no area or was expanded already (``world.frame`` set).
    ``base``: the folder a relative area path is taken from (the scenario file's)."""
    from dcee.scenarios.schema import validate_scenario

    world = data.get("world") if isinstance(data.get("world"), dict) else {}
    agent = data.get("agent") if isinstance(data.get("agent"), dict) else {}
    truth = data.get("truth") if isinstance(data.get("truth"), dict) else {}
    if world.get("area") is None or world.get("frame") is not None:
        for where, key in ((agent, "agent.start_geo"), (truth, "truth.source_geo")):
            if key.split(".")[1] in where:
                raise DceeInputError(key, "needs a map in geographic coordinates (world.area)")
        return data
    path = Path(str(world["area"])).expanduser()
    if not path.is_absolute() and base is not None:
        path = base / path
    site = read_site(path)
    out = copy.deepcopy(data)
    out_world, out_agent, out_truth = (out.setdefault(k, {}) for k in ("world", "agent", "truth"))
    if "volume" in out:
        raise DceeInputError("volume", "set by world.area (the area's bounding box); leave it out")
    lon, lat = site.area.ring[:, 0], site.area.ring[:, 1]
    frame = frame_for_bounds(lon.min(), lat.min(), lon.max(), lat.max())
    from shapely import Point, Polygon, box

    ring = _local_ring(frame, site.area.ring)
    area = Polygon(ring, [_local_ring(frame, h) for h in site.area.holes])
    width, depth = area.bounds[2], area.bounds[3]
    if max(width, depth) > MAX_EXTENT:
        raise DceeInputError(
            site.area.label,
            f"{max(width, depth) / 1000.0:,.1f} km across; one local frame serves at most "
            f"{MAX_EXTENT / 1000.0:.0f} km (scale error within 1e-5): split the area",
        )
    start_spec = out_agent.pop("start_geo", None)
    source_spec = out_truth.pop("source_geo", None)
    start = _geo_point(start_spec, "agent.start_geo") if start_spec is not None else site.start
    source = _geo_point(source_spec, "truth.source_geo") if source_spec is not None else site.source
    if start is None:
        raise DceeInputError(
            "agent.start_geo", f"{site.path.name} has no start Point and the scenario gives none"
        )
    start_xyz = _place(frame, start, area, "agent.start_geo" if start_spec else start.label)
    if source is not None:
        src = _place(frame, source, area, "truth.source_geo" if source_spec else source.label)
        out_truth.update(x=src[0], y=src[1], z=src[2])
        props = source.properties
        defaults = {"q": props.get("rate"), "u": props.get("wind_speed")}
        for key, value in defaults.items():
            if value is not None and key not in truth:
                out_truth[key] = value
        if props.get("wind_from") is not None and "phi" not in truth and "wind_from" not in truth:
            out_truth.pop("phi", None)
            out_truth["wind_from"] = props["wind_from"]
    elif not {"x", "y"} <= set(truth):
        raise DceeInputError(
            "truth.source_geo",
            f"{site.path.name} has no source Point and the scenario gives none (a simulation "
            "needs the release it flies against)",
        )
    ceiling = max(MIN_CEILING, start_xyz[2] + 1.0)
    out["volume"] = {
        "low": [0.0, 0.0, 0.0],
        "high": [math.ceil(width * 10) / 10, math.ceil(depth * 10) / 10, ceiling],
    }
    out_agent["start"] = start_xyz
    outside = box(0.0, 0.0, *out["volume"]["high"][:2]).difference(Polygon(ring))
    pieces = _simple_pieces(outside)
    zones = [
        _polygon_spec([[round(a, 3), round(b, 3)] for a, b in list(p.exterior.coords)[:-1]])
        for p in pieces
    ]
    zones += [_polygon_spec(_local_ring(frame, h)) for h in site.area.holes]
    zones += [_polygon_spec(_local_ring(frame, z.ring)) for z in site.no_go]
    out_world.update(
        frame={
            "latitude": frame.latitude,
            "longitude": frame.longitude,
            "x0": frame.x0,
            "y0": frame.y0,
        },
        area=str(site.path),
        no_go=[*world.get("no_go", []), *zones],
    )
    out.setdefault("name", f"area:{site.path.stem}")
    # which buildings block: those reaching the lowest altitude the agent may fly (module doc)
    provisional = validate_scenario(out)
    if provisional.agent.min_altitude is not None:
        lowest = float(provisional.agent.min_altitude)
    elif provisional.resolved_climb(False) == 0:
        lowest = start_xyz[2]
    else:
        lowest = float(provisional.volume.low[2])
    blocking = [b for b in site.buildings if b.height is None or b.height >= lowest]
    local = [_local_ring(frame, b.footprint.ring) for b in blocking]
    for building, points in zip(blocking, local, strict=True):
        if Polygon(points).covers(Point(start_xyz[0], start_xyz[1])):
            raise DceeInputError(
                "agent.start_geo" if start_spec else start.label,
                f"inside {building.footprint.label}"
                + (f", {building.height:g} m high" if building.height is not None else ""),
            )
    out_world["obstacles"] = [*world.get("obstacles", []), *map(_polygon_spec, local)]
    return out


def _simple_pieces(geometry: Any) -> list[Any]:
    """Polygons without holes covering ``geometry`` (the site's shapes have none): a polygon
    with a hole is cut in two by a vertical line through the hole, until none is left."""
    from shapely import LineString
    from shapely.ops import split

    out = []
    for part in getattr(geometry, "geoms", [geometry]):
        if part.area <= 1e-6:
            continue
        if not part.interiors:
            out.append(part)
            continue
        x = part.interiors[0].centroid.x
        low, high = part.bounds[1] - 1.0, part.bounds[3] + 1.0
        out += _simple_pieces(split(part, LineString([(x, low), (x, high)])))
    return out


def packaged_site(name: str) -> Path:
    """The site file of ``area:NAME``."""
    path = SITES / f"{name}.geojson"
    if not path.is_file():
        names = ", ".join(f"area:{p.stem}" for p in sorted(SITES.glob("*.geojson")))
        raise DceeInputError("scenario", f"no site area:{name}; dcee ships {names}")
    return path


def area_configuration(path: str | Path) -> dict[str, Any]:
    """The scenario of a site file alone (``--scenario FILE.geojson``, ``--area FILE`` without
    a scenario): the paper's sensor, agent and priors (configuration 1 of its study) on the
    site, the wind prior centred on the release Point's ``wind_from``."""
    from dcee.scenarios.builtin import paper_configuration

    site: GeoSite = read_site(path)
    data = paper_configuration(1)
    for key in ("volume", "name", "description"):
        data.pop(key)
    props = site.source.properties if site.source is not None else {}
    given = {"rate": "q", "wind_speed": "u"}  # the release Point's, where it gives them
    drop = {"x", "y", "z"} | {given[k] for k in given if props.get(k) is not None}
    truth = {k: v for k, v in data["truth"].items() if k not in drop}
    if props.get("wind_from") is not None:
        truth.pop("phi")
        prior = {k: v for k, v in data["prior"].items() if k != "phi"}
        prior["wind_from"] = {**data["prior"]["phi"], "mean": float(props["wind_from"])}
        data["prior"] = prior
    data.update(
        name=f"area:{site.path.stem}",
        description=f"The site {site.path.name}"
        + (f" ({site.attribution})" if site.attribution else ""),
        truth=truth,
        world={"area": str(site.path)},
    )
    data["agent"] = {k: v for k, v in data["agent"].items() if k != "start"}
    return expand_area(data)


def with_area(scenario: Any, path: str | Path) -> dict[str, Any]:
    """``scenario``'s settings moved onto the site in ``path`` (``dcee run --scenario X --area
    FILE``): its volume, start and release location come from the site (the file's start and
    source Points), everything else is kept."""
    data = scenario.model_dump()
    data.pop("volume")
    world = {k: v for k, v in data.get("world", {}).items() if k not in ("frame", "area")}
    data["world"] = {**world, "area": str(Path(path).expanduser().resolve())}
    data["truth"] = {k: v for k, v in data["truth"].items() if k not in ("x", "y", "z")}
    data["agent"] = {k: v for k, v in data["agent"].items() if k != "start"}
    data["name"] = f"{scenario.name}@{Path(path).stem}"
    return expand_area(data)


__all__ = [
    "MIN_CEILING",
    "SITES",
    "area_configuration",
    "expand_area",
    "packaged_site",
    "with_area",
]
