"""The robot as the running move_base knows it: its parameters, fetched from the ROS master.

``navseq run --navigator ros1`` on a robot other than the TurtleBot3 burger must not
plan, check or judge arrival with the burger's outline and tolerances. move_base holds
the real values on the parameter server, under the action's namespace; which of them
count, and how, is :mod:`navseq.roscore.stack_profile`'s (shared with Nav2). This module
only fetches the tree.
"""

from __future__ import annotations

from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.roscore.stack_profile import profile_from_navstack_params


def read_navstack_profile(
    action_ns: str, base: RobotProfile = DEFAULT_PROFILE
) -> tuple[RobotProfile, str]:
    """The profile from the parameters under ``action_ns`` (e.g. ``/move_base``), and a note."""
    import rospy

    try:
        tree = rospy.get_param(action_ns, {})
    except KeyError:
        tree = {}
    return profile_from_navstack_params(tree if isinstance(tree, dict) else {}, action_ns, base)
