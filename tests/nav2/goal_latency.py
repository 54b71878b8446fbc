"""Goal round trips to ``navigate_to_pose`` servers, alternating between them.

usage: goal_latency.py --rounds N X,Y,YAW_DEG ACTION [ACTION ...]

Each round sends every ACTION one goal at (X, Y, YAW) in ``map`` — where the robot
already stands, so a Nav2 server succeeds without driving — and times, in wall ms,
``send_goal`` -> accepted and ``send_goal`` -> result. The first round is a warm-up
(discovery, first allocations) and is not counted. Prints one JSON object:
``{ACTION: {"accepted": [ms...], "result": [ms...], "statuses": {...}}}``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections import Counter
from typing import Any

import rclpy
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionClient
from rclpy.node import Node

STATUS = {4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}


def goal_at(text: str) -> NavigateToPose.Goal:
    x, y, yaw_deg = (float(value) for value in text.split(","))
    goal = NavigateToPose.Goal()
    goal.pose.header.frame_id = "map"
    goal.pose.pose.position.x, goal.pose.pose.position.y = x, y
    yaw = math.radians(yaw_deg)
    goal.pose.pose.orientation.z, goal.pose.pose.orientation.w = (
        math.sin(yaw / 2),
        math.cos(yaw / 2),
    )
    return goal


def wait(node: Node, future: Any, timeout: float = 30.0) -> Any:
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout)
    if not future.done():
        raise SystemExit("no answer within 30 s")
    return future.result()


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=50)
    parser.add_argument("pose")
    parser.add_argument("actions", nargs="+")
    args = parser.parse_args()
    rclpy.init()
    node = Node("navseq_goal_latency")
    goal = goal_at(args.pose)
    clients = {action: ActionClient(node, NavigateToPose, action) for action in args.actions}
    for action, client in clients.items():
        if not client.wait_for_server(timeout_sec=60.0):
            raise SystemExit(f"no {action} server")
    out: dict[str, dict[str, Any]] = {
        action: {"accepted": [], "result": [], "statuses": Counter()} for action in args.actions
    }
    for round_ in range(args.rounds + 1):
        for action, client in clients.items():
            started = time.perf_counter()
            handle = wait(node, client.send_goal_async(goal))
            accepted = time.perf_counter()
            result = wait(node, handle.get_result_async()) if handle.accepted else None
            ended = time.perf_counter()
            if round_ == 0:
                continue
            seen = out[action]
            seen["accepted"].append((accepted - started) * 1000)
            seen["result"].append((ended - started) * 1000)
            seen["statuses"][
                STATUS.get(result.status, str(result.status)) if result else "REJECTED"
            ] += 1
    print(json.dumps(out), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
