"""``~robot``: which robot the simulator's ROS nodes simulate.

Both sim nodes (:mod:`navseq.ros1.sim_robot_node`, :mod:`navseq.ros1.sim_nav_node`) take
the same private parameter, read here once: a built-in robot name
(``turtlebot3_waffle``) or the path of a robot YAML file, exactly what ``navseq run
--robot`` accepts (:func:`navseq.mission.robot_format.robot_from_option`). The profile
becomes the simulator's settings through :meth:`navseq.sim.profile.SimSettings.of`, the
function the in-process simulator uses, so a ROS sim and ``navseq run`` with the same
robot have the same outline, limits, inflation and tolerances.
"""

from __future__ import annotations

import rospy

from navseq.errors import NavseqError
from navseq.mission.robot import BUILTIN_PROFILES, DEFAULT_PROFILE, RobotProfile
from navseq.mission.robot_format import robot_from_option
from navseq.ros1.params import param_error
from navseq.sim.profile import SimSettings

ROBOT_PARAM = "robot"


def robot_param(name: str = ROBOT_PARAM) -> RobotProfile:
    """``~name``: a built-in robot name or a robot YAML file; the burger when unset.

    A bad value is a :class:`NavseqError` whose source is the resolved parameter name
    (``param /sim_robot/robot``), so the node logs one line that says which parameter to
    fix; a problem inside a robot file keeps its file:line too.
    """
    value = rospy.get_param(f"~{name}", DEFAULT_PROFILE.name)
    if not isinstance(value, str) or not value.strip():
        raise param_error(
            name,
            f"expected a built-in robot name ({', '.join(BUILTIN_PROFILES)}) or the path of "
            f"a robot YAML file, got {value!r}",
        )
    try:
        return robot_from_option(value)
    except NavseqError as error:
        # robot_from_option speaks of the CLI's --robot; here the culprit is the param.
        message = error.message if error.source == "--robot" else str(error)
        raise param_error(name, message) from None


def sim_settings_param(name: str = ROBOT_PARAM) -> SimSettings:
    """The simulator's settings for the robot that ``~name`` names."""
    return SimSettings.of(robot_param(name))


def describe_settings(settings: SimSettings) -> str:
    """One log line's worth: which robot, and the numbers a user would check first."""
    profile = settings.profile
    limits = settings.nav_params.limits
    return (
        f"robot {profile.name} ({profile.source}): footprint {len(profile.footprint)} points, "
        f"circumscribed {settings.footprint.circumscribed_radius:.3f} m, "
        f"max {limits.max_v:g} m/s / {limits.max_w:g} rad/s"
    )


__all__ = ["ROBOT_PARAM", "describe_settings", "robot_param", "sim_settings_param"]
