"""A search site in geographic coordinates, read from GeoJSON (RFC 7946).

The file is a ``FeatureCollection`` whose features say what they are:

* **the area** (the fence; exactly one): a ``Polygon`` with the property ``"dcee": "area"``;
  the search stays inside it (its holes, if any, are no-go zones);
* **buildings**: every ``Polygon`` or ``MultiPolygon`` tagged as OpenStreetMap tags one,
  ``"building"`` with any value but ``"no"``, its height from ``"height"`` (metres: ``12``,
  ``"12"``, ``"12 m"``) or else ``"building:levels"`` × :data:`LEVEL_HEIGHT`; a building
  whose height neither gives blocks every agent;
* **no-go zones**: polygons with ``"dcee": "no-go"``;
* optionally **the start** (``Point``, ``"dcee": "start"``, ``"height"`` m above the ground)
  and **the release** a simulation flies against (``Point``, ``"dcee": "source"``,
  ``"height"`` m, and for the simulated truth ``"rate"`` g/s, ``"wind_from"`` a compass bearing
  in degrees, ``"wind_speed"`` m/s).

Other features (roads, names, anything an OpenStreetMap export carries) are ignored.
Positions are [longitude, latitude] on WGS 84, unless the file declares another CRS with
GeoJSON 2008's ``"crs"`` member (``{"type": "name", "properties": {"name": "EPSG:27700"}}``), in
which case they are reprojected. Every problem is one :class:`DceeInputError` naming the
feature and what is allowed.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError

LEVEL_HEIGHT = 3.0
"""m per storey where a building gives ``building:levels`` but no ``height`` (the OpenStreetMap
wiki's rule of thumb for a storey; an industrial hall's storey is often taller, so a map with
real heights should give ``height``)."""
ROLES = ("area", "no-go", "start", "source")
"""The values of the ``dcee`` property."""
FIELD = "area"


@dataclass(frozen=True)
class GeoPolygon:
    """One polygon: ``ring`` (V, 2) [longitude, latitude] degrees, closed (first = last), and
    ``holes``, a tuple of such rings; ``label`` names its feature in messages."""

    label: str
    ring: np.ndarray
    holes: tuple[np.ndarray, ...] = ()


@dataclass(frozen=True)
class Building:
    footprint: GeoPolygon
    height: float | None
    """m above the ground, or None where the map does not say"""


@dataclass(frozen=True)
class GeoPoint:
    label: str
    lon: float
    lat: float
    height: float
    properties: dict[str, Any]


@dataclass(frozen=True)
class GeoSite:
    """What a site file holds (module doc), every position in WGS 84 degrees."""

    path: Path
    area: GeoPolygon
    buildings: tuple[Building, ...]
    no_go: tuple[GeoPolygon, ...]
    start: GeoPoint | None
    source: GeoPoint | None
    attribution: str
    """where the map came from: the collection's ``attribution``, ``copyright`` or ``source``
    member (an OpenStreetMap export carries one), or empty"""


def _label(i: int, props: dict[str, Any]) -> str:
    name = props.get("name") or props.get("@id") or props.get("id")
    role = props.get("dcee") or ("building" if _is_building(props) else "feature")
    return f"features[{i}] ({role}{f' {name!r}' if name else ''})"


def _is_building(props: dict[str, Any]) -> bool:
    value = props.get("building")
    return value is not None and str(value).lower() not in ("no", "false", "0")


def _number(
    value: Any, label: str, what: str, low: float, high: float, unit: str = "metres"
) -> float:
    """A number given as JSON number or as text (of metres: with an optional ``m`` unit)."""
    if isinstance(value, bool):
        value = None
    if isinstance(value, str):
        suffix = r"(?:m|metres|meters)?" if unit == "metres" else ""
        match = re.fullmatch(r"\s*([-+]?\d+(?:\.\d+)?)\s*" + suffix + r"\s*", value)
        value = float(match.group(1)) if match else None
    if not isinstance(value, int | float) or not math.isfinite(value) or not low <= value <= high:
        example = "12 or '12 m'" if unit == "metres" else "3"
        raise DceeInputError(
            label, f"{what} must be a number of {unit} in [{low:g}, {high:g}] (e.g. {example})"
        )
    return float(value)


def _height(props: dict[str, Any], label: str) -> float | None:
    if props.get("height") is not None:
        return _number(props["height"], label, "height", 0.0, 1000.0)
    if props.get("building:levels") is not None:
        levels = _number(props["building:levels"], label, "building:levels", 0, 300, "storeys")
        return LEVEL_HEIGHT * levels
    return None


def _positions(coords: Any, label: str, ring: bool) -> np.ndarray:
    try:
        arr = np.array(coords, dtype=np.float64)
    except (TypeError, ValueError):
        arr = np.zeros((0, 0))
    if arr.ndim != 2 or arr.shape[1] not in (2, 3) or not np.all(np.isfinite(arr)):
        raise DceeInputError(label, "positions must be [longitude, latitude(, height)] numbers")
    if ring:
        if len(arr) < 4:
            raise DceeInputError(label, f"a ring needs at least 4 positions, got {len(arr)}")
        if not np.array_equal(arr[0, :2], arr[-1, :2]):
            raise DceeInputError(
                label, "ring not closed: its last position must repeat its first (RFC 7946 3.1.6)"
            )
    return arr[:, :2]


class _Reprojection:
    """The file's CRS → WGS 84 longitude/latitude, or the identity with a range check."""

    def __init__(self, doc: dict[str, Any]) -> None:
        self.name = None
        crs = doc.get("crs")
        if crs is not None:
            name = (crs.get("properties") or {}).get("name") if isinstance(crs, dict) else None
            if not isinstance(name, str):
                raise DceeInputError(
                    f"{FIELD} crs", 'must be {"type": "name", "properties": {"name": "EPSG:…"}}'
                )
            from pyproj import CRS, Transformer
            from pyproj.exceptions import CRSError

            try:
                source = CRS.from_user_input(name)
            except CRSError:
                raise DceeInputError(f"{FIELD} crs", f"unknown CRS {name!r}") from None
            self.name = name
            self.transformer = Transformer.from_crs(source, "EPSG:4326", always_xy=True)

    def __call__(self, xy: np.ndarray, label: str) -> np.ndarray:
        if self.name is not None:
            lon, lat = self.transformer.transform(xy[:, 0], xy[:, 1])
            out = np.stack([lon, lat], axis=1)
            if not np.all(np.isfinite(out)):
                raise DceeInputError(label, f"positions outside the domain of {self.name}")
            return out
        bad = (np.abs(xy[:, 0]) > 180.0) | (np.abs(xy[:, 1]) > 90.0)
        if np.any(bad):
            lon, lat = xy[np.argmax(bad)]
            if abs(lon) <= 90.0 and abs(lat) <= 180.0:
                hint = "latitude and longitude swapped? positions are [longitude, latitude]"
            else:
                hint = (
                    "these are not degrees: declare the file's CRS (a 'crs' member naming e.g. "
                    "EPSG:27700) or reproject it to WGS 84"
                )
            raise DceeInputError(
                label,
                f"position ({lon:g}, {lat:g}) is outside longitude ±180, latitude ±90: {hint}",
            )
        return xy


