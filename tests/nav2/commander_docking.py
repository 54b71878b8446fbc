"""nav2_simple_commander's assisted teleop and docking calls, as Nav2's examples make them.

usage: commander_docking.py  (run with the real Nav2 tree's ROS 2 environment, against a
simulator started with examples/turtlebot3_docks.yaml)

What ``example_assisted_teleop.py`` does (``assistedTeleop(time_allowance)``, then
``isTaskComplete`` until the allowance ends it) with a 2 s allowance, then
``dockRobotByID('home_dock')``, ``undockRobot()`` and ``dockRobotByPose`` at the north
dock: each call's ``TaskResult`` name, and for docking ``getResult``'s companion, the
robot's pose from ``amcl_pose`` (transient local, as the commander reads it). Prints one
JSON object. Every call goes through ``BasicNavigator`` unchanged: a call the server
does not answer hangs, and the test's timeout says so.
"""

from __future__ import annotations

import json
import math
import sys

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator


def pose(navigator: BasicNavigator, x: float, y: float, yaw: float = 0.0) -> PoseStamped:
    stamped = PoseStamped()
    stamped.header.frame_id = "map"
    stamped.header.stamp = navigator.get_clock().now().to_msg()
    stamped.pose.position.x = x
    stamped.pose.position.y = y
    stamped.pose.orientation.z = math.sin(yaw / 2)
    stamped.pose.orientation.w = math.cos(yaw / 2)
    return stamped


def finish(navigator: BasicNavigator) -> str:
    while not navigator.isTaskComplete():
        pass
    return str(navigator.getResult().name)


def main() -> int:
    rclpy.init()
    navigator = BasicNavigator()
    out: dict[str, object] = {}
    navigator.setInitialPose(pose(navigator, -2.0, -0.5))
    navigator.waitUntilNav2Active()
    out["assistedTeleop accepted"] = navigator.assistedTeleop(time_allowance=2)
    out["assistedTeleop"] = finish(navigator)
    navigator.dockRobotByID("home_dock")
    out["dockRobotByID"] = finish(navigator)
    navigator.undockRobot()
    out["undockRobot"] = finish(navigator)
    navigator.dockRobotByPose(pose(navigator, -0.5, 0.5), "")
    out["dockRobotByPose"] = finish(navigator)
    print(json.dumps(out), flush=True)
    navigator.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
