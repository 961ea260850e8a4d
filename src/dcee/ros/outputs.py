"""What the search node publishes and writes (a mixin of :class:`dcee.ros.node.SearchNode`): the
goal, the belief (estimate, covariance, particles, path), feedback, the result, the diagnostics
and the checkpoint. Every
attribute it reads (publishers, ``searcher``, ``cycle``, ``params``) is the node's."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_msgs.msg import String

from dcee.errors import DceeInputError
from dcee.robot.cycle import Pose
from dcee.ros.messages import (
    diagnostic_status,
    estimate_fix,
    estimate_messages,
    goal_message,
    particle_markers,
    path_pose,
    search_result,
)


class NodeOutputs:
    """The search node's outputs (module doc)."""

    def result(self) -> dict[str, Any]:
        """The search's result (the ``dcee/result`` message, :func:`search_result`)."""
        return search_result(self.searcher, len(self.cycle.records), self.finish_reason)

    def _publish_feedback(self, record: dict[str, Any]) -> None:
        est = self.searcher.estimate()
        feedback = {
            "state": self.cycle.state,
            "readings": len(self.cycle.records),
            "mean": [float(v) for v in est.mean],
            "spread": float(est.spread),
            "elapsed": float(record["time"]),
        }
        self.feedback_pub.publish(String(data=json.dumps(feedback)))

    def diagnostics(self) -> DiagnosticStatus:
        """The search's state and its input health (:func:`diagnostic_status`)."""
        return diagnostic_status(
            f"{self.get_name()}: source search",
            self.cycle,
            self.active,
            self.callback_errors,
            self.finish_reason,
            self.checkpoint_error,
            self.checkpoint_failure,
            self._health(),
        )

    def _health(self) -> dict[str, str]:
        """The decision latency over the last goals and the checkpoints not written."""
        out = {"checkpoints not written": str(self.checkpoint_failures)}
        if self.step_latency:
            wall = [w for _, w in self.step_latency]
            out["latency to goal: last, s"] = f"{wall[-1]:.3f}"
            out["latency to goal: max of last 1000, s"] = f"{max(wall):.3f}"
        return out

    def _save_checkpoint(self) -> None:
        """Write the checkpoint; a disk that is full or read-only costs the checkpoint, not the
        search: the failure is logged (throttled), counted and in the diagnostics (WARN), and
        the search goes on; the previous checkpoint stays whole (written atomically)."""
        try:
            self.searcher.save(self.checkpoint)
        except DceeInputError as exc:
            self.checkpoint_failures += 1
            self.checkpoint_failure = exc.message
            self.get_logger().error(
                f"checkpoint not written ({exc.message}); the search goes on",
                throttle_duration_sec=10.0,
            )
        else:
            self.checkpoint_failure = ""

    def _publish_diagnostics(self) -> None:
        msg = DiagnosticArray()
        msg.header.stamp = self._stamp()
        msg.status = [self.diagnostics()]
        self.diagnostics_pub.publish(msg)

    # --- outputs ------------------------------------------------------------------------------

    def _stamp(self) -> Any:
        return self.get_clock().now().to_msg()

    def _publish_goal(self, goal: np.ndarray, pose: Pose) -> None:
        self.goal_pub.publish(goal_message(goal, pose, self.frame_id, self._stamp()))

    def _publish_belief(self, record: dict[str, Any]) -> None:
        est = self.searcher.estimate()
        stamp = self._stamp()
        point, cov = estimate_messages(est.mean, est.cov, self.frame_id, stamp)
        self.estimate_pub.publish(point)
        self.cov_pub.publish(cov)
        if self.fix_pub is not None:  # a site on a map: the estimate in degrees too
            self.fix_pub.publish(estimate_fix(est.mean, est.cov, self.map_frame, stamp))
        n = int(self.params["marker_particles"])
        self.particles_pub.publish(
            particle_markers(self.searcher.filter, self._marker_rng, n, self.frame_id, stamp)
        )
        self.path_msg.header.stamp = stamp
        poses = self.path_msg.poses
        poses.append(path_pose(record, self.frame_id, stamp))
        if len(poses) > PATH_POSES:  # a day's mission: the message would grow without end
            del poses[0]
        self.path_pub.publish(self.path_msg)


PATH_POSES = 1000
"""Readings the ``dcee/path`` message holds: the last 1,000 (every reading's position is in the
``dcee/feedback`` stream and a recorded bag). The whole path made every reading cost more than
the last: in an 8-hour soak the latency from a pose to its goal grew from 10.5 to 26.3 ms
(docs/guide/robot.md)."""

__all__ = ["PATH_POSES", "NodeOutputs"]
