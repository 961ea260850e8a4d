"""A search's answer on a map: ``estimate.geojson`` (RFC 7946) and ``estimate.kml``.

Features of ``estimate.geojson``, every position [longitude, latitude] on WGS 84 (heights above
the ground as the property ``height_m``, never as a third coordinate: RFC 7946 makes that the
height above the ellipsoid, which a search does not know):

* ``estimate`` (Point): the posterior mean of the release, with its local (x, y) in metres;
* ``region_95`` (Polygon): the 95 % credible region of the release's horizontal position
  (:func:`dcee.estimation.summaries.credible_ellipse_boundary`, with the run's region floor);
* ``path`` (LineString): the sensor's positions in order;
* ``reading`` (Point, one per reading): its value, the time (s from the start), the unit, and
  whether it was a detection.

Exterior rings run counter-clockwise (RFC 7946 3.1.6). The KML holds the same, for Google
Earth (heights relative to the ground).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import escape

import numpy as np

from dcee.geo.frame import LocalFrame

COORDINATE_DECIMALS = 8
"""Decimals of a written degree: 1e-8° is about 1 mm, below any position error here."""


@dataclass(frozen=True)
class MapAnswer:
    """What a search answers, in the local frame: ``estimate`` (3,) m, ``region`` (V, 2) m (the
    95 % region's boundary, counter-clockwise), ``path`` (K, 3) m, ``times`` (K,) s,
    ``readings`` (K,) in ``unit``, ``detections`` (K,) bool."""

    estimate: np.ndarray
    region: np.ndarray
    path: np.ndarray
    times: np.ndarray
    readings: np.ndarray
    detections: np.ndarray
    unit: str = "g/m3"
    name: str = "dcee search"


def _lonlat(frame: LocalFrame, xy: np.ndarray) -> list[list[float]]:
    lon, lat = frame.to_geo(xy[:, 0], xy[:, 1])
    return [
        [round(float(a), COORDINATE_DECIMALS), round(float(b), COORDINATE_DECIMALS)]
        for a, b in zip(np.atleast_1d(lon), np.atleast_1d(lat), strict=True)
    ]


def estimate_geojson(frame: LocalFrame, answer: MapAnswer, extra: dict[str, Any]) -> dict:
    """The FeatureCollection of ``answer`` (module doc); ``extra`` goes into the estimate's
    properties (the scenario, the code version)."""
    est = np.asarray(answer.estimate, dtype=np.float64)
    ring = _lonlat(frame, np.asarray(answer.region, dtype=np.float64))
    point = _lonlat(frame, est[None, :2])[0]
    features: list[dict[str, Any]] = [
        {
            "type": "Feature",
            "properties": {
                "kind": "estimate",
                "height_m": round(float(est[2]), 3),
                "local_x_m": round(float(est[0]), 3),
                "local_y_m": round(float(est[1]), 3),
                **extra,
            },
            "geometry": {"type": "Point", "coordinates": point},
        },
        {
            "type": "Feature",
            "properties": {"kind": "region_95", "level": 0.95},
            "geometry": {"type": "Polygon", "coordinates": [[*ring, ring[0]]]},
        },
    ]
    path = np.asarray(answer.path, dtype=np.float64)
    positions = _lonlat(frame, path[:, :2])
    if len(positions) >= 2:
        features.append(
            {
                "type": "Feature",
                "properties": {
                    "kind": "path",
                    "height_m": [round(float(z), 3) for z in path[:, 2]],
                },
                "geometry": {"type": "LineString", "coordinates": positions},
            }
        )
    for k, position in enumerate(positions):
        features.append(
            {
                "type": "Feature",
                "properties": {
                    "kind": "reading",
                    "value": float(answer.readings[k]),
                    "unit": answer.unit,
                    "time_s": round(float(answer.times[k]), 3),
                    "detection": bool(answer.detections[k]),
                    "height_m": round(float(path[k, 2]), 3),
                },
                "geometry": {"type": "Point", "coordinates": position},
            }
        )
    return {"type": "FeatureCollection", "features": features}


def estimate_kml(frame: LocalFrame, answer: MapAnswer) -> str:
    """The same answer as a KML 2.2 document (heights relative to the ground)."""
    est = np.asarray(answer.estimate, dtype=np.float64)
    (lon, lat) = _lonlat(frame, est[None, :2])[0]
    ring = _lonlat(frame, np.asarray(answer.region, dtype=np.float64))
    path = np.asarray(answer.path, dtype=np.float64)
    track = _lonlat(frame, path[:, :2])

    def coords(points: list[list[float]], heights: np.ndarray | None = None) -> str:
        z = np.zeros(len(points)) if heights is None else heights
        return " ".join(f"{a},{b},{h:.2f}" for (a, b), h in zip(points, z, strict=True))

    readings = "\n".join(
        f"<Placemark><name>{answer.readings[k]:.3g} {escape(answer.unit)}</name>"
        f"<description>t = {answer.times[k]:.1f} s"
        f"{', detection' if answer.detections[k] else ''}</description>"
        f"<Point><altitudeMode>relativeToGround</altitudeMode>"
        f"<coordinates>{coords([p], path[k : k + 1, 2])}</coordinates></Point></Placemark>"
        for k, p in enumerate(track)
    )
    ground = "<altitudeMode>relativeToGround</altitudeMode>"
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<kml xmlns="http://www.opengis.net/kml/2.2">
<Document><name>{escape(answer.name)}</name>
<Placemark><name>estimated release</name>
<description>{est[2]:.2f} m above the ground; local ({est[0]:.2f}, {est[1]:.2f}) m</description>
<Point>{ground}<coordinates>{lon},{lat},{est[2]:.2f}</coordinates></Point></Placemark>
<Placemark><name>95 % region</name><Polygon><outerBoundaryIs><LinearRing>
<coordinates>{coords([*ring, ring[0]])}</coordinates>
</LinearRing></outerBoundaryIs></Polygon></Placemark>
<Placemark><name>path</name><LineString>{ground}
<coordinates>{coords(track, path[:, 2])}</coordinates></LineString></Placemark>
<Folder><name>readings</name>
{readings}
</Folder>
</Document>
</kml>
"""


__all__ = ["COORDINATE_DECIMALS", "MapAnswer", "estimate_geojson", "estimate_kml"]
