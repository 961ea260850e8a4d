"""ROS 2 bags without ROS (``rosbags``, pure Python): writing the topics a search exchanges
(MCAP) and reading them back as time-ordered events for ``dcee replay``."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

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

    def close(self) -> None:
        self._writer.close()


@dataclass(frozen=True)
class BagEvent:
    """One recorded message: ``t`` s (the pose's header stamp; for readings and goals, the
    time the recorder received them), ``kind`` ("pose", "reading" or "goal") and ``value``:
    (x, y, heading, v, omega) for a pose, the sensor value for a reading, (x, y, z) for a
    goal."""

    t: float
    kind: str
    value: Any


def _yaw(q: Any) -> float:
    """Yaw (rad, counter-clockwise from +x) of a geometry_msgs quaternion."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _stamp(header: Any, fallback: float) -> float:
    t = header.stamp.sec + header.stamp.nanosec * 1e-9
    return t if t > 0 else fallback


def read_events(path: str | Path, topics: dict[str, str] | None = None) -> list[BagEvent]:
    """The poses (nav_msgs/Odometry), readings (std_msgs/Float32) and goals
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
                events.extend(_event(by_topic[conn.topic], msg, log_ns * 1e-9))
    except DceeInputError:
        raise
    except Exception as exc:
        raise DceeInputError("bag", f"cannot read {path} as a ROS 2 bag ({exc})") from None
    kinds = {e.kind for e in events}
    for kind in ("pose", "reading", "goal"):
        if kind not in kinds:
            topic = names["concentration" if kind == "reading" else kind]
            raise DceeInputError("bag", f"{path} has no {kind} messages on topic {topic!r}")
    order = {"pose": 0, "reading": 1, "goal": 2}
    events.sort(key=lambda e: (e.t, order[e.kind]))
    return events


def _event(kind: str, msg: Any, log_t: float) -> Iterator[BagEvent]:
    if kind == "concentration":
        yield BagEvent(log_t, "reading", float(msg.data))
    elif kind == "pose":
        p = msg.pose.pose
        twist = getattr(msg, "twist", None)
        v = twist.twist.linear.x if twist is not None else 0.0
        w = twist.twist.angular.z if twist is not None else 0.0
        yield BagEvent(
            _stamp(msg.header, log_t),
            "pose",
            (p.position.x, p.position.y, _yaw(p.orientation), v, w),
        )
    elif kind == "goal":
        p = msg.pose.position
        yield BagEvent(log_t, "goal", (p.x, p.y, p.z))


__all__ = ["DEFAULT_TOPICS", "BagEvent", "BagWriter", "read_events"]
