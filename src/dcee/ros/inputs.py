"""What the search node does with its inputs (a mixin of :class:`dcee.ros.node.SearchNode`):
readings, the wind, a map, and the robot's pose as odometry, a pose with covariance or a GNSS
fix. Every attribute it reads (``cycle``, ``scenario``, the lock) is the node's; each handler
runs guarded (:meth:`SearchNode._guarded`)."""

from __future__ import annotations

import dataclasses

from geometry_msgs.msg import PoseWithCovarianceStamped, Vector3Stamped
from nav_msgs.msg import OccupancyGrid, Odometry
from sensor_msgs.msg import NavSatFix
from std_msgs.msg import Float32

from dcee.robot.gps import pose_from_fix
from dcee.ros.messages import (
    grid_from_map,
    pose_from_odometry,
    pose_from_pose_cov,
    seconds,
    site_from_map,
)


class NodeInputs:
    """The search node's input handlers (module doc)."""

    def _reading(self, msg: Float32) -> None:
        with self._lock:
            if self.active and self.cycle is not None:
                self.cycle.on_reading(self._now(), float(msg.data))

    def _wind(self, msg: Vector3Stamped) -> None:
        if not self.scenario.anemometer.enabled:
            if not self._wind_warned:
                self._wind_warned = True
                self.get_logger().warning(
                    "wind readings ignored: the scenario has no [anemometer] (enabled = true)"
                )
            return
        t = seconds(msg.header.stamp) or self._now()
        with self._lock:
            if self.active and self.cycle is not None:
                self.cycle.on_wind(t, msg.vector.x, msg.vector.y)

    def _map(self, msg: OccupancyGrid) -> None:
        """Apply an occupancy grid: a map that cannot be used (rotated, not covering the
        search area, malformed) is logged and ignored; the search goes on with the last map."""
        grid = grid_from_map(msg)
        site = site_from_map(grid, self.scenario)
        with self._lock:
            self._map_site = site
            self.map_gas.update(grid)
            searching = self.searcher is not None
            if searching:
                self.searcher.agent = dataclasses.replace(self.searcher.agent, site=site)
        self.maps_received += 1
        info = msg.info
        later = " (the gas model follows it from the next search)" if searching else ""
        self.get_logger().info(
            f"map applied: {info.width} x {info.height} cells of {info.resolution:g} m, "
            f"{int(site.blocked.sum())} of {site.blocked.size} planning cells blocked{later}"
        )

    def _odometry(self, msg: Odometry) -> None:
        self._step(pose_from_odometry(msg, self._now()))

    def _pose_cov(self, msg: PoseWithCovarianceStamped) -> None:
        self._step(pose_from_pose_cov(msg, self._now(), self._last_pose))

    def _fix(self, msg: NavSatFix) -> None:
        t = seconds(msg.header.stamp) or self._now()
        self._step(pose_from_fix(self.map_frame, t, msg.latitude, msg.longitude,
                                 msg.status.status, self._last_pose))  # fmt: skip


__all__ = ["NodeInputs"]
