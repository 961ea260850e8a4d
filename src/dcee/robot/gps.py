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
with a latitude or longitude that is not finite is dropped and counted by the cycle like any
impossible pose; an unknown status (-2, the message's default since ROS 2 Jazzy) is taken as a
fix.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from dcee.errors import DceeInputError
from dcee.robot.cycle import Pose

if TYPE_CHECKING:
    from dcee.geo.frame import LocalFrame
    from dcee.scenarios import Scenario

NO_FIX = -1
"""``sensor_msgs/NavSatStatus.STATUS_NO_FIX``."""
COURSE_MIN_STEP = 0.05
"""m: the least motion between two fixes that updates the heading (the course over ground)."""


def map_frame(scenario: Scenario, field_name: str) -> LocalFrame:
    """The local frame of ``scenario``'s map; refused in one line where it has none."""
    if scenario.world.frame is None:
        raise DceeInputError(
            field_name,
            "GNSS fixes (sensor_msgs/NavSatFix) need a scenario on a map in geographic "
            "coordinates (world.area, docs/guide/on-a-map.md) to place them",
        )
    return scenario.world.frame.local_frame()


def pose_from_fix(
    frame: LocalFrame,
    t: float,
    latitude: float,
    longitude: float,
    status: int,
    last: Pose | None,
) -> Pose:
    """The pose of a fix at ``t`` s in ``frame``, its heading and speeds from the ``last``
    accepted pose (as :func:`dcee.ros.messages.pose_from_pose_cov` takes them from successive
    poses). A fix marked NO_FIX, or without a finite latitude and longitude, becomes a pose
    that is not finite, which the cycle drops and counts (``pose not finite``) as it does any
    other impossible pose; so does a stamp not after the last (``pose stamp went backwards``)."""
    if status == NO_FIX:
        return Pose(t, math.nan, math.nan)
    x, y = frame.to_local(np.array([longitude]), np.array([latitude]))
    x0, y0 = float(x[0]), float(y[0])
    if last is None or not t > last.t:
        return Pose(t, x0, y0, last.heading if last is not None else 0.0)
    dt = t - last.t
    step = math.hypot(x0 - last.x, y0 - last.y)
    heading = math.atan2(y0 - last.y, x0 - last.x) if step >= COURSE_MIN_STEP else last.heading
    turn = math.remainder(heading - last.heading, 2.0 * math.pi)
    return Pose(t, x0, y0, heading, step / dt, turn / dt)


__all__ = ["COURSE_MIN_STEP", "NO_FIX", "map_frame", "pose_from_fix"]
