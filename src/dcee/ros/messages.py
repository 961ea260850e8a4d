"""ROS 2 messages to and from dcee's objects, for the search node (:mod:`dcee.ros.node`): poses
from odometry, a site from an occupancy grid, and the goal, estimate, path, particle, result and
diagnostics messages it publishes. Frames are REP-103 ENU; stamps are given by the caller."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import (
    Point,
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
)
from nav_msgs.msg import OccupancyGrid, Odometry
from visualization_msgs.msg import Marker, MarkerArray

from dcee.errors import DceeInputError
from dcee.models.compass import estimated_bearing
from dcee.models.plume import PARAMETER_NAMES
from dcee.models.site import SiteMap, compose_site
from dcee.robot.bag import quaternion_of, yaw_of
from dcee.robot.cycle import Pose, SearchCycle

if TYPE_CHECKING:
    from dcee.scenarios import Scenario
    from dcee.searcher import Searcher

# --- inputs ----------------------------------------------------------------------------------


def seconds(stamp: Any) -> float:
    """A builtin_interfaces/Time as seconds."""
    return stamp.sec + stamp.nanosec * 1e-9


def pose_from_odometry(msg: Odometry, now: float) -> Pose:
    """The robot's pose and speeds from nav_msgs/Odometry (``now`` s when it has no stamp)."""
    p = msg.pose.pose
    return Pose(
        seconds(msg.header.stamp) or now,
        p.position.x,
        p.position.y,
        yaw_of(p.orientation),
        msg.twist.twist.linear.x,
        msg.twist.twist.angular.z,
    )


def pose_from_pose_cov(msg: PoseWithCovarianceStamped, now: float, last: Pose | None) -> Pose:
    """The robot's pose from geometry_msgs/PoseWithCovarianceStamped, its speeds from the
    ``last`` accepted pose (0 without one)."""
    p = msg.pose.pose
    t = seconds(msg.header.stamp) or now
    x, y, yaw = p.position.x, p.position.y, yaw_of(p.orientation)
    v = w = 0.0
    if last is not None and t > last.t and math.isfinite(t - last.t):
        v = math.hypot(x - last.x, y - last.y) / (t - last.t)
        w = math.remainder(yaw - last.heading, 2 * math.pi) / (t - last.t)
    return Pose(t, x, y, yaw, v, w)


def estimate_fix(mean: np.ndarray, cov: np.ndarray, frame: Any, stamp: Any) -> Any:
    """The source estimate on the map (sensor_msgs/NavSatFix): its latitude and longitude
    through the scenario's frame (a :class:`dcee.geo.frame.LocalFrame`), the location covariance
    (m², east-north-up) as a known covariance. The altitude is NaN: NavSatFix's is the height
    above the ellipsoid, which a search does not know (the height above the ground is the z of
    ``dcee/estimate``)."""
    from sensor_msgs.msg import NavSatFix, NavSatStatus

    lon, lat = frame.to_geo(np.array([mean[0]]), np.array([mean[1]]))
    msg = NavSatFix()
    msg.header.stamp, msg.header.frame_id = stamp, "wgs84"
    msg.status.status, msg.status.service = NavSatStatus.STATUS_FIX, 0
    msg.latitude, msg.longitude, msg.altitude = float(lat[0]), float(lon[0]), math.nan
    msg.position_covariance = [float(v) for v in np.asarray(cov, dtype=float)[:3, :3].ravel()]
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_KNOWN
    return msg


def grid_from_map(msg: OccupancyGrid) -> SiteMap:
    """The occupancy grid as it is (occupied and unknown cells blocked); a grid that cannot be
    used (malformed, rotated) raises :class:`DceeInputError`."""
    info = msg.info
    if info.width == 0 or info.height == 0 or len(msg.data) != info.width * info.height:
        raise DceeInputError("map", f"{len(msg.data)} cells for {info.width} x {info.height}")
    if abs(yaw_of(info.origin.orientation)) > 1e-6:
        raise DceeInputError("map", "a rotated map (origin yaw != 0) is not supported")
    occ = np.asarray(msg.data, dtype=float).reshape(info.height, info.width)
    occ = np.where(occ < 0, np.nan, occ / 100.0)
    return SiteMap.from_occupancy(
        occ, (info.origin.position.x, info.origin.position.y), info.resolution, name="map topic"
    )


