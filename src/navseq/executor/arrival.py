"""Whether a goal the navigation stack calls SUCCEEDED is believed: is the robot there?

move_base can end a fresh goal SUCCEEDED with the robot metres away
(ros-planning/navigation #949); Nav2 can end a goal that preempted another SUCCEEDED
where the old one ended. So every SUCCEEDED is checked against the robot's pose.
"""

from __future__ import annotations

import math

from navseq.geometry import Pose2D, normalize_angle
from navseq.mission.model import Policy
from navseq.mission.robot import GoalTolerance, RobotProfile

#: Added to the goal's xy tolerance when checking a SUCCEEDED against the robot's pose
#: (m): amcl's pose jitters by a few centimetres, and the pose the executor sees may be
#: a tick (0.1 s, 0.02 m at TurtleBot3 speed) older than the stack's own.
ARRIVAL_SLACK_M = 0.10
#: Added to the goal's yaw tolerance in the same check (rad, about 6°), for the same
#: reasons (amcl's heading jitter, a robot still settling its last turn).
ARRIVAL_SLACK_RAD = 0.10


def goal_tolerance(policy: Policy, robot: RobotProfile) -> GoalTolerance:
    """The arrival tolerance of a visit: its policy's, else the robot profile's."""
    default = robot.goal_tolerance
    return GoalTolerance(
        default.xy_m if policy.xy_tolerance_m is None else policy.xy_tolerance_m,
        default.yaw_rad if policy.yaw_tolerance_rad is None else policy.yaw_tolerance_rad,
    )


def arrival_miss(
    pose: Pose2D, goal: Pose2D, tolerance: GoalTolerance, pass_through_m: float | None
) -> str | None:
    """Why a SUCCEEDED with the robot at ``pose`` is not believed, or None.

    A visit where the robot stops (``pass_through_m`` None) allows the goal tolerance
    plus :data:`ARRIVAL_SLACK_M`, and the yaw tolerance plus :data:`ARRIVAL_SLACK_RAD`.
    A pass-through visit allows its radius (or the goal tolerance, if larger: the stack
    may legitimately end the goal there before the robot comes within the radius) plus
    the same slack, and no yaw: passing through does not turn to the goal's heading.
    Nav2 can end a goal that preempted another SUCCEEDED with the robot still at the
    preempted goal (its tree keeps following the old path until the next re-plan), so
    pass-through visits need the check as much as stops.
    """
    off = pose.distance_to(goal)
    allowed = tolerance.xy_m if pass_through_m is None else max(pass_through_m, tolerance.xy_m)
    if off > allowed + ARRIVAL_SLACK_M:
        return f"succeeded far from goal ({off:.2f} m)"
    if pass_through_m is not None:
        return None
    yaw_off = abs(normalize_angle(goal.yaw - pose.yaw))
    if yaw_off > tolerance.yaw_rad + ARRIVAL_SLACK_RAD:
        return f"succeeded {math.degrees(yaw_off):.0f}° off the goal yaw"
    return None


__all__ = ["ARRIVAL_SLACK_M", "ARRIVAL_SLACK_RAD", "arrival_miss", "goal_tolerance"]
