"""Where the robot was when each goal ended: a bystander beside a Nav2 client script.

usage: goal_witness.py [--ns NS]  (run with a ROS 2 environment; stop it with SIGINT)

Listens to the status topics of the actions that move the robot (as ``ros2 action
info`` would find them) and to ``/tf`` (``map -> odom -> base_footprint``); prints one
JSON line per goal as it reaches a terminal status: the action, the status name and the
robot's map pose (x, y, yaw) at that moment. Prints ``watching`` once subscribed. The
script under test stays unchanged: this is how a test sees where an endless script
(``demo_security``) sent the robot.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
from collections.abc import Callable

import rclpy
from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

MOVING_ACTIONS = (
    "navigate_to_pose",
    "navigate_through_poses",
    "follow_waypoints",
    "follow_path",
    "spin",
    "backup",
    "drive_on_heading",
    "assisted_teleop",
)
TERMINAL = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
}
# The action status topics' QoS (rclpy's qos_profile_action_status_default).
STATUS_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--ns", default="")
    args = parser.parse_args()
    prefix = f"/{args.ns.strip('/')}" if args.ns.strip("/") else ""
    rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    node = Node("navseq_goal_witness")
    frames: dict[str, tuple[float, float, float]] = {}
    seen: set[bytes] = set()

    def on_tf(message: TFMessage) -> None:
        for transform in message.transforms:
            t, q = transform.transform.translation, transform.transform.rotation
            key = "odom" if transform.child_frame_id.endswith("odom") else "base"
            frames[key] = (t.x, t.y, 2 * math.atan2(q.z, q.w))

    def map_pose() -> list[float] | None:
        if len(frames) < 2:
            return None
        (ox, oy, oyaw), (bx, by, byaw) = frames["odom"], frames["base"]
        return [
            round(ox + bx * math.cos(oyaw) - by * math.sin(oyaw), 3),
            round(oy + bx * math.sin(oyaw) + by * math.cos(oyaw), 3),
            round(math.remainder(oyaw + byaw, math.tau), 3),
        ]

    def on_status(action: str) -> Callable[[GoalStatusArray], None]:
        def callback(message: GoalStatusArray) -> None:
            for status in message.status_list:
                goal = bytes(status.goal_info.goal_id.uuid)
                if status.status in TERMINAL and goal not in seen:
                    seen.add(goal)
                    record = {"action": action, "status": TERMINAL[status.status]}
                    print(json.dumps({**record, "pose": map_pose()}), flush=True)

        return callback

    node.create_subscription(TFMessage, f"{prefix}/tf", on_tf, 100)
    for action in MOVING_ACTIONS:
        node.create_subscription(
            GoalStatusArray, f"{prefix}/{action}/_action/status", on_status(action), STATUS_QOS
        )
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(True))
    signal.signal(signal.SIGTERM, lambda *_: stop.append(True))
    print("watching", flush=True)
    while not stop:
        rclpy.spin_once(node, timeout_sec=0.05)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
