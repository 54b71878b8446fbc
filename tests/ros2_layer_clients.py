"""rclpy clients for the costmap-layer and collision-monitor tests, run as subprocesses.

``python tests/ros2_layer_clients.py VERB`` prints one JSON object on its last stdout
line: what it saw. Verbs:

- ``layers``: the static layer (``global_costmap/static_layer_raw``, latched, and
  ``get_static_layer``), the obstacle layer (``get_obstacle_layer``), the voxel layer's
  grid and clearing endpoints, and ``local_costmap/published_footprint`` before and after
  a footprint is published on ``local_costmap/footprint``;
- ``lifecycle``: both costmap nodes' ``get_state`` after start, after
  ``lifecycle_manager_navigation`` PAUSE and after RESUME, with the transitions
  ``global_costmap/global_costmap/transition_event`` said meanwhile;
- ``monitor``: ``cmd_vel_smoothed`` at 0.2 m/s (20 Hz) for ``--seconds`` with the robot
  facing an obstacle, then ``collision_monitor/toggle`` off and as long again: the
  ``collision_monitor_state`` messages, ``cmd_vel``'s linear speeds in each half, and
  whether ``collision_monitor/collision_points_marker`` had points.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import rclpy
from geometry_msgs.msg import Point32, Polygon, PolygonStamped, Twist
from lifecycle_msgs.msg import TransitionEvent
from lifecycle_msgs.srv import GetState
from nav2_msgs.msg import CollisionMonitorState, VoxelGrid
from nav2_msgs.msg import Costmap as CostmapMsg
from nav2_msgs.srv import GetCostmap, ManageLifecycleNodes, Toggle
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import PointCloud2
from visualization_msgs.msg import MarkerArray

LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
TIMEOUT = 30.0


def wait(node: Node, future: Any) -> Any:
    rclpy.spin_until_future_complete(node, future, timeout_sec=TIMEOUT)
    if not future.done():
        raise SystemExit(f"timed out after {TIMEOUT} s")
    return future.result()


def call(node: Node, kind: Any, service: str, request: Any) -> Any:
    client = node.create_client(kind, service)
    if not client.wait_for_service(timeout_sec=TIMEOUT):
        raise SystemExit(f"no {service}")
    return wait(node, client.call_async(request))


def first(node: Node, kind: Any, topic: str, qos: Any = 10, check: Any = None) -> Any:
    """The first message on ``topic`` that passes ``check``."""
    got: list[Any] = []

    def take(message: Any) -> None:
        if not got and (check is None or check(message)):
            got.append(message)

    subscription = node.create_subscription(kind, topic, take, qos)
    deadline = time.monotonic() + TIMEOUT
    while not got and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_subscription(subscription)
    if not got:
        raise SystemExit(f"nothing on {topic}")
    return got[0]


def costmap_summary(message: Any) -> dict:
    data = list(message.data)
    return {
        "size": [message.metadata.size_x, message.metadata.size_y],
        "resolution": message.metadata.resolution,
        "origin": [message.metadata.origin.position.x, message.metadata.origin.position.y],
        "frame": message.header.frame_id,
        "data": data,
    }


def layers(node: Node, args: argparse.Namespace) -> dict:
    out: dict[str, Any] = {}
    out["static_topic"] = costmap_summary(
        first(node, CostmapMsg, "global_costmap/static_layer_raw", LATCHED)
    )
    reply = call(node, GetCostmap, "global_costmap/get_static_layer", GetCostmap.Request())
    out["static_service"] = costmap_summary(reply.map)
    reply = call(node, GetCostmap, "global_costmap/get_obstacle_layer", GetCostmap.Request())
    out["obstacle_service"] = costmap_summary(reply.map)
    voxels = first(node, VoxelGrid, "local_costmap/voxel_grid")
    out["voxel_grid"] = {
        "size": [voxels.size_x, voxels.size_y, voxels.size_z],
        "frame": voxels.header.frame_id,
        "columns": sorted(set(voxels.data)),
    }
    cloud = first(node, PointCloud2, "local_costmap/clearing_endpoints")
    out["clearing_endpoints"] = {"points": cloud.width, "frame": cloud.header.frame_id}
    before = first(node, PolygonStamped, "local_costmap/published_footprint")
    out["footprint_before"] = [[p.x, p.y] for p in before.polygon.points]
    publisher = node.create_publisher(Polygon, "local_costmap/footprint", 10)
    square = [(0.2, 0.2), (0.2, -0.2), (-0.2, -0.2), (-0.2, 0.2)]
    message = Polygon(points=[Point32(x=x, y=y, z=0.0) for x, y in square])
    deadline = time.monotonic() + TIMEOUT
    after = None
    while after is None and time.monotonic() < deadline:
        publisher.publish(message)
        seen = first(node, PolygonStamped, "local_costmap/published_footprint")
        if (
            len(seen.polygon.points) == 4
            and abs(
                max(p.x for p in seen.polygon.points) - min(p.x for p in seen.polygon.points) - 0.4
            )
            < 1e-3
        ):
            after = seen
    out["footprint_after"] = None if after is None else [[p.x, p.y] for p in after.polygon.points]
    return out


def states(node: Node) -> dict:
    return {
        costmap: call(
            node, GetState, f"{costmap}/{costmap}/get_state", GetState.Request()
        ).current_state.label
        for costmap in ("global_costmap", "local_costmap")
    }


def lifecycle(node: Node, args: argparse.Namespace) -> dict:
    events: list[str] = []
    node.create_subscription(
        TransitionEvent,
        "global_costmap/global_costmap/transition_event",
        lambda message: events.append(message.goal_state.label),
        10,
    )
    out: dict[str, Any] = {"started": states(node)}
    manage = "lifecycle_manager_navigation/manage_nodes"
    for command in ("PAUSE", "RESUME"):
        request = ManageLifecycleNodes.Request(
            command=getattr(ManageLifecycleNodes.Request, command)
        )
        out[f"{command.lower()}_success"] = call(
            node, ManageLifecycleNodes, manage, request
        ).success
        out[command.lower()] = states(node)
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    out["events"] = events
    return out


def monitor(node: Node, args: argparse.Namespace) -> dict:
    seen: list[list[Any]] = []
    speeds: list[float] = []
    marked: list[int] = []
    node.create_subscription(
        CollisionMonitorState,
        "collision_monitor_state",
        lambda m: seen.append([m.action_type, m.polygon_name]),
        10,
    )
    node.create_subscription(Twist, "cmd_vel", lambda m: speeds.append(m.linear.x), 10)
    node.create_subscription(
        MarkerArray,
        "collision_monitor/collision_points_marker",
        lambda m: marked.append(sum(len(marker.points) for marker in m.markers)),
        10,
    )
    publisher = node.create_publisher(Twist, "cmd_vel_smoothed", 10)
    command = Twist()
    command.linear.x = 0.2

    def drive(seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            publisher.publish(command)
            rclpy.spin_once(node, timeout_sec=0.05)

    drive(args.seconds)
    out: dict[str, Any] = {"states_on": list(seen), "speeds_on": list(speeds)}
    reply = call(node, Toggle, "collision_monitor/toggle", Toggle.Request(enable=False))
    out["toggle"] = [reply.success, reply.message]
    speeds.clear()
    drive(args.seconds / 2)
    out["speeds_off"] = list(speeds)
    out["states_all"] = seen
    out["marker_points"] = max(marked, default=0)
    publisher.publish(Twist())
    return out


VERBS = {"layers": layers, "lifecycle": lifecycle, "monitor": monitor}


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("verb", choices=sorted(VERBS))
    parser.add_argument("--seconds", type=float, default=6.0)
    args = parser.parse_args()
    rclpy.init()
    node = Node(f"navseq_test_{args.verb}")
    try:
        print(json.dumps(VERBS[args.verb](node, args)), flush=True)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
