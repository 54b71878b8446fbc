"""Conversions between navseq's plain types and ROS 1 messages.

Shared by every navseq ROS node (the sequencer, the recorder, the simulator nodes).
Message classes are imported here, so only code under ``navseq.ros`` (and the ``ros1``
navigator) may import this module.
"""

from __future__ import annotations

from typing import Any

import rospy
from actionlib_msgs.msg import GoalStatus as GoalStatusMsg
from geometry_msgs.msg import Pose, PoseStamped, Quaternion, TransformStamped
from move_base_msgs.msg import MoveBaseGoal

from navseq.geometry import Pose2D, quaternion_to_yaw, yaw_to_quaternion
from navseq.navigators.base import GoalStatus

# actionlib_msgs/GoalStatus values that end a goal, and what the executor calls them.
TERMINAL_STATUSES: dict[int, GoalStatus] = {
    GoalStatusMsg.SUCCEEDED: GoalStatus.SUCCEEDED,
    GoalStatusMsg.ABORTED: GoalStatus.ABORTED,
    GoalStatusMsg.REJECTED: GoalStatus.REJECTED,
    GoalStatusMsg.PREEMPTED: GoalStatus.PREEMPTED,
    GoalStatusMsg.RECALLED: GoalStatus.RECALLED,
    GoalStatusMsg.LOST: GoalStatus.LOST,
}


def terminal_status(code: int) -> GoalStatus | None:
    """The executor's name for a terminal actionlib status, None while the goal is alive.

    PENDING, ACTIVE, PREEMPTING and RECALLING are not terminal: a result still follows.
    """
    return TERMINAL_STATUSES.get(code)


def quaternion_msg(yaw: float) -> Quaternion:
    x, y, z, w = yaw_to_quaternion(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)


def yaw_of(orientation: Any) -> float:
    """Yaw (radians) of a geometry_msgs/Quaternion-like object; roll and pitch ignored."""
    return quaternion_to_yaw(orientation.x, orientation.y, orientation.z, orientation.w)


def pose2d_from_pose(pose: Pose) -> Pose2D:
    return Pose2D(pose.position.x, pose.position.y, yaw_of(pose.orientation))


def pose_from_pose2d(pose: Pose2D, z: float = 0.0) -> Pose:
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


def pose2d_from_transform(transform: TransformStamped) -> Pose2D:
    t = transform.transform
    return Pose2D(t.translation.x, t.translation.y, yaw_of(t.rotation))


def transform_stamped(
    pose: Pose2D, parent: str, child: str, stamp: rospy.Time
) -> TransformStamped:
    """A planar TF transform ``parent`` -> ``child`` placing the child at ``pose``."""
    message = TransformStamped()
    message.header.frame_id = parent
    message.header.stamp = stamp
    message.child_frame_id = child
    message.transform.translation.x = pose.x
    message.transform.translation.y = pose.y
    message.transform.rotation = quaternion_msg(pose.yaw)
    return message

