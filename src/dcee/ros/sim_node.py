"""A simulated robot as a ROS 2 node: a unicycle (:class:`dcee.robot.simulated.SimulatedRobot`)
in any dcee truth (isotropic, filament, recording) that drives to ``goal_pose`` and publishes
``/clock`` (simulated time), ``odom`` (nav_msgs/Odometry in the ``frame_id`` frame, child
``base_link``, with the scenario's localisation error) and ``concentration``
(std_msgs/Float32, an instantaneous instrument reading in g/m³) every control step.

Simulated time runs ``speedup`` times faster than the wall clock (a timer fires every
``control_dt / speedup`` s); the other nodes follow it with ``use_sim_time``. A slow callback
elsewhere delays the timer, and simulated time then simply waits: the robot never skips steps.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float32

from dcee.robot.bag import quaternion_of
from dcee.robot.simulated import SimulatedRobot
from dcee.ros.parameters import LATCHED, RELIABLE
from dcee.runs.streams import anemometer_stream
from dcee.scenarios import Scenario


def stamp_of(t: float) -> Any:
    from builtin_interfaces.msg import Time

    ns = round(t * 1e9)  # rounding the whole stamp: t = 96.9999999999 is 97 s, not 96 s
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


class SimRobotNode(Node):
    """Publishes a simulated robot's clock, odometry and readings; follows ``goal_pose``."""

    def __init__(
        self,
        scenario: Scenario,
        seed: int,
        *,
        speedup: float = 10.0,
        frame_id: str = "map",
        context: Any = None,
        truth: Any = None,
        name: str = "dcee_sim_robot",
        paused: bool = False,
    ) -> None:
        super().__init__(name, context=context)
        self.robot = SimulatedRobot(scenario, seed, truth)
        self.frame_id = frame_id
        self.clock_pub = self.create_publisher(Clock, "/clock", 10)
        self.odom_pub = self.create_publisher(Odometry, "odom", RELIABLE)
        self.conc_pub = self.create_publisher(Float32, "concentration", RELIABLE)
        # the anemometer (when the scenario has one): the truth's mean wind with its noise,
        # as the air's velocity in the map frame, at 10 Hz of simulated time
        self.anemometer = scenario.make_anemometer()
        self.wind_pub = self.create_publisher(Vector3Stamped, "wind", RELIABLE)
        self._wind_rng = anemometer_stream(seed)
        self._next_wind = 0.0
        self.wind_messages = 0
        self.create_subscription(PoseStamped, "goal_pose", self._on_goal, LATCHED)
        self.goals = 0
        self._lock = threading.Lock()
        self._stopped = False
        self.paused = paused
        """while True the robot's clock stands still and nothing is published"""
        self.clock_offset = 0.0
        """s added to the robot's time in every stamp and on ``/clock``: lowering it is a clock
        that jumps back (fault injection, ``studies/soak_node.py``)"""
        if not paused:
            self._publish()
        self.timer = self.create_timer(self.robot.control_dt / speedup, self._tick)

    def _on_goal(self, msg: Any) -> None:
        p = msg.pose.position
        self.robot.set_goal(np.array([p.x, p.y, p.z]))
        self.goals += 1

    def _tick(self) -> None:
        with self._lock:
            if self._stopped or self.paused:
                return
            self.robot.step()
            self._publish()

    def stop(self) -> None:
        """Stop the robot's clock: after this returns no tick publishes again (so the context
        can shut down under a spinning executor)."""
        with self._lock:
            self._stopped = True
            self.timer.cancel()

    def _publish(self) -> None:
        r = self.robot
        stamp = stamp_of(r.time + self.clock_offset)
        self.clock_pub.publish(Clock(clock=stamp))
        s = r.odometry()
        odom = Odometry()
        odom.header.stamp = stamp
        odom.header.frame_id = self.frame_id
        odom.child_frame_id = "base_link"
        odom.pose.pose.position.x, odom.pose.pose.position.y = s.x, s.y
        odom.pose.pose.position.z = r.altitude
        o = odom.pose.pose.orientation
        o.x, o.y, o.z, o.w = quaternion_of(s.heading)
        sd = r.scenario.agent.localisation_sd
        cov = np.zeros((6, 6))
        cov[0, 0] = cov[1, 1] = sd**2
        odom.pose.covariance = [float(v) for v in cov.ravel()]
        odom.twist.twist.linear.x = s.v
        odom.twist.twist.angular.z = s.omega
        if self.anemometer is not None and r.time >= self._next_wind - 1e-9:
            self._next_wind = r.time + 0.1
            truth = r.scenario.truth_theta()
            speed, direction = self.anemometer.simulate(truth[4], truth[5], self._wind_rng)
            wind = Vector3Stamped()
            wind.header.stamp = stamp
            wind.header.frame_id = self.frame_id
            # from direction phi: the air moves towards phi + pi
            wind.vector.x = -speed * math.cos(direction)
            wind.vector.y = -speed * math.sin(direction)
            self.wind_pub.publish(wind)
            self.wind_messages += 1
        # the reading first: the search node completes a hold on the pose that follows it
        self.conc_pub.publish(Float32(data=r.sample()))
        self.odom_pub.publish(odom)


__all__ = ["SimRobotNode", "stamp_of"]
