"""The plainest ``navigate_to_pose`` server: rclpy's ActionServer, accepting every goal
and succeeding at once. The baseline of ``benchmarks/bench_standin.py``'s round trip.

usage: instant_nav_server.py [--ns NS]  (prints ``ready``; stop it with SIGINT)
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

import rclpy
from nav2_msgs.action import NavigateToPose
from rclpy.action import ActionServer
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--ns", default="instant")
    args = parser.parse_args()
    rclpy.init()
    node = Node("instant_nav_server", namespace=args.ns)

    def execute(goal: Any) -> NavigateToPose.Result:
        goal.succeed()
        return NavigateToPose.Result()

    ActionServer(node, NavigateToPose, "navigate_to_pose", execute)
    print("ready", flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
