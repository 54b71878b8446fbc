"""Real rclpy clients of the route server, the behaviour tree's topics and the docking
topics, run as subprocesses by the ROS 2 tests (like ``tests/ros2_clients.py``).

``python tests/ros2_route_clients.py VERB [options]`` prints one JSON object on its last
stdout line: what it saw. Verbs:

- ``route START GOAL``: a ``compute_route`` goal; START and GOAL are node ids (``7``) or
  poses ``X,Y`` (then ``use_poses``; START ``robot``: from the robot's pose);
- ``track START GOAL``: ``compute_and_track_route`` as navigation2's ``example_route.py``
  drives it: each rerouted feedback's path goes to ``follow_path``; the feedback's node
  ids, both results and the robot's final pose (``map -> odom -> base`` on ``/tf``);
- ``interrupt START GOAL``: ``compute_and_track_route`` with nothing driving the robot:
  after its first feedback a ``route_server/ReroutingService/reroute`` call, then a
  second goal (which preempts the first), then a cancel of the second; the statuses and
  the feedback's ``rerouted`` flags of each;
- ``graph``: the ``route_graph`` markers (transient local) and a ``set_route_graph`` call
  with ``--file``;
- ``btlog X,Y X,Y``: ``behavior_tree_log`` while two ``navigate_to_pose`` goals run one
  after the other, and the selectors' topics: publishes ``--controller`` on
  ``controller_selector`` first when given;
- ``dockposes DOCK_ID``: a ``dock_robot`` goal while ``detected_dock_pose``,
  ``filtered_dock_pose`` and ``docking_trajectory`` are recorded.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from typing import Any

import rclpy
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import (
    ComputeAndTrackRoute,
    ComputeRoute,
    DockRobot,
    FollowPath,
    NavigateToPose,
)
from nav2_msgs.msg import BehaviorTreeLog
from nav2_msgs.srv import SetRouteGraph
from nav_msgs.msg import Path
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

STATUS = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
}
LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def pose_stamped(text: str) -> PoseStamped:
    x, y = (float(part) for part in text.split(",")[:2])
    pose = PoseStamped()
    pose.header.frame_id = "map"
    pose.pose.position.x = x
    pose.pose.position.y = y
    pose.pose.orientation.w = 1.0
    return pose


def wait(node: Node, future: Any, timeout: float) -> Any:
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout)
    if not future.done():
        raise SystemExit(f"timed out after {timeout} s")
    return future.result()


def spin_for(node: Node, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)


def client(node: Node, action: Any, name: str, timeout: float) -> ActionClient:
    found = ActionClient(node, action, name)
    if not found.wait_for_server(timeout_sec=timeout):
        raise SystemExit(f"no {name} server")
    return found


def route_goal(action: Any, start: str, goal: str) -> Any:
    message = action.Goal()
    if "," in goal:
        message.use_poses = True
        message.goal = pose_stamped(goal)
        if start != "robot":
            message.use_start = True
            message.start = pose_stamped(start)
    else:
        message.start_id, message.goal_id = int(start), int(goal)
    return message


def robot_pose(node: Node, timeout: float) -> list[float] | None:
    """The robot in the map frame: ``map -> odom`` after ``odom -> base_footprint``."""
    seen: dict[str, tuple[float, float, float]] = {}

    def on_tf(message: TFMessage) -> None:
        for transform in message.transforms:
            t, q = transform.transform.translation, transform.transform.rotation
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            seen[transform.child_frame_id] = (t.x, t.y, yaw)

    subscription = node.create_subscription(TFMessage, "/tf", on_tf, 100)
    end = time.monotonic() + timeout
    while ("odom" not in seen or "base_footprint" not in seen) and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    node.destroy_subscription(subscription)
    if "odom" not in seen or "base_footprint" not in seen:
        return None
    (ox, oy, oyaw), (bx, by, _) = seen["odom"], seen["base_footprint"]
    return [
        ox + bx * math.cos(oyaw) - by * math.sin(oyaw),
        oy + bx * math.sin(oyaw) + by * math.cos(oyaw),
    ]


def route(node: Node, args: argparse.Namespace) -> dict:
    found = client(node, ComputeRoute, "compute_route", args.timeout)
    handle = wait(
        node, found.send_goal_async(route_goal(ComputeRoute, *args.poses[:2])), args.timeout
    )
    if not handle.accepted:
        return {"accepted": False}
    result = wait(node, handle.get_result_async(), args.timeout)
    answer = result.result
    return {
        "status": STATUS.get(result.status, str(result.status)),
        "error_code": int(answer.error_code),
        "nodes": [int(n.nodeid) for n in answer.route.nodes],
        "edges": [int(e.edgeid) for e in answer.route.edges],
        "route_cost": float(answer.route.route_cost),
        "path": [[p.pose.position.x, p.pose.position.y] for p in answer.path.poses],
        "frame": answer.path.header.frame_id,
    }


def track(node: Node, args: argparse.Namespace) -> dict:
    tracker = client(node, ComputeAndTrackRoute, "compute_and_track_route", args.timeout)
    follower = client(node, FollowPath, "follow_path", args.timeout)
    feedback: list[dict] = []
    follows: list[Any] = []

    def on_feedback(message: Any) -> None:
        fb = message.feedback
        feedback.append(
            {
                "rerouted": bool(fb.rerouted),
                "last": int(fb.last_node_id),
                "next": int(fb.next_node_id),
                "edge": int(fb.current_edge_id),
                "nodes": [int(n.nodeid) for n in fb.route.nodes],
            }
        )
        if fb.rerouted:  # example_route.py: pass the new route to the controller
            follows.append(follower.send_goal_async(FollowPath.Goal(path=fb.path)))

    goal = route_goal(ComputeAndTrackRoute, *args.poses[:2])
    handle = wait(node, tracker.send_goal_async(goal, feedback_callback=on_feedback), args.timeout)
    if not handle.accepted:
        return {"accepted": False}
    result = wait(node, handle.get_result_async(), args.timeout)
    follow_status = None
    if follows:
        follow_handle = wait(node, follows[-1], args.timeout)
        follow_result = wait(node, follow_handle.get_result_async(), args.timeout)
        follow_status = STATUS.get(follow_result.status, str(follow_result.status))
    return {
        "status": STATUS.get(result.status, str(result.status)),
        "error_code": int(result.result.error_code),
        "feedback": feedback,
        "follow_path": follow_status,
        "pose": robot_pose(node, args.timeout),
    }


def interrupt(node: Node, args: argparse.Namespace) -> dict:
    tracker = client(node, ComputeAndTrackRoute, "compute_and_track_route", args.timeout)
    rerouted: dict[int, list[bool]] = {1: [], 2: []}

    def watch(goal_number: int) -> Any:
        return lambda message: rerouted[goal_number].append(bool(message.feedback.rerouted))

    def until(condition: Any) -> None:
        end = time.monotonic() + args.timeout
        while not condition() and time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)

    goal = route_goal(ComputeAndTrackRoute, *args.poses[:2])
    first = wait(node, tracker.send_goal_async(goal, feedback_callback=watch(1)), args.timeout)
    until(lambda: rerouted[1])
    service = node.create_client(Trigger, "route_server/ReroutingService/reroute")
    if not service.wait_for_service(timeout_sec=args.timeout):
        raise SystemExit("no reroute service")
    answer = wait(node, service.call_async(Trigger.Request()), args.timeout)
    until(lambda: rerouted[1].count(True) >= 2)
    second = wait(node, tracker.send_goal_async(goal, feedback_callback=watch(2)), args.timeout)
    first_result = wait(node, first.get_result_async(), args.timeout)
    until(lambda: rerouted[2])
    wait(node, second.cancel_goal_async(), args.timeout)
    second_result = wait(node, second.get_result_async(), args.timeout)
    return {
        "reroute_answer": bool(answer.success),
        "first": STATUS.get(first_result.status, str(first_result.status)),
        "second": STATUS.get(second_result.status, str(second_result.status)),
        "rerouted": [rerouted[1], rerouted[2]],
    }


def graph(node: Node, args: argparse.Namespace) -> dict:
    markers: list[MarkerArray] = []
    node.create_subscription(MarkerArray, "route_graph", markers.append, LATCHED)
    end = time.monotonic() + args.timeout
    while not markers and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)

    def nodes_drawn() -> int:
        spheres = [m for m in markers[-1].markers if m.ns == "route_graph_nodes"]
        return len(spheres[0].points) if spheres else -1

    out: dict[str, Any] = {"nodes_drawn": nodes_drawn() if markers else None}
    service = node.create_client(SetRouteGraph, "route_server/set_route_graph")
    if not service.wait_for_service(timeout_sec=args.timeout):
        raise SystemExit("no set_route_graph")
    answer = wait(
        node, service.call_async(SetRouteGraph.Request(graph_filepath=args.file)), args.timeout
    )
    out["success"] = bool(answer.success)
    spin_for(node, 0.5)
    out["nodes_drawn_after"] = nodes_drawn() if markers else None
    return out


def btlog(node: Node, args: argparse.Namespace) -> dict:
    events: list[list[Any]] = []
    messages = 0

    def on_log(message: BehaviorTreeLog) -> None:
        nonlocal messages
        messages += 1
        events.extend(
            [e.node_name, int(e.uid), e.previous_status, e.current_status]
            for e in message.event_log
        )

    node.create_subscription(BehaviorTreeLog, "behavior_tree_log", on_log, 100)
    if args.controller:
        publisher = node.create_publisher(String, "controller_selector", LATCHED)
        publisher.publish(String(data=args.controller))
        spin_for(node, 1.0)
    navigator = client(node, NavigateToPose, "navigate_to_pose", args.timeout)
    results = []
    for target in args.poses:
        goal = NavigateToPose.Goal(pose=pose_stamped(target))
        handle = wait(node, navigator.send_goal_async(goal), args.timeout)
        outcome = wait(node, handle.get_result_async(), args.timeout)
        results.append(
            [STATUS.get(outcome.status, str(outcome.status)), int(outcome.result.error_code)]
        )
        spin_for(node, 0.5)
    return {"results": results, "events": events, "messages": messages}


def dockposes(node: Node, args: argparse.Namespace) -> dict:
    seen: dict[str, list[Any]] = {"detected": [], "filtered": [], "trajectory": []}

    def keep(key: str) -> Any:
        def store(message: Any) -> None:
            if isinstance(message, Path):
                seen[key].append(
                    [
                        message.header.frame_id,
                        [[p.pose.position.x, p.pose.position.y] for p in message.poses],
                    ]
                )
            else:
                p = message.pose.position
                seen[key].append([message.header.frame_id, p.x, p.y])

        return store

    node.create_subscription(PoseStamped, "detected_dock_pose", keep("detected"), 10)
    node.create_subscription(PoseStamped, "filtered_dock_pose", keep("filtered"), 10)
    node.create_subscription(Path, "docking_trajectory", keep("trajectory"), 10)
    docker = client(node, DockRobot, "dock_robot", args.timeout)
    goal = DockRobot.Goal(use_dock_id=True, dock_id=args.poses[0])
    handle = wait(node, docker.send_goal_async(goal), args.timeout)
    result = wait(node, handle.get_result_async(), args.timeout)
    spin_for(node, 0.3)
    return {"status": STATUS.get(result.status, str(result.status)), **seen}


VERBS = {
    "route": route,
    "track": track,
    "interrupt": interrupt,
    "graph": graph,
    "btlog": btlog,
    "dockposes": dockposes,
}


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("verb", choices=sorted(VERBS))
    parser.add_argument("poses", nargs="*")
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--file", default="")
    parser.add_argument("--controller", default="")
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
    raise SystemExit(main())
