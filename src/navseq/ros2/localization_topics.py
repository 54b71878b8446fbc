"""The ``amcl`` part of the ROS 2 simulator node: initial pose in, estimate out.

What nav2_amcl (Jazzy) serves, on the ``amcl`` lifecycle node, over the stand-in's
:class:`navseq.sim.localization.Localization` (no particle filter: see there):

- ``initialpose`` (``geometry_msgs/PoseWithCovarianceStamped``, map frame): sets the
  estimate — the ``map -> odom`` transform moves, the robot does not (RViz's "2D Pose
  Estimate"). With ``--initial-pose teleport`` the simulated robot is put there instead
  (refused inside an obstacle), for scripts that place the robot between runs;
- ``amcl_pose`` (``PoseWithCovarianceStamped``, reliable, transient local, depth 1): the
  believed pose, after every initial pose and every update (the robot drove 0.25 m or
  turned 0.2 rad), and every 0.5 s of simulated time once localised; its covariance is
  the estimate's spread (error to the truth, a few centimetres at best);
- ``particle_cloud`` (``nav2_msgs/ParticleCloud``, best effort as amcl's sensor-data
  QoS): :data:`PARTICLES` poses around the belief, drawn once from a seeded normal
  distribution and scaled by the spread, equal weights;
- the services ``set_initial_pose`` (``nav2_msgs/srv/SetInitialPose``: as
  ``initialpose``), ``request_nomotion_update`` (``std_srvs/srv/Empty``: one correction
  now, without motion) and ``reinitialize_global_localization`` (``std_srvs/srv/Empty``:
  answered; **simplified**: no global search, the estimate keeps converging from where
  it is, as the stand-in's estimate always does).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav2_msgs.msg import Particle, ParticleCloud
from nav2_msgs.srv import SetInitialPose
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from std_srvs.srv import Empty

from navseq.geometry import Pose2D
from navseq.ros2.messages import pose2d_of, pose_msg
from navseq.ros2.standin import Nav2StandIn
from navseq.sim.localization import Spread

PARTICLES = 200  # nav2_bringup's amcl keeps 500-2000; a cloud to look at needs fewer
AMCL_POSE_PERIOD = 0.5  # s of simulated time between two amcl_pose messages
AMCL_POSE_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
# The cloud's shape: fixed, so that runs stay reproducible.
_OFFSETS = np.random.default_rng(20).standard_normal((PARTICLES, 3))


def particles_around(pose: Pose2D, spread: Spread) -> list[Pose2D]:
    """:data:`PARTICLES` poses about ``pose``, ``spread`` standard deviations apart."""
    return [
        Pose2D(pose.x + spread.xy * dx, pose.y + spread.xy * dy, pose.yaw + spread.yaw * da)
        for dx, dy, da in _OFFSETS
    ]


class LocalizationTopics:
    """``initialpose``, ``amcl_pose`` and ``particle_cloud`` on ``amcl``; see the module
    docstring. :meth:`publish` is called after every simulation step."""

    def __init__(
        self,
        amcl: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        stamp: Callable[[], Any],
        frame: str,
        teleport: bool,
    ) -> None:
        self._standin = standin
        self._lock = lock
        self._stamp = stamp
        self._frame = frame
        self._teleport = teleport
        self._log = amcl.get_logger()
        self._localized = False
        self._last_published = -float("inf")
        self._updates_published = standin.localization.updates
        self._pose_pub = amcl.create_publisher(
            PoseWithCovarianceStamped, "amcl_pose", AMCL_POSE_QOS
        )
        self._cloud_pub = amcl.create_publisher(
            ParticleCloud, "particle_cloud", qos_profile_sensor_data
        )
        amcl.create_subscription(
            PoseWithCovarianceStamped,
            "initialpose",
            self._on_initial_pose,
            10,
            callback_group=group,
        )
        amcl.create_service(
            SetInitialPose, "set_initial_pose", self._on_set_initial_pose, callback_group=group
        )
        amcl.create_service(
            Empty, "request_nomotion_update", self._on_nomotion_update, callback_group=group
        )
        amcl.create_service(
            Empty,
            "reinitialize_global_localization",
            self._on_global_localization,
            callback_group=group,
        )

    def publish(self) -> None:
        """The estimate, when it changed or its period is up (call after a step). Nothing
        before the first initial pose: amcl publishes no pose until it has one."""
        if not self._localized:
            return
        with self._lock:
            localization = self._standin.localization
            now = self._standin.time
            changed = localization.updates != self._updates_published
            due = now - self._last_published >= AMCL_POSE_PERIOD
            if not (changed or due):
                return
            self._updates_published = localization.updates
            self._last_published = now
            believed, spread = localization.believed_pose, localization.spread()
        self._send(believed, spread)

    def _send(self, pose: Pose2D, spread: Spread) -> None:
        stamp = self._stamp()
        message = PoseWithCovarianceStamped()
        message.header.frame_id = self._frame
        message.header.stamp = stamp
        message.pose.pose = pose_msg(pose)
        covariance = [0.0] * 36
        covariance[0] = covariance[7] = spread.xy**2
        covariance[35] = spread.yaw**2
        message.pose.covariance = covariance
        self._pose_pub.publish(message)
        cloud = ParticleCloud()
        cloud.header.frame_id = self._frame
        cloud.header.stamp = stamp
        weight = 1.0 / PARTICLES
        cloud.particles = [
            Particle(pose=pose_msg(p), weight=weight) for p in particles_around(pose, spread)
        ]
        self._cloud_pub.publish(cloud)

    def _on_set_initial_pose(
        self, request: SetInitialPose.Request, response: SetInitialPose.Response
    ) -> SetInitialPose.Response:
        self._on_initial_pose(request.pose)
        return response

    def _on_nomotion_update(self, request: Empty.Request, response: Empty.Response) -> Any:
        with self._lock:
            self._standin.localization.update_without_motion()
        self._log.info("no-motion update: the estimate corrected once")
        self.publish()
        return response

    def _on_global_localization(self, request: Empty.Request, response: Empty.Response) -> Any:
        # A real amcl spreads its particles over the whole map; the stand-in has none to
        # spread, and its estimate converges from anywhere (docs/ros2.md says so).
        self._log.info("global localization requested: the estimate keeps converging")
        return response

    def _on_initial_pose(self, message: PoseWithCovarianceStamped) -> None:
        frame = message.header.frame_id.lstrip("/")
        if frame not in ("", self._frame):
            self._log.warning(f"initialpose ignored: frame {frame!r} is not {self._frame!r}")
            return
        pose = pose2d_of(message.pose.pose)
        if isinstance(pose, str):
            self._log.warning(f"initialpose ignored: {pose}")
            return
        with self._lock:
            refused = self._standin.teleport(pose) if self._teleport else None
            if not self._teleport:
                self._standin.set_initial_pose(pose)
        if refused is not None:
            self._log.warning(f"initialpose refused: {refused}")
            return
        what = "teleported to" if self._teleport else "initial pose set to"
        self._log.info(f"{what} ({pose.x:.2f}, {pose.y:.2f}, {pose.yaw:.2f} rad)")
        self._localized = True
        self.publish()


__all__ = ["LocalizationTopics", "particles_around"]