def _polygons(geometry: dict[str, Any], label: str, project: _Reprojection) -> list[GeoPolygon]:
    kind = geometry.get("type")
    if kind == "Polygon":
        parts = [geometry.get("coordinates")]
    elif kind == "MultiPolygon":
        parts = geometry.get("coordinates") or []
    else:
        raise DceeInputError(label, f"must be a Polygon or MultiPolygon, got {kind}")
    out = []
    for part in parts:
        if not isinstance(part, list) or not part:
            raise DceeInputError(label, "a polygon needs at least its outer ring")
        rings = [project(_positions(r, label, ring=True), label) for r in part]
        polygon = GeoPolygon(label, rings[0], tuple(rings[1:]))
        _check_simple(polygon)
        out.append(polygon)
    return out


def _check_simple(polygon: GeoPolygon) -> None:
    from shapely import Polygon
    from shapely.validation import explain_validity

    shape = Polygon(polygon.ring, list(polygon.holes))
    if not shape.is_valid:
        why = explain_validity(shape)
        raise DceeInputError(
            polygon.label, f"not a valid polygon ({why}): a ring may not cross itself"
        )
    if shape.area <= 0.0:
        raise DceeInputError(polygon.label, "the polygon has no area")


def _point(
    geometry: dict[str, Any], props: dict[str, Any], label: str, project: _Reprojection
) -> GeoPoint:
    if geometry.get("type") != "Point":
        raise DceeInputError(label, f"must be a Point, got {geometry.get('type')}")
    xy = project(_positions([geometry.get("coordinates")], label, ring=False), label)[0]
    height = _number(props.get("height", 0.0), label, "height", 0.0, 1000.0)
    return GeoPoint(label, float(xy[0]), float(xy[1]), height, dict(props))


