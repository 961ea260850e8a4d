"""The local metric frame of a site given in geographic coordinates.

dcee searches in a local frame, x east and y north in metres. For a site given as longitude and
latitude (WGS 84) the frame is a **transverse Mercator projection centred on the site**
(``+proj=tmerc`` with its central meridian and origin latitude at the centre of the area's
bounding box, scale 1 there, on the WGS 84 ellipsoid), shifted so that the south-west corner of
the area's bounding box is (0, 0). Why this one and not a tangent plane (ENU):

* it is conformal: angles are kept, so a wind bearing, a heading and a crosswind offset mean
  the same in both frames; its grid north differs from true north by the meridian convergence
  γ ≈ (d / R) tan φ at d east or west of the central meridian: zero on it, 0.009° at 1 km at
  latitude 45°, 0.05° at 80° (far below a wind vane's error);
* its scale error grows as k − 1 ≈ d² / (2 R²) with the distance d from the central meridian
  (R ≈ 6,371 km): 1.2e-8 at 1 km, 1.2e-6 at 10 km. :data:`MAX_EXTENT` bounds an area so that
  every local distance is within 1e-5 of the true one (1 cm per km, well below a GNSS fix's
  error);
* an ENU tangent plane drops away from the ground as d² / (2 R) (8 cm at 1 km), which a
  horizontal search frame would have to absorb into its heights.

Heights are metres above the ground, never ellipsoidal (a GeoJSON position's third value is
ellipsoidal height, RFC 7946 §3.1.1, which a site plan rarely knows): dcee writes them as a
property, ``height_m``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from dcee.errors import DceeInputError

EARTH_RADIUS = 6_371_000.0
"""m: the mean Earth radius, for the scale-error bounds below."""
MAX_SCALE_ERROR = 1e-5
"""The largest relative error of a local distance the frame may make (1 cm per km)."""
MAX_EXTENT = 2.0 * EARTH_RADIUS * math.sqrt(2.0 * MAX_SCALE_ERROR)
"""m (about 57 km): the widest area one frame serves within :data:`MAX_SCALE_ERROR`; each point
lies at most half of it from the central meridian."""


def require_geo() -> None:
    """Refuse in one line where the ``geo`` extra (pyproj, shapely) is missing."""
    try:
        import pyproj  # noqa: F401
        import shapely  # noqa: F401
    except ImportError:  # pragma: no cover - the extra is installed in CI
        raise DceeInputError(
            "area",
            "maps in geographic coordinates need pyproj and shapely: pip install 'dcee[geo]'",
        ) from None


def _pyproj():  # an optional dependency: the ``geo`` extra
    require_geo()
    import pyproj

    return pyproj


@dataclass(frozen=True)
class LocalFrame:
    """Transverse Mercator about (``latitude``, ``longitude``) degrees, then shifted by
    (``x0``, ``y0``) m: local (x, y) = projected (E, N) + (x0, y0)."""

    latitude: float
    longitude: float
    x0: float = 0.0
    y0: float = 0.0

    def __post_init__(self) -> None:
        if not (-90.0 < self.latitude < 90.0 and -180.0 <= self.longitude <= 180.0):
            raise DceeInputError(
                "world.frame",
                f"centre ({self.latitude:g}, {self.longitude:g}) must have latitude in (-90, 90) "
                "and longitude in [-180, 180]",
            )

    @property
    def proj(self) -> str:
        """The PROJ string of the projection (before the shift)."""
        return (
            f"+proj=tmerc +lat_0={float(self.latitude)!r} +lon_0={float(self.longitude)!r} +k_0=1 "
            "+x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"
        )

    @cached_property
    def _forward(self):  # type: ignore[no-untyped-def]
        pyproj = _pyproj()
        return pyproj.Transformer.from_crs("EPSG:4326", pyproj.CRS(self.proj), always_xy=True)

    def to_local(self, lon: np.ndarray, lat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Degrees (K,) → local (x, y) m (K,)."""
        e, n = self._forward.transform(np.asarray(lon, float), np.asarray(lat, float))
        return np.asarray(e) + self.x0, np.asarray(n) + self.y0

    def to_geo(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Local (x, y) m (K,) → (longitude, latitude) degrees (K,)."""
        from pyproj.enums import TransformDirection

        lon, lat = self._forward.transform(
            np.asarray(x, float) - self.x0,
            np.asarray(y, float) - self.y0,
            direction=TransformDirection.INVERSE,
        )
        return np.asarray(lon), np.asarray(lat)

    def scale_error(self, half_width: float) -> float:
        """The largest relative error of a local distance at ``half_width`` m from the central
        meridian (k − 1 ≈ d² / 2R²)."""
        return half_width**2 / (2.0 * EARTH_RADIUS**2)

    def describe(self, half_width: float) -> str:
        """One line for reports: the projection and its error over the area."""
        return (
            f"transverse Mercator about {self.latitude:.6f}°, {self.longitude:.6f}° (WGS 84), "
            f"origin shifted by ({self.x0:.2f}, {self.y0:.2f}) m; scale error at most "
            f"{self.scale_error(half_width):.1e} over the area"
        )


@lru_cache(maxsize=64)
def shared_frame(latitude: float, longitude: float, x0: float = 0.0, y0: float = 0.0) -> LocalFrame:
    """The :class:`LocalFrame` of these parameters, one instance per distinct frame (it is
    immutable): its pyproj transformer, built on first use, takes about 8 ms, which a caller
    converting one fix at a time would otherwise pay per call."""
    return LocalFrame(latitude, longitude, x0, y0)


def frame_for_bounds(lon_min: float, lat_min: float, lon_max: float, lat_max: float) -> LocalFrame:
    """The frame centred on a bounding box (degrees) with its south-west corner at (0, 0)
    (rounded to the centimetre: the shift is part of the frame's record)."""
    centre = LocalFrame(
        round(float(lat_min + lat_max) / 2.0, 7), round(float(lon_min + lon_max) / 2.0, 7), 0.0, 0.0
    )
    corners_x, corners_y = centre.to_local(
        np.array([lon_min, lon_min, lon_max, lon_max]),
        np.array([lat_min, lat_max, lat_min, lat_max]),
    )
    x0 = -math.floor(float(np.min(corners_x)) * 100.0) / 100.0
    y0 = -math.floor(float(np.min(corners_y)) * 100.0) / 100.0
    return LocalFrame(centre.latitude, centre.longitude, x0, y0)


__all__ = ["MAX_EXTENT", "MAX_SCALE_ERROR", "LocalFrame", "frame_for_bounds", "require_geo"]
