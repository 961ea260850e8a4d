"""Positions from GNSS fixes (``sensor_msgs/NavSatFix``) in a site's local frame: what the
search node (``pose_type = "navsatfix"``) and ``dcee replay`` (a bag whose pose topic carries
NavSatFix) do with a robot that reports latitude and longitude.

A fix becomes a :class:`~dcee.robot.cycle.Pose` in the scenario's local frame
(:mod:`dcee.geo.frame`, ``world.frame``). A fix carries no heading or speed: they are taken from
successive fixes (the course over ground and the distance over the time between them), the
heading kept while the robot moves less than :data:`COURSE_MIN_STEP` between two fixes (a
heading from a few centimetres of motion is noise). The cycle's "settled" test then reads the
speed the fixes show: a receiver whose fixes wander at rest by more than ``settle_speed`` × the
interval needs odometry for the speeds (give ``pose_type = "odometry"`` in the site's frame) or a
larger ``settle_speed``. A fix the receiver marks as none (``status.status`` = -1, NO_FIX) or
with a latitude or longitude that is not finite is dropped; an unknown status (-2, the message's
default since ROS 2 Jazzy) is taken as a fix.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from dcee.errors import DceeInputError
from dcee.robot.cycle import Pose

NO_FIX = -1
"""``sensor_msgs/NavSatStatus.STATUS_NO_FIX``."""
COURSE_MIN_STEP = 0.05
"""m: the least motion between two fixes that updates the heading (the course over ground)."""


@dataclass
class FixToPose:
    """Turns fixes into poses in ``frame`` (a :class:`dcee.geo.frame.LocalFrame`)."""

    frame: object
    _last: Pose | None = field(default=None, init=False)
    dropped: int = field(default=0, init=False)

    @classmethod
    def for_scenario(cls, scenario: object, field_name: str) -> FixToPose:
        """The converter of ``scenario``'s map; refused where it has none."""
        frame = getattr(getattr(scenario, "world", None), "frame", None)
        if frame is None:
            raise DceeInputError(
                field_name,
                "GNSS fixes (sensor_msgs/NavSatFix) need a scenario on a map in geographic "
                "coordinates (world.area, docs/guide/on-a-map.md) to place them",
            )
        return cls(frame.local_frame())

    def pose(self, t: float, latitude: float, longitude: float, status: int = 0) -> Pose | None:
        """The pose of a fix at ``t`` s, or None (no fix; a time not after the last fix)."""
        if status == NO_FIX or not (math.isfinite(latitude) and math.isfinite(longitude)):
            self.dropped += 1
            return None
        x, y = self.frame.to_local(np.array([longitude]), np.array([latitude]))  # type: ignore[attr-defined]
        x0, y0 = float(x[0]), float(y[0])
        last = self._last
        if last is None:
            pose = Pose(t, x0, y0)
        else:
            dt = t - last.t
            if dt <= 0:
                self.dropped += 1
                return None
            step = math.hypot(x0 - last.x, y0 - last.y)
            heading = (
                math.atan2(y0 - last.y, x0 - last.x) if step >= COURSE_MIN_STEP else last.heading
            )
            turn = math.remainder(heading - last.heading, 2.0 * math.pi)
            pose = Pose(t, x0, y0, heading, step / dt, turn / dt)
        self._last = pose
        return pose


__all__ = ["COURSE_MIN_STEP", "NO_FIX", "FixToPose"]
