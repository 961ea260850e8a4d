"""ROS 2 bags without ROS (``rosbags``, pure Python): writing the topics a search exchanges
(MCAP) and reading them back as time-ordered events for ``dcee replay``."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError

DEFAULT_TOPICS = {"concentration": "concentration", "pose": "odom", "goal": "goal_pose"}
"""The search node's default topic names (ROS parameters ``*_topic`` change them)."""


def _typestore() -> Any:
    try:
        from rosbags.typesys import Stores, get_typestore
    except ImportError:  # pragma: no cover - the extra is missing
        raise DceeInputError(
            "bag", "reading and writing bags needs rosbags: pip install 'dcee[bags]'"
        ) from None
    return get_typestore(Stores.ROS2_KILTED)


class BagWriter:
    """Append serialised (CDR) messages to a new MCAP bag at ``path`` (a folder that must not
    exist yet). :meth:`write` takes the bytes rclpy hands a raw subscription."""

    def __init__(self, path: str | Path) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        self.path = Path(path)
        if self.path.exists():
            raise DceeInputError("record", f"{self.path} exists; choose a new bag folder")
        self._typestore = _typestore()
        self._writer = Writer(self.path, version=9, storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
        self._connections: dict[str, Any] = {}

    def add_topic(self, topic: str, msgtype: str) -> None:
        """Declare ``topic`` carrying ``msgtype`` (e.g. ``"std_msgs/msg/Float32"``)."""
        if topic not in self._connections:
            self._connections[topic] = self._writer.add_connection(
                topic, msgtype, typestore=self._typestore
            )

    def write(self, topic: str, stamp_ns: int, data: bytes) -> None:
        self._writer.write(self._connections[topic], int(stamp_ns), data)

    def write_message(self, topic: str, stamp_ns: int, message: Any, msgtype: str) -> None:
        """Serialise a rosbags message object (``typestore.types[msgtype](...)``) and write it."""
        self.add_topic(topic, msgtype)
        self.write(topic, stamp_ns, bytes(self._typestore.serialize_cdr(message, msgtype)))

    def _header(self, ns: int, frame_id: str) -> Any:
        """A std_msgs/Header stamped ``ns`` (integer nanoseconds) in ``frame_id``."""
        types = self._typestore.types
        return types["std_msgs/msg/Header"](
            stamp=types["builtin_interfaces/msg/Time"](
                sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000
            ),
            frame_id=frame_id,
        )

    def write_search_step(
        self,
        t: float,
        pose: tuple[float, float, float, float, float] | None = None,
        reading: float | None = None,
        goal: tuple[float, float, float] | None = None,
        topics: dict[str, str] | None = None,
        frame_id: str = "map",
    ) -> None:
        """Write, at ``t`` s, a pose (x, y, heading rad, v m/s, ω rad/s) as nav_msgs/Odometry, a
        reading as std_msgs/Float32 and/or a goal (x, y, z) as geometry_msgs/PoseStamped on
        the search's topics (:data:`DEFAULT_TOPICS`): how a log from a robot without ROS
        becomes a bag ``dcee replay`` reads."""
        names = {**DEFAULT_TOPICS, **(topics or {})}
        types = self._typestore.types
        ns = round(t * 1e9)
        header = self._header(ns, frame_id)
        vec3, point = types["geometry_msgs/msg/Vector3"], types["geometry_msgs/msg/Point"]
        quat = types["geometry_msgs/msg/Quaternion"]
        if reading is not None:
            msg = types["std_msgs/msg/Float32"](data=float(reading))
            self.write_message(names["concentration"], ns, msg, "std_msgs/msg/Float32")
        if pose is not None:
            x, y, heading, v, omega = (float(u) for u in pose)
            odom = types["nav_msgs/msg/Odometry"](
                header=header,
                child_frame_id="base_link",
                pose=types["geometry_msgs/msg/PoseWithCovariance"](
                    pose=types["geometry_msgs/msg/Pose"](
                        position=point(x=x, y=y, z=0.0),
                        orientation=quat(*quaternion_of(heading)),
                    ),
                    covariance=np.zeros(36),
                ),
                twist=types["geometry_msgs/msg/TwistWithCovariance"](
                    twist=types["geometry_msgs/msg/Twist"](
                        linear=vec3(x=v, y=0.0, z=0.0), angular=vec3(x=0.0, y=0.0, z=omega)
                    ),
                    covariance=np.zeros(36),
                ),
            )
            self.write_message(names["pose"], ns, odom, "nav_msgs/msg/Odometry")
        if goal is not None:
            gx, gy, gz = (float(u) for u in goal)
            msg = types["geometry_msgs/msg/PoseStamped"](
                header=header,
                pose=types["geometry_msgs/msg/Pose"](
                    position=point(x=gx, y=gy, z=gz), orientation=quat(x=0.0, y=0.0, z=0.0, w=1.0)
                ),
            )
            self.write_message(names["goal"], ns, msg, "geometry_msgs/msg/PoseStamped")

    def write_fix(
        self,
        t: float,
        latitude: float,
        longitude: float,
        topic: str = "fix",
        status: int = 0,
        frame_id: str = "gps",
    ) -> None:
        """Write a GNSS fix (sensor_msgs/NavSatFix; altitude NaN, covariance unknown) at ``t``
        s: how a robot that reports latitude and longitude is logged (:mod:`dcee.robot.gps`)."""
        types = self._typestore.types
        ns = round(t * 1e9)
        header = self._header(ns, frame_id)
        status_type = types["sensor_msgs/msg/NavSatStatus"]
        msg = types["sensor_msgs/msg/NavSatFix"](
            header=header,
            status=status_type(status=status, service=1),
            latitude=float(latitude),
            longitude=float(longitude),
            altitude=math.nan,
            position_covariance=np.zeros(9),
            position_covariance_type=0,
        )
        self.write_message(topic, ns, msg, "sensor_msgs/msg/NavSatFix")

    def close(self) -> None:
        self._writer.close()

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass(frozen=True)
class BagEvent:
    """One recorded message: ``t`` s (the pose's header stamp; for readings and goals, the
    time the recorder received them), ``kind`` ("pose", "reading" or "goal") and ``value``:
    (x, y, heading, v, omega) for a pose, the sensor value for a reading, (x, y, z) for a
    goal."""

    t: float
    kind: str
    value: Any


def yaw_of(q: Any) -> float:
    """Yaw (rad, counter-clockwise from +x) of a geometry_msgs quaternion (rclpy's or rosbags')."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def quaternion_of(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by ``yaw`` rad about +z."""
    return 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)