def read_site(path: str | Path) -> GeoSite:
    """The site in ``path`` (module doc); one-line errors naming the feature."""
    from dcee.geo.frame import require_geo
    from dcee.limits import read_text

    require_geo()
    path = Path(path).expanduser()
    if not path.is_file():
        raise DceeInputError(FIELD, f"no such file {str(path)!r}")
    try:
        doc = json.loads(read_text(path, FIELD))
    except json.JSONDecodeError as exc:
        raise DceeInputError(FIELD, f"{path.name} is not JSON: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DceeInputError(FIELD, f"cannot read {path}: {exc}") from None
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        raise DceeInputError(FIELD, f"{path.name} must be a GeoJSON FeatureCollection")
    features = doc.get("features")
    if not isinstance(features, list):
        raise DceeInputError(FIELD, f"{path.name}: 'features' must be a list")
    project = _Reprojection(doc)
    areas: list[GeoPolygon] = []
    buildings: list[Building] = []
    no_go: list[GeoPolygon] = []
    points: dict[str, GeoPoint] = {}
    for i, feature in enumerate(features):
        if not isinstance(feature, dict) or feature.get("type") != "Feature":
            raise DceeInputError(f"features[{i}]", "must be a GeoJSON Feature")
        props = feature.get("properties") or {}
        geometry = feature.get("geometry") or {}
        if not isinstance(props, dict) or not isinstance(geometry, dict):
            raise DceeInputError(f"features[{i}]", "properties and geometry must be objects")
        label = _label(i, props)
        role = props.get("dcee")
        if role is not None and role not in ROLES:
            raise DceeInputError(label, f"'dcee' must be one of {', '.join(ROLES)}, got {role!r}")
        if role == "area":
            found = _polygons(geometry, label, project)
            if len(found) != 1:
                raise DceeInputError(label, "the area must be one Polygon")
            areas += found
        elif role == "no-go":
            no_go += _polygons(geometry, label, project)
        elif role in ("start", "source"):
            if role in points:
                raise DceeInputError(label, f"a second {role}; give one")
            points[role] = _point(geometry, props, label, project)
        elif _is_building(props) and geometry.get("type") in ("Polygon", "MultiPolygon"):
            height = _height(props, label)
            buildings += [Building(p, height) for p in _polygons(geometry, label, project)]
    if len(areas) != 1:
        raise DceeInputError(
            FIELD,
            f'{path.name} must have exactly one Polygon with "dcee": "area" (the search '
            f"area), found {len(areas)}",
        )
    attribution = next(
        (str(doc[k]) for k in ("attribution", "copyright", "source") if doc.get(k)), ""
    )
    return GeoSite(
        path.resolve(),
        areas[0],
        tuple(buildings),
        tuple(no_go),
        points.get("start"),
        points.get("source"),
        attribution,
    )


__all__ = ["LEVEL_HEIGHT", "Building", "GeoPoint", "GeoPolygon", "GeoSite", "read_site"]