def site_from_map(msg: OccupancyGrid | SiteMap, scenario: Scenario) -> SiteMap:
    """The site an occupancy grid (a message, or :func:`grid_from_map`'s grid) makes over
    ``scenario``'s search area: its occupied and unknown cells blocked, on top of the
    scenario's own obstacles, zones and map file. A grid that cannot be used (malformed,
    rotated, not covering the area) raises :class:`DceeInputError`."""
    grid = msg if isinstance(msg, SiteMap) else grid_from_map(msg)
    site = compose_site(
        tuple(scenario.volume.low[:2]),
        tuple(scenario.volume.high[:2]),
        maps=[grid],
        resolution=scenario.site_resolution,
        clearance=scenario.world.clearance,
        name="map topic",
    )
    own = scenario.make_site()
    if own is not None:
        site.blocked |= own.blocked
    return site


# --- outputs ---------------------------------------------------------------------------------


def _stamped(msg: Any, frame_id: str, stamp: Any) -> Any:
    msg.header.frame_id = frame_id
    msg.header.stamp = stamp
    return msg


def goal_message(goal: np.ndarray, pose: Pose, frame_id: str, stamp: Any) -> PoseStamped:
    """The next goal (3,) m, facing the move from ``pose`` (what Nav2's bt_navigator takes)."""
    msg = _stamped(PoseStamped(), frame_id, stamp)
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = (float(v) for v in goal)
    q = quaternion_of(math.atan2(goal[1] - pose.y, goal[0] - pose.x))
    o = msg.pose.orientation
    o.x, o.y, o.z, o.w = q
    return msg


def estimate_messages(
    mean: np.ndarray, cov: np.ndarray, frame_id: str, stamp: Any
) -> tuple[PointStamped, PoseWithCovarianceStamped]:
    """The source estimate: its mean (3,) m as a point, and with the location covariance
    (3, 3) m² in the position block of a pose covariance (orientation unknown: 1e9)."""
    point = _stamped(PointStamped(), frame_id, stamp)
    point.point.x, point.point.y, point.point.z = (float(v) for v in mean)
    with_cov = _stamped(PoseWithCovarianceStamped(), frame_id, stamp)
    pos = with_cov.pose.pose.position
    pos.x, pos.y, pos.z = (float(v) for v in mean)
    with_cov.pose.pose.orientation.w = 1.0
    full = np.zeros((6, 6))
    full[:3, :3] = cov
    full[3:, 3:] = np.eye(3) * 1e9
    with_cov.pose.covariance = [float(v) for v in full.ravel()]
    return point, with_cov


def path_pose(record: dict[str, Any], frame_id: str, stamp: Any) -> PoseStamped:
    """Where a reading was taken (a record's x, y, z), for ``dcee/path``."""
    msg = _stamped(PoseStamped(), frame_id, stamp)
    msg.pose.position.x = float(record["x"])
    msg.pose.position.y = float(record["y"])
    msg.pose.position.z = float(record["z"])
    msg.pose.orientation.w = 1.0
    return msg


def particle_markers(
    belief: Any, rng: np.random.Generator, count: int, frame_id: str, stamp: Any
) -> MarkerArray:
    """``count`` source hypotheses drawn from the filter ``belief`` by weight, as points."""
    n = min(int(count), belief.n)
    idx = rng.choice(belief.n, size=n, p=belief.weights)
    marker = _stamped(Marker(), frame_id, stamp)
    marker.ns, marker.id = "dcee_particles", 0
    marker.type, marker.action = Marker.POINTS, Marker.ADD
    marker.scale.x = marker.scale.y = 0.03
    marker.color.r, marker.color.g, marker.color.b, marker.color.a = 0.1, 0.4, 0.9, 0.8
    marker.pose.orientation.w = 1.0
    for x, y, z in belief.source_locations[idx]:
        marker.points.append(Point(x=float(x), y=float(y), z=float(z)))
    return MarkerArray(markers=[marker])


