"""Conversions between navseq's plain types and ROS 2 messages.

Only message packages are imported here (no rclpy node machinery), so the conversions
can be used by any ROS 2 face of navseq. Geometry comes from :mod:`navseq.geometry`.
Serves the simulator node (what it publishes) and the ``nav2`` navigator (the goals it
sends, and how it reads Nav2's statuses, results and transforms).
"""

from __future__ import annotations

import array
import math
from typing import Any

import numpy as np
from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Pose, PoseStamped, Quaternion, TransformStamped
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg
from nav_msgs.msg import Path

from navseq.geometry import (
    FrameTree,
    Pose2D,
    pose2d_from_transform,
    quaternion_to_yaw,
    yaw_to_quaternion,
)
from navseq.navigators.base import GoalOutcome
from navseq.ros2.error_codes import describe_result
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


def finish_goal(handle: Any, outcome: str) -> str:
    """Set an action goal's terminal status from ``outcome`` ("SUCCEEDED", "CANCELED" or
    "ABORTED"; CANCELED only when the client asked for it, else ABORTED); the status set."""
    if outcome == "SUCCEEDED":
        handle.succeed()
    elif outcome == "CANCELED" and handle.is_cancel_requested:
        handle.canceled()
    else:
        handle.abort()
        return "ABORTED"
    return outcome


def seconds_of(duration: Any) -> float:
    """Seconds of a ``builtin_interfaces/Duration`` (or ``Time``)."""
    return float(duration.sec) + float(duration.nanosec) * 1e-9


#: action_msgs/GoalStatus codes of a finished goal, by the name reports keep.
_TERMINAL = {
    GoalStatus.STATUS_SUCCEEDED: (GoalOutcome.SUCCEEDED, "SUCCEEDED"),
    GoalStatus.STATUS_CANCELED: (GoalOutcome.FAILED, "CANCELED"),
    GoalStatus.STATUS_ABORTED: (GoalOutcome.FAILED, "ABORTED"),
    # A result "UNKNOWN" comes from a server that does not know the goal: one that was
    # restarted since it accepted it. The goal is as good as lost.
    GoalStatus.STATUS_UNKNOWN: (GoalOutcome.LOST, "UNKNOWN"),
}


def terminal_status(code: int) -> tuple[GoalOutcome, str] | None:
    """The neutral outcome and Nav2's name of a result's status; None if not terminal.

    ACCEPTED, EXECUTING and CANCELING are not terminal (a result never carries them).
    """
    return _TERMINAL.get(int(code))


def result_text(error_code: int, error_msg: str) -> str:
    """Nav2's own words about a result: ``error_msg``, and ``error_code`` by name when set.

    Nav2 (Iron and later) fills both on a failure (``error_code`` 206: the planner's
    GOAL_OCCUPIED, ...); Humble's results have neither, so both may be empty. The names
    come from the installed nav2_msgs (:mod:`navseq.ros2.error_codes`).
    """
    return describe_result(int(error_code), error_msg)


def navigate_goal(pose: Pose2D, frame: str, stamp: Time, z: float = 0.0) -> Any:
    """A ``nav2_msgs/action/NavigateToPose`` goal to ``pose`` in ``frame``.

    ``behavior_tree`` stays empty: bt_navigator's default tree, as RViz sends it.
    """
    from nav2_msgs.action import NavigateToPose

    goal = NavigateToPose.Goal()
    goal.pose = pose_stamped(pose, frame, stamp)
    goal.pose.pose.position.z = float(z)
    return goal


def add_transforms(tree: FrameTree, message: Any) -> None:
    """Record every transform of a ``tf2_msgs/TFMessage`` in ``tree`` (planar part)."""
    for transform in message.transforms:
        tree.set(
            transform.header.frame_id, transform.child_frame_id, pose2d_from_transform(transform)
        )
