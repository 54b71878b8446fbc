"""Nav2's velocity chain on the ROS 2 simulator node, and teleop.

The commands :mod:`navseq.sim.velocity_chain` computes inside the stand-in, published
under Nav2 Jazzy's names so a client sees each stage (all ``geometry_msgs/Twist``,
depth 1 as Nav2's publishers):

- ``cmd_vel_nav``: the controller's (or a behaviour's) command, after the speed limit;
- ``cmd_vel_smoothed``: the velocity smoother's output;
- ``cmd_vel``: what the collision monitor passes on to the base
  (:mod:`navseq.ros2.collision_monitor`); also when a command from outside came on
  ``cmd_vel_smoothed`` (teleop through the monitor).

Each is published every step while the chain drives, and once more as zero when it
stops. ``speed_limit`` (``nav2_msgs/SpeedLimit``, as the controller server subscribes
it) sets the controller's limit. ``cmd_vel`` from anyone else drives the robot while no
goal or behaviour runs (teleop); our own commands, heard back on the same topic, are
told apart by the time since we last published.
"""

from __future__ import annotations

import threading
import time
from typing import Any

from geometry_msgs.msg import Twist
from nav2_msgs.msg import SpeedLimit
from rclpy.node import Node

from navseq.ros2.standin import Nav2StandIn

TELEOP_QUIET = 0.5  # s of wall time after our own cmd_vel before outside commands count


def twist(v: float, w: float) -> Twist:
    message = Twist()
    message.linear.x, message.angular.z = float(v), float(w)
    return message


class VelocityTopics:
    """The chain's three topics, ``speed_limit`` and teleop on ``node``."""

    def __init__(self, node: Node, standin: Nav2StandIn, lock: threading.Lock, group: Any) -> None:
        self._standin = standin
        self._lock = lock
        self._log = node.get_logger()
        self._nav_pub = node.create_publisher(Twist, "cmd_vel_nav", 1)
        self._smoothed_pub = node.create_publisher(Twist, "cmd_vel_smoothed", 1)
        self._cmd_pub = node.create_publisher(Twist, "cmd_vel", 1)
        self._was_driving = False
        self._was_teleop = False
        self._last_own_cmd = -float("inf")
        self._last_smoothed = -float("inf")
        node.create_subscription(Twist, "cmd_vel", self._on_cmd_vel, 10, callback_group=group)
        node.create_subscription(
            SpeedLimit, "speed_limit", self._on_speed_limit, 10, callback_group=group
        )

    def publish(self) -> None:
        """This step's commands (call after a simulation step)."""
        with self._lock:
            commands = self._standin.commands
            driving, nav, smoothed, out = (
                commands.driving,
                commands.nav,
                commands.smoothed,
                commands.out,
            )
            teleop = commands.monitored_teleop
        if teleop or self._was_teleop:
            # cmd_vel_smoothed from outside: only the monitor's output is ours.
            self._last_own_cmd = time.monotonic()
            self._cmd_pub.publish(twist(*(out if teleop else (0.0, 0.0))))
            self._was_teleop = teleop
        if not (driving or self._was_driving):
            return
        if not driving:
            nav = smoothed = out = (0.0, 0.0)
        self._last_own_cmd = time.monotonic()
        self._nav_pub.publish(twist(*nav))
        self._smoothed_pub.publish(twist(*smoothed))
        self._last_smoothed = self._last_own_cmd
        self._cmd_pub.publish(twist(*out))
        self._was_driving = driving

    def stop(self) -> None:
        """The robot stops (the node shuts down)."""
        self._cmd_pub.publish(Twist())

    def _on_cmd_vel(self, message: Twist) -> None:
        """Teleop while no goal runs; our own commands (echoed back to us) are skipped."""
        if time.monotonic() - self._last_own_cmd < TELEOP_QUIET:
            return
        with self._lock:
            self._standin.command(float(message.linear.x), float(message.angular.z))

    def _on_speed_limit(self, message: SpeedLimit) -> None:
        with self._lock:
            limit = self._standin.speed_limit
            limit.set(bool(message.percentage), float(message.speed_limit))
            now = limit.limit
        self._log.info("speed_limit: " + ("none" if now is None else f"{now:.3f} m/s"))

    @property
    def last_smoothed(self) -> float:
        """When (monotonic s) the chain last published ``cmd_vel_smoothed``: what is
        heard there within ``TELEOP_QUIET`` of it is our own command echoed back."""
        return self._last_smoothed


__all__ = ["TELEOP_QUIET", "VelocityTopics", "twist"]
