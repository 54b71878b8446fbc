"""Conversions between navseq's plain types and ROS 2 messages.

Only message packages are imported here (no rclpy node machinery), so the conversions
can be used by any ROS 2 face of navseq. Geometry comes from :mod:`navseq.geometry`.
"""

from __future__ import annotations

import array
import math
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Pose, PoseStamped, Quaternion, TransformStamped
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Path

from navseq.geometry import Pose2D, quaternion_to_yaw, yaw_to_quaternion
from navseq.ros2.standin import plan_poses
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.planner import Plan


def time_msg(seconds: float) -> Time:
    """A ``builtin_interfaces/Time`` (seconds since the clock's epoch)."""
    whole = math.floor(seconds)
    return Time(sec=int(whole), nanosec=min(round((seconds - whole) * 1e9), 999_999_999))


def duration_msg(seconds: float) -> Duration:
    seconds = max(seconds, 0.0)
    whole = math.floor(seconds)
    return Duration(sec=int(whole), nanosec=min(round((seconds - whole) * 1e9), 999_999_999))


def quaternion_msg(yaw: float) -> Quaternion:
    x, y, z, w = yaw_to_quaternion(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)


def pose_msg(pose: Pose2D) -> Pose:
    message = Pose()
    message.position.x = float(pose.x)
    message.position.y = float(pose.y)
    message.orientation = quaternion_msg(pose.yaw)
    return message


def pose_stamped(pose: Pose2D, frame: str, stamp: Time) -> PoseStamped:
    message = PoseStamped()
    message.header.frame_id = frame
    message.header.stamp = stamp
    message.pose = pose_msg(pose)
    return message


def pose2d_of(pose: Any) -> Pose2D | str:
    """The planar pose of a ``geometry_msgs/Pose``, or why it cannot be used."""
    q, p = pose.orientation, pose.position
    if not all(math.isfinite(v) for v in (q.x, q.y, q.z, q.w, p.x, p.y)):
        return "the pose has non-finite numbers"
    if abs(q.x) + abs(q.y) + abs(q.z) + abs(q.w) == 0.0:
        return "the orientation is the zero quaternion (set w = 1 for yaw 0)"
    return Pose2D(float(p.x), float(p.y), quaternion_to_yaw(q.x, q.y, q.z, q.w))


def transform_stamped(pose: Pose2D, parent: str, child: str, stamp: Time) -> TransformStamped:
    """A planar transform ``parent`` -> ``child`` placing the child at ``pose``."""
    message = TransformStamped()
    message.header.frame_id = parent
    message.header.stamp = stamp
    message.child_frame_id = child
    message.transform.translation.x = float(pose.x)
    message.transform.translation.y = float(pose.y)
    message.transform.rotation = quaternion_msg(pose.yaw)
    return message


def grid_msg(grid: OccupancyGrid, frame: str, stamp: Time) -> OccupancyGridMsg:
    """A ``nav_msgs/OccupancyGrid`` with the same cells (both use row 0 = bottom)."""
    message = OccupancyGridMsg()
    message.header.frame_id = frame
    message.header.stamp = stamp
    message.info.map_load_time = stamp
    message.info.resolution = float(grid.resolution)
    message.info.width = grid.width
    message.info.height = grid.height
    message.info.origin = pose_msg(grid.origin)
    # array('b') is taken as is by rclpy; a list of a million ints would take seconds.
    message.data = array.array("b", np.ascontiguousarray(grid.data, dtype=np.int8).tobytes())
    return message


def path_msg(plan: Plan | None, goal: Pose2D | None, frame: str, stamp: Time) -> Path:
    """A ``nav_msgs/Path`` along ``plan``: each pose faces the next point, the last one
    has the goal's yaw. An empty path when there is no plan."""
    path = Path()
    path.header.frame_id = frame
    path.header.stamp = stamp
    if plan is None:
        return path
    path.poses = [pose_stamped(pose, frame, stamp) for pose in plan_poses(plan.points, goal)]
    return path
