"""Motion below the planner: how a robot gets to the waypoint the planner chose, and how long
that takes.

The planner chooses among the :class:`~dcee.models.agent.GridAgent`'s moves (the paper's
``p_{k+1} = p_k + u_k``); a *motion model* turns the chosen waypoint into a drive: the time it
takes and the pose where the robot settles. Two models are registered by name
(``agent.model`` in a scenario):

- ``grid``: the paper's idealisation, every move takes ``step / speed`` seconds and ends exactly
  on the waypoint (what every study before the robot issue used; bit-identical to it);
- ``unicycle``: a differential-drive robot (velocity, acceleration, turn-rate and turn-acceleration
  limits) following the straight segment to the waypoint with pure pursuit, turning in place
  first when the waypoint lies far off its heading, and braking to settle inside a tolerance.

A new model is a :class:`MotionModel` subclass decorated with :func:`register_motion`; nothing
else is edited. Poses are (x, y, heading) with the heading in radians counter-clockwise from +x.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from dcee.errors import DceeInputError


@dataclass(frozen=True)
class Travel:
    """The outcome of one drive: ``duration`` s from leaving to settling, the settled ``pose``
    (x, y, heading rad), whether it ``arrived`` inside the tolerance (False: stopped by the
    time limit), and the ``path`` (n, 4) of (t, x, y, heading) samples, t from the drive's start
    (the start and the settled pose included)."""

    duration: float
    pose: tuple[float, float, float]
    arrived: bool
    path: np.ndarray


@dataclass(frozen=True)
class UnicycleState:
    """Pose (x, y m; heading rad) and speeds (v m/s forward, omega rad/s) of a unicycle."""

    x: float
    y: float
    heading: float = 0.0
    v: float = 0.0
    omega: float = 0.0


@dataclass(frozen=True)
class Drive:
    """A drive along the straight segment from (sx, sy) to the goal (gx, gy), m."""

    sx: float
    sy: float
    gx: float
    gy: float

    @property
    def length(self) -> float:
        return math.hypot(self.gx - self.sx, self.gy - self.sy)

    @property
    def ux(self) -> float:
        return (self.gx - self.sx) / self.length if self.length > 0 else 0.0

    @property
    def uy(self) -> float:
        return (self.gy - self.sy) / self.length if self.length > 0 else 0.0


class MotionModel:
    """How a robot drives from a pose to a waypoint (one base for every motion model)."""

    name: ClassVar[str] = ""

    def travel(self, pose: tuple[float, float, float], goal: np.ndarray) -> Travel:
        """Drive from ``pose`` (x, y, heading rad) to ``goal`` (2,) or (3,) m (z ignored)."""
        raise NotImplementedError

    def shortest_move_time(self, step: float) -> float:
        """A lower bound of the seconds any move of ``step`` m takes (for the budget check)."""
        raise NotImplementedError


MOTION_MODELS: dict[str, type[MotionModel]] = {}
"""Motion models by name (``agent.model``), filled by :func:`register_motion`."""


def register_motion(name: str) -> Callable[[type[MotionModel]], type[MotionModel]]:
    """Class decorator: make a :class:`MotionModel` selectable as ``agent.model = name``."""

    def deco(cls: type[MotionModel]) -> type[MotionModel]:
        cls.name = name
        MOTION_MODELS[name] = cls
        return cls

    return deco


def make_motion(name: str, **params: Any) -> MotionModel:
    """The motion model registered as ``name``, built with ``params``."""
    if name not in MOTION_MODELS:
        raise DceeInputError("agent.model", f"must be one of {sorted(MOTION_MODELS)}, got {name!r}")
    return MOTION_MODELS[name](**params)


def wrap_angle(a: float) -> float:
    """Angle in radians wrapped to [-π, π)."""
    return (a + math.pi) % (2 * math.pi) - math.pi


@register_motion("grid")
@dataclass(frozen=True)
class GridMotion(MotionModel):
    """Every move takes ``step / speed`` seconds and ends exactly on the waypoint, heading along
    the move (the paper's agent; a robot that stays put also spends the step time)."""

    step: float = 2.0
    speed: float = 2.0

    def travel(self, pose: tuple[float, float, float], goal: np.ndarray) -> Travel:
        x, y, heading = pose
        gx, gy = float(goal[0]), float(goal[1])
        if math.hypot(gx - x, gy - y) > 1e-12:
            heading = math.atan2(gy - y, gx - x)
        duration = self.step / self.speed
        path = np.array([[0.0, x, y, pose[2]], [duration, gx, gy, heading]])
        return Travel(duration, (gx, gy, heading), True, path)

    def shortest_move_time(self, step: float) -> float:
        return self.step / self.speed


@register_motion("unicycle")
@dataclass(frozen=True)
class UnicycleMotion(MotionModel):
    """Differential drive (unicycle kinematics ẋ = v cos θ, ẏ = v sin θ, θ̇ = ω) under a
    pure-pursuit path follower, integrated at ``control_dt``.

    Limits: forward speed ``max_speed`` m/s (no reversing), ``max_accel`` m/s², turn rate
    ``max_turn_rate`` rad/s, turn acceleration ``max_turn_accel`` rad/s². The follower tracks the
    straight segment from where the drive starts to the goal with a look-ahead point
    ``lookahead`` m ahead of the robot's projection on it (curvature 2 sin α / L); when the
    goal lies more than ``turn_in_place`` rad off the heading it first turns on the spot. Speeds
    are capped so that the robot can still brake (v ≤ √(2 a d)), which makes it settle on the
    goal instead of orbiting it. Settled: within ``goal_tolerance`` m of the goal, slower than
    ``settle_speed`` m/s and turning slower than ``settle_turn_rate`` rad/s. A drive longer than
    ``time_limit`` s stops where it is (``arrived`` False).
    """

    max_speed: float = 0.2
    max_accel: float = 0.5
    max_turn_rate: float = math.radians(60.0)
    max_turn_accel: float = math.radians(180.0)
    lookahead: float = 0.15
    turn_in_place: float = math.radians(45.0)
    goal_tolerance: float = 0.02
    settle_speed: float = 0.01
    settle_turn_rate: float = math.radians(2.0)
    control_dt: float = 0.05
    time_limit: float = 60.0

    def __post_init__(self) -> None:
        for name in (
            "max_speed",
            "max_accel",
            "max_turn_rate",
            "max_turn_accel",
            "lookahead",
            "goal_tolerance",
            "control_dt",
            "time_limit",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise DceeInputError(f"agent.unicycle.{name}", f"must be > 0, got {value!r}")

    def travel(self, pose: tuple[float, float, float], goal: np.ndarray) -> Travel:
        state = UnicycleState(*(float(v) for v in pose))
        drive = self.start_drive(state, goal)
        samples = [(0.0, state.x, state.y, state.heading)]
        t = 0.0
        arrived = False
        for _ in range(math.ceil(self.time_limit / self.control_dt)):
            if self.settled(state, drive):
                arrived = True
                break
            state = self.step(state, drive)
            t += self.control_dt
            samples.append((t, state.x, state.y, state.heading))
        return Travel(t, (state.x, state.y, state.heading), arrived, np.array(samples))

    def start_drive(self, state: UnicycleState, goal: np.ndarray) -> Drive:
        """The drive from ``state``'s position to ``goal`` (the segment the follower tracks)."""
        return Drive(state.x, state.y, float(goal[0]), float(goal[1]))

    def settled(self, state: UnicycleState, drive: Drive) -> bool:
        """Within the goal tolerance and nearly still (the settle criterion)."""
        return (
            math.hypot(drive.gx - state.x, drive.gy - state.y) <= self.goal_tolerance
            and abs(state.v) <= self.settle_speed
            and abs(state.omega) <= self.settle_turn_rate
        )

    def step(self, state: UnicycleState, drive: Drive | None) -> UnicycleState:
        """One control period: the follower's command (brake to a stop without a drive), the
        acceleration limits, then the exact unicycle arc for constant (v, ω) over ``control_dt``."""
        dt = self.control_dt
        x, y, th = state.x, state.y, state.heading
        if drive is None:
            v_cmd = omega_cmd = 0.0
        else:
            v_cmd, omega_cmd = self._command(x, y, th, drive)
        v = state.v + float(np.clip(v_cmd - state.v, -self.max_accel * dt, self.max_accel * dt))
        omega = state.omega + float(
            np.clip(omega_cmd - state.omega, -self.max_turn_accel * dt, self.max_turn_accel * dt)
        )
        if abs(omega) > 1e-9:
            x += v / omega * (math.sin(th + omega * dt) - math.sin(th))
            y -= v / omega * (math.cos(th + omega * dt) - math.cos(th))
        else:
            x += v * math.cos(th) * dt
            y += v * math.sin(th) * dt
        return UnicycleState(x, y, wrap_angle(th + omega * dt), v, omega)

    def _command(self, x: float, y: float, th: float, drive: Drive) -> tuple[float, float]:
        """(v, ω) commanded by the follower at pose (x, y, th)."""
        gx, gy, sx, sy = drive.gx, drive.gy, drive.sx, drive.sy
        dist = math.hypot(gx - x, gy - y)
        seg_len, ux, uy = drive.length, drive.ux, drive.uy
        if dist <= self.goal_tolerance:
            return 0.0, 0.0  # brake and settle
        bearing = wrap_angle(math.atan2(gy - y, gx - x) - th)
        if abs(bearing) > self.turn_in_place:
            return 0.0, self._turn_rate(bearing)
        # look-ahead point on the segment, ``lookahead`` past the robot's projection on it
        along = (x - sx) * ux + (y - sy) * uy
        s = min(max(along, 0.0) + self.lookahead, seg_len)
        lx, ly = sx + s * ux, sy + s * uy
        if math.hypot(lx - x, ly - y) < 1e-6:
            lx, ly = gx, gy
        alpha = wrap_angle(math.atan2(ly - y, lx - x) - th)
        ld = max(math.hypot(lx - x, ly - y), 1e-6)
        curvature = 2.0 * math.sin(alpha) / ld
        v = min(self.max_speed, math.sqrt(2.0 * self.max_accel * dist))
        omega = v * curvature
        limit = self.max_turn_rate
        if abs(omega) > limit:  # keep the curvature, slow down
            v *= limit / abs(omega)
            omega = math.copysign(limit, omega)
        return v, omega

    def _turn_rate(self, error: float) -> float:
        """Turn rate towards a heading error (rad), capped so the turn can stop on it."""
        cap = min(self.max_turn_rate, math.sqrt(2.0 * self.max_turn_accel * abs(error)))
        return math.copysign(cap, error)

    def shortest_move_time(self, step: float) -> float:
        return step / self.max_speed


__all__ = [
    "MOTION_MODELS",
    "Drive",
    "GridMotion",
    "MotionModel",
    "Travel",
    "UnicycleMotion",
    "UnicycleState",
    "make_motion",
    "register_motion",
    "wrap_angle",
]
