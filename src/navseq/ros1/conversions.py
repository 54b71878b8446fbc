"""Conversions between navseq's plain types and ROS 1 messages.

Shared by every navseq ROS node (the sequencer, the recorder, the simulator nodes).
Message classes are imported here, so only code under ``navseq.ros1`` may import this
module.
"""

from __future__ import annotations

import numpy as np
import rospy
from actionlib_msgs.msg import GoalStatus as GoalStatusMsg
from geometry_msgs.msg import Pose, PoseStamped, Quaternion, TransformStamped
from move_base_msgs.msg import MoveBaseGoal
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg

from navseq.geometry import (  # the message-free readers, re-exported for the nodes
    Pose2D,
    pose2d_from_pose,
    pose2d_from_transform,
    yaw_of,
    yaw_to_quaternion,
)
from navseq.navigators.base import GoalOutcome
from navseq.sim.occupancy import OccupancyGrid, grid_from_map_message

# actionlib_msgs/GoalStatus values that end a goal: the executor's outcome and the name
# the report gives the status.
TERMINAL_STATUSES: dict[int, tuple[GoalOutcome, str]] = {
    GoalStatusMsg.SUCCEEDED: (GoalOutcome.SUCCEEDED, "SUCCEEDED"),
    GoalStatusMsg.ABORTED: (GoalOutcome.FAILED, "ABORTED"),
    GoalStatusMsg.REJECTED: (GoalOutcome.FAILED, "REJECTED"),
    GoalStatusMsg.PREEMPTED: (GoalOutcome.FAILED, "PREEMPTED"),
    GoalStatusMsg.RECALLED: (GoalOutcome.FAILED, "RECALLED"),
    GoalStatusMsg.LOST: (GoalOutcome.LOST, "LOST"),
}


def terminal_status(code: int) -> tuple[GoalOutcome, str] | None:
    """The outcome and name of a terminal actionlib status, None while the goal is alive.

    PENDING, ACTIVE, PREEMPTING and RECALLING are not terminal: a result still follows.
    """
    return TERMINAL_STATUSES.get(code)


def quaternion_msg(yaw: float) -> Quaternion:
    x, y, z, w = yaw_to_quaternion(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)


def pose_from_pose2d(pose: Pose2D, z: float = 0.0) -> Pose:
    """A ``geometry_msgs/Pose`` at ``pose`` (height ``z``), yaw as a quaternion."""
    message = Pose()
    message.position.x = pose.x
    message.position.y = pose.y
    message.position.z = z
    message.orientation = quaternion_msg(pose.yaw)
    return message


def pose_stamped(pose: Pose2D, frame: str, stamp: rospy.Time, z: float = 0.0) -> PoseStamped:
    message = PoseStamped()
    message.header.frame_id = frame
    message.header.stamp = stamp
    message.pose = pose_from_pose2d(pose, z)
    return message


def move_base_goal(pose: Pose2D, frame: str, stamp: rospy.Time, z: float = 0.0) -> MoveBaseGoal:
    """The MoveBaseGoal the tutorial builds: target pose in ``frame``, yaw as a quaternion."""
    return MoveBaseGoal(target_pose=pose_stamped(pose, frame, stamp, z))


def transform_stamped(pose: Pose2D, parent: str, child: str, stamp: rospy.Time) -> TransformStamped:
    """A planar TF transform ``parent`` -> ``child`` placing the child at ``pose``."""
    message = TransformStamped()
    message.header.frame_id = parent
    message.header.stamp = stamp
    message.child_frame_id = child
    message.transform.translation.x = pose.x
    message.transform.translation.y = pose.y
    message.transform.rotation = quaternion_msg(pose.yaw)
    return message


def grid_to_msg(grid: OccupancyGrid, frame_id: str, stamp: rospy.Time) -> OccupancyGridMsg:
    """A ``nav_msgs/OccupancyGrid`` with the same cells (both use row 0 = bottom)."""
    msg = OccupancyGridMsg()
    msg.header.frame_id = frame_id
    msg.header.stamp = stamp
    msg.info.map_load_time = stamp
    msg.info.resolution = grid.resolution
    msg.info.width = grid.width
    msg.info.height = grid.height
    msg.info.origin = pose_from_pose2d(grid.origin)
    msg.data = grid.data.astype(np.int8).ravel().tolist()
    return msg


def grid_from_msg(msg: OccupancyGridMsg, source: str) -> OccupancyGrid:
    """navseq's grid from a ``nav_msgs/OccupancyGrid``; ``source`` names it in messages."""
    return grid_from_map_message(msg, source)


__all__ = [
    "TERMINAL_STATUSES",
    "grid_from_msg",
    "grid_to_msg",
    "move_base_goal",
    "pose2d_from_pose",
    "pose2d_from_transform",
    "pose_from_pose2d",
    "pose_stamped",
    "quaternion_msg",
    "terminal_status",
    "transform_stamped",
    "yaw_of",
]
