"""nav2_simple_commander's path and behaviour calls, as Nav2's example scripts make them.

usage: commander_paths.py  (run with the real Nav2 tree's ROS 2 environment)

What ``example_follow_path.py`` and ``demo_recoveries.py`` do, with the poses moved onto
the TurtleBot3 arena: an initial pose at (-2, -0.5), ``waitUntilNav2Active``, then
``getPath`` → ``smoothPath`` → ``followPath`` to (-0.6, -0.5), ``getPathThroughPoses``
through two poses, ``getGlobalCostmap`` / ``getLocalCostmap``, ``spin``, ``backup`` and
``driveOnHeading``. Prints one JSON object: each call's ``TaskResult`` name and what came
back. Every call goes through ``BasicNavigator`` unchanged: a call the server does not
answer hangs, and the test's timeout says so.
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
    feedback = 0
    while not navigator.isTaskComplete():
        if navigator.getFeedback() is not None:
            feedback += 1
    return f"{navigator.getResult().name} ({feedback} feedback)"


def main() -> int:
    rclpy.init()
    navigator = BasicNavigator()
    out: dict[str, object] = {}
    start = pose(navigator, -2.0, -0.5)
    navigator.setInitialPose(start)
    navigator.waitUntilNav2Active()
    goal = pose(navigator, -0.6, -0.5)
    path = navigator.getPath(start, goal)
    out["getPath"] = len(path.poses) if path else None
    smoothed = navigator.smoothPath(path)
    out["smoothPath"] = len(smoothed.poses) if smoothed else None
    navigator.followPath(smoothed)
    out["followPath"] = finish(navigator)
    through = navigator.getPathThroughPoses(
        goal, [pose(navigator, -0.6, 0.5), pose(navigator, -1.5, 0.5)]
    )
    out["getPathThroughPoses"] = len(through.poses) if through else None
    for which, costmap in (
        ("getGlobalCostmap", navigator.getGlobalCostmap()),
        ("getLocalCostmap", navigator.getLocalCostmap()),
    ):
        specs = costmap.metadata
        lethal = sum(1 for value in costmap.data if value == 254)
        out[which] = [
            specs.size_x,
            specs.size_y,
            round(specs.resolution, 3),
            lethal,
            costmap.header.frame_id,
        ]
    navigator.spin(spin_dist=1.57)
    out["spin"] = finish(navigator)
    navigator.backup(backup_dist=0.15, backup_speed=0.05)
    out["backup"] = finish(navigator)
    navigator.driveOnHeading(dist=0.15, speed=0.05)
    out["driveOnHeading"] = finish(navigator)
    print(json.dumps(out), flush=True)
    navigator.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
