"""Nav2's velocity chain between the controller and the robot, without ROS.

A default Jazzy bringup does not let the controller drive the robot directly:

``controller_server`` / ``behavior_server`` → ``cmd_vel_nav`` → ``velocity_smoother``
→ ``cmd_vel_smoothed`` → ``collision_monitor`` → ``cmd_vel`` → the base.

:class:`VelocitySmoother` is the smoother's open-loop mode with nav2_bringup's
parameters (``max_velocity [0.5, 0.0, 2.0]``, ``max_accel [2.5, 0.0, 3.2]``,
``max_decel [-2.5, 0.0, -3.2]``, ``velocity_timeout 1.0``): each command is clipped to
the velocity limits, and moves from the last smoothed command no faster than the
acceleration (speeding up) or deceleration (slowing down) limits allow. The stand-in
smooths once per simulation step (20 Hz, nav2_bringup's ``smoothing_frequency``).

:class:`SpeedLimit` is the controller's answer to ``speed_limit``
(``nav2_msgs/SpeedLimit``): a percentage of the controller's own maximum linear speed,
or an absolute one in m/s; 0 lifts the limit. As Regulated Pure Pursuit lowers its
desired speed, a limited command keeps its curvature (the turn rate scales with it).

The collision monitor, the chain's last stage, is :mod:`navseq.sim.collision_monitor`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class SmootherLimits:
    """nav2_bringup's velocity_smoother parameters for x and yaw (y is not used)."""

    max_v: float = 0.5
    min_v: float = -0.5
    max_w: float = 2.0
    min_w: float = -2.0
    accel_v: float = 2.5
    accel_w: float = 3.2
    decel_v: float = 2.5  # magnitudes of max_decel
    decel_w: float = 3.2
    timeout: float = 1.0  # s without a command before the smoother stops (and says 0)


NAV2_BRINGUP_SMOOTHER = SmootherLimits()


def _smooth_axis(
    current: float, target: float, low: float, high: float, accel: float, decel: float, dt: float
) -> float:
    target = min(max(target, low), high)
    speeding_up = abs(target) > abs(current) and (current == 0.0 or (target > 0) == (current > 0))
    limit = (accel if speeding_up else decel) * dt
    return current + min(max(target - current, -limit), limit)


class VelocitySmoother:
    """Nav2's velocity smoother in open loop; see the module docstring."""

    def __init__(self, limits: SmootherLimits = NAV2_BRINGUP_SMOOTHER) -> None:
        self.limits = limits
        self.output = (0.0, 0.0)  # the last smoothed command
        self._target = (0.0, 0.0)
        self._last_command = -math.inf

    def command(self, v: float, w: float, now: float) -> None:
        """A command arrives on ``cmd_vel_nav`` at ``now`` (s)."""
        self._target = (v, w)
        self._last_command = now

    def active(self, now: float) -> bool:
        """Whether a command came within the timeout (otherwise the smoother is silent)."""
        return now - self._last_command <= self.limits.timeout

    def step(self, now: float, dt: float) -> tuple[float, float]:
        """The smoothed command for this cycle; zero once the commands stopped coming."""
        limits = self.limits
        if not self.active(now):
            self.output = (0.0, 0.0)
            return self.output
        v, w = self.output
        target_v, target_w = self._target
        self.output = (
            _smooth_axis(
                v, target_v, limits.min_v, limits.max_v, limits.accel_v, limits.decel_v, dt
            ),
            _smooth_axis(
                w, target_w, limits.min_w, limits.max_w, limits.accel_w, limits.decel_w, dt
            ),
        )
        return self.output


class SpeedLimit:
    """The controller's speed limit from ``speed_limit``; see the module docstring."""

    def __init__(self, max_linear: float) -> None:
        self.max_linear = max_linear  # the controller's own top speed (m/s)
        self.limit: float | None = None  # m/s; None: no limit

    def set(self, percentage: bool, value: float) -> None:
        """``nav2_msgs/SpeedLimit``'s two fields; a value <= 0 (or 100 %) lifts the limit."""
        if not math.isfinite(value) or value <= 0.0 or (percentage and value >= 100.0):
            self.limit = None
        else:
            self.limit = self.max_linear * value / 100.0 if percentage else value

    def apply(self, v: float, w: float) -> tuple[float, float]:
        """The command with its linear speed capped, its curvature kept."""
        limit = self.limit
        if limit is None or abs(v) <= limit:
            return v, w
        scale = limit / abs(v)
        return v * scale, w * scale


__all__ = ["NAV2_BRINGUP_SMOOTHER", "SmootherLimits", "SpeedLimit", "VelocitySmoother"]
