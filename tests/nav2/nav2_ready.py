"""Wait until a real Nav2 on its loopback simulator takes goals, with the robot at a pose.

usage: nav2_ready.py X Y YAW_DEG [--timeout S]

Run with a ROS 2 environment (``tests/nav2_real_support.py``). Publishes the pose on
``/initialpose`` (map frame) until ``map -> base_footprint`` on ``/tf`` puts the robot
there, then waits for bt_navigator's ``navigate_to_pose`` and prints ``ready``. The loopback
simulator starts from the first initial pose and teleports the robot on every later one,
so the same script puts the robot back at a start pose between missions. Exit 0 when
ready, 1 on the timeout.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import rclpy
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionClient
from tf2_msgs.msg import TFMessage

from navseq.geometry import FrameTree
from navseq.ros2.messages import add_transforms

PLACED_WITHIN = 0.05  # m between the asked pose and the one /tf gives


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("x", type=float)
    parser.add_argument("y", type=float)
    parser.add_argument("yaw_deg", type=float)
    parser.add_argument("--timeout", type=float, default=90.0)
    args = parser.parse_args()
    rclpy.init()
    node = rclpy.create_node("navseq_nav2_ready")
    publisher = node.create_publisher(PoseWithCovarianceStamped, "/initialpose", 10)
    tree = FrameTree()
    node.create_subscription(TFMessage, "/tf", lambda m: add_transforms(tree, m), 100)
    client = ActionClient(node, NavigateToPose, "navigate_to_pose")
    yaw = math.radians(args.yaw_deg)
    deadline = time.monotonic() + args.timeout
    sent_at = -1.0
    try:
        while time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.05)
            pose = tree.lookup("map", "base_footprint")
            placed = pose is not None and math.hypot(pose.x - args.x, pose.y - args.y) < (
                PLACED_WITHIN
            )
            if placed and client.server_is_ready():
                print("ready", flush=True)
                return 0
            if not placed and time.monotonic() - sent_at > 1.0:
                message = PoseWithCovarianceStamped()
                message.header.frame_id = "map"
                message.pose.pose.position.x = args.x
                message.pose.pose.position.y = args.y
                message.pose.pose.orientation.z = math.sin(yaw / 2)
                message.pose.pose.orientation.w = math.cos(yaw / 2)
                publisher.publish(message)
                sent_at = time.monotonic()
        print("nav2_ready: timed out", file=sys.stderr)
        return 1
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
