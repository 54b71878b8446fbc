"""A differential-drive robot that integrates velocity commands on a frictionless plane.

This is the simulated body of a TurtleBot3 burger: it accepts ``cmd_vel``-style
commands ``(v, w)`` (forward speed in m/s, turn rate in rad/s), clamps them to the
robot's speed limits, lets its actual velocity approach the command no faster than
the acceleration limits allow, and then moves along the exact circular arc that
constant ``(v, w)`` describes over the time step. Nothing here knows about maps or
obstacles: refusing to move into a wall is :class:`navseq.sim.world.SimWorld`'s job.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from navseq.geometry import Pose2D, normalize_angle


@dataclass(frozen=True)
class DiffDriveLimits:
    """Speed and acceleration limits (TurtleBot3 burger defaults, ROBOTIS e-Manual).

    ``max_v`` bounds the forward speed in both directions, ``max_w`` the turn rate;
    ``acc_v`` (m/s²) and ``acc_w`` (rad/s²) bound how fast either may change.
    """

    max_v: float = 0.22
    max_w: float = 2.75
    acc_v: float = 2.5
    acc_w: float = 3.2


def approach(current: float, target: float, max_change: float) -> float:
    """``target`` if it is within ``max_change`` of ``current``, else one step toward it."""
    if target > current + max_change:
        return current + max_change
    if target < current - max_change:
        return current - max_change
    return target


def clamp(value: float, limit: float) -> float:
    """``value`` limited to ``[-limit, limit]``."""
    return limit if value > limit else -limit if value < -limit else value


def next_velocity(
    limits: DiffDriveLimits, v: float, w: float, cmd_v: float, cmd_w: float, dt: float
) -> tuple[float, float]:
    """The velocity a robot at ``(v, w)`` has during a step commanded ``(cmd_v, cmd_w)``."""
    new_v = approach(v, clamp(cmd_v, limits.max_v), limits.acc_v * dt)
    new_w = approach(w, clamp(cmd_w, limits.max_w), limits.acc_w * dt)
    return new_v, new_w


def wrap_angle(angle: float) -> float:
    """``angle`` wrapped to [-pi, pi); left bit-exact when it already is in range."""
    return angle if -math.pi <= angle < math.pi else normalize_angle(angle)


def integrate_arc(x: float, y: float, yaw: float, v: float, w: float, dt: float) -> Pose2D:
    """The pose reached from ``(x, y, yaw)`` moving at constant ``(v, w)`` for ``dt`` seconds.

    The arc's chord has length ``v * dt * sinc(w * dt / 2)`` and points along the mean
    heading. Written this way instead of ``v / w * (sin(yaw + w dt) - sin(yaw))`` it stays
    exact for turn rates near zero, where the radius explodes and the difference of sines
    cancels catastrophically.
    """
    turn = w * dt
    half = 0.5 * turn
    sinc = math.sin(half) / half if half != 0.0 else 1.0
    chord = v * dt * sinc
    heading = yaw + half
    return Pose2D(
        x + chord * math.cos(heading), y + chord * math.sin(heading), wrap_angle(yaw + turn)
    )


class DiffDriveRobot:
    """A differential-drive robot body: pose and current velocity, moved by :meth:`step`."""

    def __init__(self, pose: Pose2D, limits: DiffDriveLimits | None = None) -> None:
        self.limits = limits if limits is not None else DiffDriveLimits()
        self.pose = Pose2D(pose.x, pose.y, wrap_angle(pose.yaw))
        self.v = 0.0
        self.w = 0.0

    def predict(self, cmd_v: float, cmd_w: float, dt: float) -> tuple[Pose2D, float, float]:
        """Pose and velocity after one step commanded ``(cmd_v, cmd_w)``, without moving."""
        v, w = next_velocity(self.limits, self.v, self.w, cmd_v, cmd_w, dt)
        pose = self.pose
        return integrate_arc(pose.x, pose.y, pose.yaw, v, w, dt), v, w

    def step(self, cmd_v: float, cmd_w: float, dt: float) -> Pose2D:
        """Apply a command for ``dt`` seconds; returns the new pose."""
        self.pose, self.v, self.w = self.predict(cmd_v, cmd_w, dt)
        return self.pose

    def stop(self) -> None:
        """Halt at once (a bumper hit: the velocity drops to zero, the pose stays)."""
        self.v = 0.0
        self.w = 0.0

    def teleport(self, pose: Pose2D) -> None:
        """Place the robot at ``pose``, at rest (RViz's "2D Pose Estimate")."""
        self.pose = Pose2D(pose.x, pose.y, wrap_angle(pose.yaw))
        self.v = 0.0
        self.w = 0.0