def stamp_seconds(ns: int) -> float:
    """Seconds of a time in integer nanoseconds, computed as ROS does (sec + nanosec · 1e-9)."""
    return ns // 1_000_000_000 + (ns % 1_000_000_000) * 1e-9


def _stamp(header: Any, fallback: float) -> float:
    t = header.stamp.sec + header.stamp.nanosec * 1e-9
    return t if t > 0 else fallback


def read_events(path: str | Path, topics: dict[str, str] | None = None) -> list[BagEvent]:
    """The poses (nav_msgs/Odometry, or GNSS fixes: sensor_msgs/NavSatFix as events of kind
    "fix", value (latitude, longitude, status)), readings (std_msgs/Float32) and goals
    (geometry_msgs/PoseStamped) of a bag, in time order. ``topics`` maps "concentration",
    "pose" and "goal" to topic names (:data:`DEFAULT_TOPICS`)."""
    try:
        from rosbags.highlevel import AnyReader
    except ImportError:  # pragma: no cover
        raise DceeInputError("bag", "replay needs rosbags: pip install 'dcee[bags]'") from None
    names = {**DEFAULT_TOPICS, **(topics or {})}
    path = Path(path)
    if not path.exists():
        raise DceeInputError("bag", f"no bag at {path}")
    by_topic = {v: k for k, v in names.items()}
    events: list[BagEvent] = []
    try:
        with AnyReader([path], default_typestore=_typestore()) as reader:
            conns = [c for c in reader.connections if c.topic in by_topic]
            for conn, log_ns, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                events.extend(_event(by_topic[conn.topic], msg, stamp_seconds(log_ns)))
    except DceeInputError:
        raise
    except Exception as exc:  # rosbags raises many kinds for a corrupt bag
        first = str(exc).strip().splitlines()[0][:200] if str(exc).strip() else ""
        why = f"{type(exc).__name__}: {first}" if first else type(exc).__name__
        raise DceeInputError("bag", f"cannot read {path} as a ROS 2 bag ({why})") from None
    kinds = {"pose" if e.kind == "fix" else e.kind for e in events}
    for kind in ("pose", "reading", "goal"):
        if kind not in kinds:
            topic = names["concentration" if kind == "reading" else kind]
            raise DceeInputError("bag", f"{path} has no {kind} messages on topic {topic!r}")
    # at equal times: the reading, then the pose it completes a hold with, then the goal the
    # node published in answer (the order the simulated robot and the node produce them)
    order = {"reading": 0, "pose": 1, "fix": 1, "goal": 2}
    events.sort(key=lambda e: (e.t, order[e.kind]))
    return events


def _event(kind: str, msg: Any, log_t: float) -> Iterator[BagEvent]:
    if kind == "concentration":
        yield BagEvent(log_t, "reading", float(msg.data))
    elif kind == "pose" and hasattr(msg, "latitude"):  # sensor_msgs/NavSatFix (dcee.robot.gps)
        yield BagEvent(
            _stamp(msg.header, log_t),
            "fix",
            (float(msg.latitude), float(msg.longitude), int(msg.status.status)),
        )
    elif kind == "pose":
        p = msg.pose.pose
        twist = getattr(msg, "twist", None)
        v = twist.twist.linear.x if twist is not None else 0.0
        w = twist.twist.angular.z if twist is not None else 0.0
        yield BagEvent(
            _stamp(msg.header, log_t),
            "pose",
            (p.position.x, p.position.y, yaw_of(p.orientation), v, w),
        )
    elif kind == "goal":
        p = msg.pose.position
        yield BagEvent(log_t, "goal", (p.x, p.y, p.z))


__all__ = [
    "DEFAULT_TOPICS",
    "BagEvent",
    "BagWriter",
    "quaternion_of",
    "read_events",
    "stamp_seconds",
    "yaw_of",
]
