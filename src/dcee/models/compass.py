"""Wind directions as people read them: compass bearings.

dcee's frame is east-north-up (x east, y north, as ROS's REP 103), and the source term's φ is
the direction the wind comes *from*, counter-clockwise from +x (east), in radians (degrees in
scenario files): the mathematical convention the plume equation is written in
(:mod:`dcee.models.plume`). Meteorologists, anemometers and ROS users give the *meteorological
bearing*: the direction the wind comes from, clockwise from north, in degrees. The two are
mirror images about north-east: bearing = 90° − φ (mod 360), and φ = 90° − bearing, the same map.

Examples: φ = 0 (wind from the east) is bearing 90°; φ = 90° (from the north) is 0°; φ = 180°
(from the west) is 270°; φ = 270° (from the south) is 180°.
"""

from __future__ import annotations

import math

import numpy as np

POINTS = ("N", "NNE", "NE", "ENE", "E", "ESE", "SE", "SSE",
          "S", "SSW", "SW", "WSW", "W", "WNW", "NW", "NNW")  # fmt: skip
"""The 16 points of the compass, clockwise from north."""


def bearing_from_phi(phi_deg: float) -> float:
    """The meteorological bearing (°, clockwise from north, where the wind comes from; in
    [0, 360)) of the wind direction φ (°, counter-clockwise from east, where it comes from)."""
    return (90.0 - phi_deg) % 360.0


def phi_from_bearing(bearing_deg: float) -> float:
    """φ (°, counter-clockwise from east, in [0, 360)) of a meteorological bearing (°): the
    same reflection as :func:`bearing_from_phi`, its own inverse."""
    return bearing_from_phi(bearing_deg)


def compass_point(bearing_deg: float) -> str:
    """The nearest of the 16 compass points to a bearing (°): 0 → "N", 225 → "SW"."""
    return POINTS[round((bearing_deg % 360.0) / 22.5) % 16]


def wind_from_words(phi_deg: float) -> str:
    """How a person says the wind direction φ (°): ``"wind from 270° (W)"``."""
    bearing = round(bearing_from_phi(phi_deg)) % 360
    return f"wind from {bearing:03d}° ({compass_point(bearing)})"


def estimated_bearing(phi_rad: np.ndarray, weights: np.ndarray) -> float:
    """The compass bearing (°, in [0, 360)) of a belief's wind direction: the weighted circular
    mean of φ (radians, one per particle), so that 350° and 10° average to 0°, not 180°."""
    s = float(np.sum(weights * np.sin(phi_rad)))
    c = float(np.sum(weights * np.cos(phi_rad)))
    return bearing_from_phi(math.degrees(math.atan2(s, c)))
