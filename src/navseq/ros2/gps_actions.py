"""Nav2's GPS waypoints on the ROS 2 simulator node: ``follow_gps_waypoints`` and ``fromLL``.

- ``follow_gps_waypoints`` (``nav2_msgs/action/FollowGPSWaypoints``, the waypoint
  follower's, as ``nav2_simple_commander``'s ``followGpsWaypoints()`` sends it): each
  ``geographic_msgs/GeoPose`` is converted to the map frame with the datum of the node's
  ``--datum`` (:mod:`navseq.mission.geodesy`, as robot_localization's navsat_transform
  converts), its orientation kept as the map-frame heading (Nav2's follower passes it on
  unchanged), and the poses are followed as a ``follow_waypoints`` goal is: the same
  feedback (``current_waypoint``), ``missed_waypoints``, error codes, ``number_of_loops``,
  ``goal_index`` and ``stop_on_failure``. Nav2 converts through robot_localization's
  ``fromLL`` service; the stand-in converts itself. Without ``--datum`` a goal ends
  ABORTED with ``TASK_EXECUTOR_FAILED`` (601) saying so.
- ``fromLL`` (``robot_localization/srv/FromLL``, navsat_transform's service) with the
  same datum, when a datum is given and robot_localization's interfaces are installed
  (Nav2's build has them; a ROS 2 without them gets no such service, said in the log).
  Without ``--datum`` the node serves what a default Nav2 bringup serves: no ``fromLL``.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

from geographic_msgs.msg import GeoPose
from nav2_msgs.action import FollowGPSWaypoints
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node

from navseq.geometry import Pose2D, quaternion_to_yaw
from navseq.mission.geodesy import Datum, GeoPoint, check_latitude, check_longitude
from navseq.ros2.lifecycle import Nav2Lifecycle
from navseq.ros2.standin import Ending, Nav2StandIn, Outcome, WaypointRun
from navseq.ros2.waypoint_goals import see_waypoints_through

ACTION = "follow_gps_waypoints"
LIFECYCLE_ACTION = "follow_waypoints"  # the same server node: waypoint_follower
TASK_EXECUTOR_FAILED = 601


def map_pose_of(datum: Datum, geo_pose: GeoPose) -> Pose2D | str:
    """A GeoPose in the map frame, or why it cannot be converted."""
    position = geo_pose.position
    problem = check_latitude(position.latitude) or check_longitude(position.longitude)
    if problem:
        return problem
    q = geo_pose.orientation
    norm = math.hypot(q.x, q.y, q.z, q.w)
    yaw = quaternion_to_yaw(q.x / norm, q.y / norm, q.z / norm, q.w / norm) if norm > 0 else 0.0
    x, y, _ = datum.to_map(GeoPoint(position.latitude, position.longitude))
    return Pose2D(x, y, yaw)


class GpsWaypointActions:
    """``follow_gps_waypoints`` (and ``fromLL`` where its type exists) on ``node``."""

    def __init__(
        self,
        node: Node,
        standin: Nav2StandIn,
        lock: threading.Lock,
        group: Any,
        *,
        datum: Datum | None,
        lifecycle: Nav2Lifecycle,
        stamp: Callable[[], Any],
        frame: str,
    ) -> None:
        self._node = node
        self._standin = standin
        self._lock = lock
        self._datum = datum
        self._lifecycle = lifecycle
        self._stamp = stamp
        self._frame = frame
        self._log = node.get_logger()
        self._server = ActionServer(
            node,
            FollowGPSWaypoints,
            ACTION,
            execute_callback=self._execute,
            goal_callback=self._gate,
            cancel_callback=lambda _handle: CancelResponse.ACCEPT,
            callback_group=group,
        )
        # navsat_transform is not part of a default bringup: served only with a datum.
        self._from_ll = self._serve_from_ll(group) if datum is not None else None

    def _gate(self, _request: Any) -> GoalResponse:
        if self._lifecycle.active(LIFECYCLE_ACTION):
            return GoalResponse.ACCEPT
        self._log.info(f"{ACTION}: Action server is inactive. Rejecting the goal.")
        return GoalResponse.REJECT

    def _poses(self, geo_poses: list[GeoPose]) -> list[Pose2D] | str:
        if self._datum is None:
            return "no datum: start the simulator with --datum LAT,LON[,YAW]"
        poses: list[Pose2D] = []
        for index, geo_pose in enumerate(geo_poses):
            pose = map_pose_of(self._datum, geo_pose)
            if isinstance(pose, str):
                return f"GPS pose {index}: {pose}"
            poses.append(pose)
        return poses

    def _execute(self, handle: Any) -> Any:
        request = handle.request
        stop_on_failure = bool(self._node.get_parameter("stop_on_failure").value)
        poses = self._poses(list(request.gps_poses))
        run: WaypointRun | None = None
        refused: Ending | None = None
        if isinstance(poses, str):
            refused = Ending(Outcome.ABORTED, TASK_EXECUTOR_FAILED, poses)
            self._log.warning(f"{ACTION}: goal ABORTED: {poses}")
        else:
            with self._lock:
                run = self._standin.follow(
                    poses,
                    loops=int(request.number_of_loops),
                    start_index=int(request.goal_index),
                    stop_on_failure=stop_on_failure,
                )
        if run is not None:
            self._log.info(f"{ACTION}: {len(run.poses)} GPS waypoints")
        return see_waypoints_through(
            handle,
            run,
            refused,
            standin=self._standin,
            lock=self._lock,
            action=FollowGPSWaypoints,
            frame=self._frame,
            stamp=self._stamp,
        )

    def _serve_from_ll(self, group: Any) -> Any:
        """navsat_transform's ``fromLL`` with the datum, if robot_localization is there."""
        try:
            from robot_localization.srv import FromLL
        except ImportError:
            self._log.info("no robot_localization interfaces here: fromLL is not served")
            return None
        return self._node.create_service(
            FromLL, "fromLL", self._from_ll_answer, callback_group=group
        )

    def _from_ll_answer(self, request: Any, response: Any) -> Any:
        point = request.ll_point
        if (
            self._datum is None
            or check_latitude(point.latitude)
            or check_longitude(point.longitude)
        ):
            # navsat_transform answers with the point it has; nothing sensible here.
            self._log.warning("fromLL: no datum (--datum) or a position out of range")
            return response
        x, y, _ = self._datum.to_map(GeoPoint(point.latitude, point.longitude))
        response.map_point.x, response.map_point.y = x, y
        altitude = point.altitude
        datum_altitude = self._datum.point.altitude
        if math.isfinite(altitude) and datum_altitude is not None:
            response.map_point.z = altitude - datum_altitude
        return response


__all__ = ["GpsWaypointActions", "map_pose_of"]