def search_result(searcher: Searcher, readings: int, finish_reason: str) -> dict[str, Any]:
    """A search's result (the ``dcee/result`` message): ``success`` (the source was localised
    or the budget spent with a reading; False when cancelled or failed), ``reason``, the
    estimate's ``mean`` (3,) m and location ``covariance`` (3 × 3) m², ``spread`` m,
    ``readings``, and the believed wind: ``wind_from`` (a compass bearing, °, where it comes
    from, clockwise from north) and ``wind_speed`` m/s; with the count of releases unknown
    also ``estimated_count``, ``count_probabilities`` (P(K), K = 0 …), ``count_switches`` and
    ``estimated_sources`` (each release's mean, m), the mean above being the release the
    search goes after."""
    est = searcher.estimate()
    belief, weights = searcher.filter.theta, searcher.filter.weights
    phi, u = (belief[:, PARAMETER_NAMES.index(k)] for k in ("phi", "u"))
    return {
        "success": finish_reason in ("localised", "budget") and readings > 0,
        "reason": finish_reason,
        "mean": [float(v) for v in est.mean],
        "covariance": [[float(v) for v in row] for row in est.cov],
        "spread": float(est.spread),
        "readings": readings,
        "wind_from": estimated_bearing(phi, weights),
        "wind_speed": float(weights @ u),
        # the count unknown (estimator.max_sources > 1): how many releases, P(K), where each is
        **(counted() if (counted := getattr(searcher.filter, "count_summary", None)) else {}),
    }


def diagnostic_status(
    name: str,
    cycle: SearchCycle | None,
    active: bool,
    callback_errors: int,
    finish_reason: str,
    checkpoint_error: str = "",
    checkpoint_failure: str = "",
    health: dict[str, str] | None = None,
) -> DiagnosticStatus:
    """The search's state and its input health as one DiagnosticStatus: WARN once input
    messages were dropped, ERROR once a callback failed or while a checkpoint file was refused
    (``checkpoint_error``: no search started from it); WARN while checkpoints cannot be written
    (``checkpoint_failure``: the search goes on). ``health``: more key-values (latency)."""
    status = DiagnosticStatus()
    status.name = name
    status.hardware_id = "dcee"
    if cycle is None and checkpoint_error:
        status.level = DiagnosticStatus.ERROR
        status.message = f"checkpoint refused: {checkpoint_error}"
        status.values = [KeyValue(key="state", value="checkpoint refused")]
        return status
    if cycle is None:
        status.level = DiagnosticStatus.OK
        status.message = "configured, no search yet" if active else "inactive"
        status.values = [KeyValue(key="state", value="inactive")]
        return status
    rejected = cycle.rejected
    if callback_errors:
        status.level = DiagnosticStatus.ERROR
        status.message = f"{callback_errors} callback errors (messages ignored)"
    elif checkpoint_failure:
        status.level = DiagnosticStatus.WARN
        status.message = f"checkpoint not written: {checkpoint_failure}"
    elif rejected:
        status.level = DiagnosticStatus.WARN
        status.message = f"{sum(rejected.values())} input messages dropped"
    else:
        status.level = DiagnosticStatus.OK
        status.message = "inputs healthy"
    values = {
        "state": cycle.state,
        "finish_reason": finish_reason,
        "readings used": str(len(cycle.records)),
        "callback errors": str(callback_errors),
        **{f"dropped: {k}": str(v) for k, v in sorted(rejected.items())},
        **(health or {}),
    }
    status.values = [KeyValue(key=k, value=v) for k, v in values.items()]
    return status
