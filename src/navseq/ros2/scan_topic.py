"""The simulated laser on the ROS 2 simulator node: ``scan`` and its frame.

A TurtleBot3's LDS-01 as its driver publishes it (:mod:`navseq.sim.scan` casts the
rays): ``sensor_msgs/LaserScan`` on ``scan`` at 5 Hz of simulated time, 360 beams from
0 rad counter-clockwise, 0.12-3.5 m, ``inf`` where nothing is hit; sensor-data QoS (best
effort), which amcl and the costmaps subscribe with. The frame is ``base_scan``, placed
on ``base_link`` by a static transform (turtlebot3_description's offsets). The ranges
are measured from the robot's true pose, on the map and the other robots' footprints.
"""

from __future__ import annotations

import array
import threading
from collections.abc import Callable
from typing import Any

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan

from navseq.ros2.standin import Nav2StandIn
from navseq.sim.scan import TURTLEBOT3_LDS, LaserSpec, ray_cast


def base_scan_transform(base_link: str, base_scan: str, stamp: Any, spec: LaserSpec) -> Any:
    """The static ``base_link -> base_scan`` transform."""
    transform = TransformStamped()
    transform.header.frame_id = base_link
    transform.header.stamp = stamp
    transform.child_frame_id = base_scan
    transform.transform.translation.x = spec.mount_x
    transform.transform.translation.z = spec.height
    transform.transform.rotation.w = 1.0
    return transform


class ScanTopic:
    """Publishes ``scan`` from ``standin``'s robot every 1/rate simulated seconds."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        *,
        stamp: Callable[[], Any],
        frame: str,
        others: Callable[[], list[Any]],
        spec: LaserSpec = TURTLEBOT3_LDS,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._stamp = stamp
        self._frame = frame
        self._others = others
        self.spec = spec
        self._next = 0.0
        self._publisher = node.create_publisher(LaserScan, "scan", qos_profile_sensor_data)

    def publish_if_due(self) -> None:
        """A scan when its period is up (call after a simulation step)."""
        with self._lock:
            now = self._standin.time
            if now + 1e-9 < self._next:
                return
            self._next = now + 1.0 / self.spec.rate
            world = self._standin.world
            grid, pose, others = world.grid, world.robot.pose, self._others()
        ranges = ray_cast(grid, pose, self.spec, others)
        spec = self.spec
        message = LaserScan()
        message.header.frame_id = self._frame
        message.header.stamp = self._stamp()
        message.angle_min = 0.0
        message.angle_max = float(spec.angle_increment * (spec.beams - 1))
        message.angle_increment = float(spec.angle_increment)
        message.time_increment = float(1.0 / spec.rate / spec.beams)
        message.scan_time = float(1.0 / spec.rate)
        message.range_min = float(spec.range_min)
        message.range_max = float(spec.range_max)
        message.ranges = array.array("f", ranges.tobytes())
        self._publisher.publish(message)


__all__ = ["ScanTopic", "base_scan_transform"]
