"""The stand-in's republished paths and costmap updates, with plain rclpy
(tests/test_ros2_updates.py).

    python updates_client.py '{"map": "changed.yaml", "goal": [-1.5, -0.5]}'

In order, every wait bounded: both full costmaps (transient local); ``map_server/load_map``
with a map that differs from the running one in a few cells, then the updates on
``*/costmap_updates`` and ``*/costmap_raw_updates``; a ``smooth_path`` goal, watching
``plan_smoothed``; a ``navigate_to_pose`` goal, watching ``plan`` and
``received_global_plan`` (the goal is cancelled then). Prints one JSON line.
"""

from __future__ import annotations

import json
import sys
import time
from typing import Any

import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import NavigateToPose, SmoothPath
from nav2_msgs.msg import Costmap, CostmapUpdate
from nav2_msgs.srv import LoadMap
from nav_msgs.msg import OccupancyGrid, Path
from rclpy.action import ActionClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

try:  # Nav2's build has map_msgs; a minimal ROS 2 may not (then only the raw updates)
    from map_msgs.msg import OccupancyGridUpdate
except ImportError:
    OccupancyGridUpdate = None

LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
COSTMAPS = ("global_costmap", "local_costmap")
FULL_TOPICS = ("costmap", "costmap_raw")


def pose(x: float, y: float) -> PoseStamped:
    stamped = PoseStamped()
    stamped.header.frame_id = "map"
    stamped.pose.position.x, stamped.pose.position.y = x, y
    stamped.pose.orientation.w = 1.0
    return stamped


def points(path: Any) -> list[list[float]]:
    return [[round(p.pose.position.x, 4), round(p.pose.position.y, 4)] for p in path.poses]


def _size(update: Any) -> list[int]:
    if isinstance(update, CostmapUpdate):
        return [update.size_x, update.size_y]
    return [update.width, update.height]


def main() -> int:
    setup = json.loads(sys.argv[1])
    rclpy.init()
    node = rclpy.create_node("updates_client")
    seen: dict[str, list[Any]] = {}

    def subscribe(kind: Any, topic: str, qos: Any) -> None:
        seen[topic] = []
        node.create_subscription(kind, f"/{topic}", seen[topic].append, qos)

    for name in COSTMAPS:
        subscribe(OccupancyGrid, f"{name}/costmap", LATCHED)
        subscribe(Costmap, f"{name}/costmap_raw", LATCHED)
        subscribe(CostmapUpdate, f"{name}/costmap_raw_updates", LATCHED)
        if OccupancyGridUpdate is not None:
            subscribe(OccupancyGridUpdate, f"{name}/costmap_updates", LATCHED)
    for topic in ("plan", "received_global_plan", "plan_smoothed"):
        subscribe(Path, topic, 10)

    def spin_until(condition: Any, seconds: float) -> bool:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if condition():
                return True
            rclpy.spin_once(node, timeout_sec=0.05)
        return bool(condition())

    def wait_future(future: Any, seconds: float) -> Any:
        spin_until(future.done, seconds)
        return future.result() if future.done() else None

    update_kinds = [
        kind
        for kind in ("costmap_updates", "costmap_raw_updates")
        if kind in [topic.rsplit("/", 1)[-1] for topic in seen]
    ]
    out: dict[str, Any] = {"update_topics": update_kinds}
    # -- the full costmaps first, then a map that differs in a few cells ----------------
    spin_until(lambda: all(seen[f"{name}/{full}"] for name in COSTMAPS for full in FULL_TOPICS), 60)
    out["updates_before_change"] = sum(
        len(seen[f"{name}/{kind}"]) for name in COSTMAPS for kind in update_kinds
    )
    full = {name: seen[f"{name}/costmap_raw"][-1] for name in COSTMAPS}
    loader = node.create_client(LoadMap, "/map_server/load_map")
    loader.wait_for_service(timeout_sec=20)
    request = LoadMap.Request()
    request.map_url = setup["map"]
    answer = wait_future(loader.call_async(request), 20)
    out["load_map"] = None if answer is None else answer.result
    spin_until(
        lambda: all(seen[f"{name}/{kind}"] for name in COSTMAPS for kind in update_kinds),
        20,
    )
    for name in COSTMAPS:
        raw_updates = seen[f"{name}/costmap_raw_updates"]
        updates = seen.get(f"{name}/costmap_updates", raw_updates)
        if not updates or not raw_updates:
            out[name] = None
            continue
        raw = raw_updates[0]
        update = updates[0]
        # The full costmap after the change, to check the update's cells against.
        after = seen[f"{name}/costmap_raw"][-1]
        width = after.metadata.size_x
        cells = [
            after.data[(raw.y + row) * width + raw.x + col]
            for row in range(raw.size_y)
            for col in range(raw.size_x)
        ]
        before = full[name]
        out[name] = {
            "frame": update.header.frame_id,
            "bounds": [update.x, update.y, *_size(update)],
            "raw_bounds": [raw.x, raw.y, raw.size_x, raw.size_y],
            "data_sizes": [len(update.data), len(raw.data)],
            "raw_matches_full_costmap": list(raw.data) == cells,
            # Lethal: 100 in an OccupancyGridUpdate, 254 in a raw one.
            "lethal_cells": sum(1 for value in update.data if value in (100, 254)),
            "full_size": [after.metadata.size_x, after.metadata.size_y],
            "same_size_as_before": [before.metadata.size_x, before.metadata.size_y]
            == [after.metadata.size_x, after.metadata.size_y],
        }

    # -- smooth_path: its result on plan_smoothed ---------------------------------------
    smoother = ActionClient(node, SmoothPath, "/smooth_path")
    smoother.wait_for_server(timeout_sec=20)
    goal = SmoothPath.Goal()
    goal.path.header.frame_id = "map"
    goal.path.poses = [pose(-2.0, -0.5), pose(-1.8, -0.3), pose(-1.6, -0.5), pose(-1.4, -0.3)]
    handle = wait_future(smoother.send_goal_async(goal), 20)
    result = wait_future(handle.get_result_async(), 20) if handle is not None else None
    spin_until(lambda: seen["plan_smoothed"], 10)
    out["smoothed_result"] = points(result.result.path) if result is not None else None
    out["plan_smoothed"] = [points(path) for path in seen["plan_smoothed"]]

    # -- navigate_to_pose: the controller's copy of the plan ----------------------------
    navigator = ActionClient(node, NavigateToPose, "/navigate_to_pose")
    navigator.wait_for_server(timeout_sec=20)
    nav_goal = NavigateToPose.Goal()
    nav_goal.pose = pose(*setup["goal"])
    nav_handle = wait_future(navigator.send_goal_async(nav_goal), 20)
    spin_until(lambda: seen["received_global_plan"] and seen["plan"], 20)
    if nav_handle is not None:
        wait_future(nav_handle.cancel_goal_async(), 10)
    received = seen["received_global_plan"]
    out["received_global_plan"] = points(received[0]) if received else None
    out["received_frame"] = received[0].header.frame_id if received else None
    out["plan"] = points(seen["plan"][0]) if seen["plan"] else None
    print(json.dumps(out))
    node.destroy_node()
    rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
