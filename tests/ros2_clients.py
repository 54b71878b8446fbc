"""Real rclpy clients for the ROS 2 tests, run as subprocesses (never in pytest's process).

``python tests/ros2_clients.py VERB [options]`` does one thing a Nav2 user's client does
and prints one JSON object on its last stdout line: what it saw. Verbs:

- ``navigate X,Y,YAW``: a ``navigate_to_pose`` goal (``--delay`` before sending,
  ``--cancel-after`` seconds then a cancel and a watch of ``odom`` until the robot stands);
- ``through X,Y,YAW X,Y,YAW ...``: a ``navigate_through_poses`` goal;
- ``waypoints X,Y,YAW ...``: a ``follow_waypoints`` goal;
- ``path X,Y,YAW``: ``compute_path_to_pose`` from the robot;
- ``map``: subscribes to ``map`` late, transient local, like RViz or a costmap;
- ``behavior KIND``: a goal to the behaviour server's ``spin`` (``--value`` radians),
  ``backup`` / ``drive_on_heading`` (``--value`` metres at ``--speed``, ``--target-y``),
  or ``wait`` (``--value`` seconds), ``--allowance`` seconds of time allowance; says how
  far the robot turned and moved (its ``odom -> base`` transform on ``/tf``);
- ``teleop``: an ``assisted_teleop`` goal (``--allowance`` seconds) while the operator's
  ``cmd_vel_teleop`` says ``--speed`` m/s (10 Hz), then ``preempt_teleop`` after
  ``--value`` wall seconds (0: never); says how far the robot moved, as ``behavior``;
- ``dock DOCK_ID`` / ``undock``: ``dock_robot`` (by id; ``--value`` > 0 sets
  ``navigate_to_staging_pose`` false) / ``undock_robot`` goals, with their result fields,
  the feedback states and where the robot ended (``map -> odom -> base`` on ``/tf``);
- ``refusals``: goals the planner, smoother and controller servers refuse (no goals,
  unknown plugin ids, an empty path, a pose in an unknown frame), each one's status and
  error code;
- ``manage COMMAND``: ``lifecycle_manager_navigation/manage_nodes`` with COMMAND (pause,
  resume, reset, startup, shutdown) as ``nav2_simple_commander``'s lifecycle calls make
  it, then ``is_active``, bt_navigator's state, and whether a ``spin`` goal is accepted;
- ``filters``: the keepout filter's servers as a client of their lifecycle sees them:
  subscribed to the mask and its filter info from the start, then
  ``lifecycle_manager_keepout_zone/manage_nodes`` PAUSE and RESUME, each followed by
  ``is_active``, both servers' ``get_state`` and the mask server's ``map`` service; says
  how many masks and filter infos arrived (each activation publishes them);
- ``ready``: the lifecycle ``get_state`` of bt_navigator and amcl, then an
  ``initialpose`` and the ``amcl_pose`` that follows, then a clear-costmap call — what
  nav2_simple_commander's ``waitUntilNav2Active`` and ``clearAllCostmaps`` do.

``--ns NS`` puts every name in a namespace. Yaw is in degrees.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from typing import Any

import rclpy
from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from lifecycle_msgs.srv import GetState
from nav2_msgs.action import (
    AssistedTeleop,
    BackUp,
    ComputePathThroughPoses,
    ComputePathToPose,
    DockRobot,
    DriveOnHeading,
    FollowPath,
    FollowWaypoints,
    NavigateThroughPoses,
    NavigateToPose,
    SmoothPath,
    Spin,
    UndockRobot,
    Wait,
)
from nav2_msgs.srv import ClearEntireCostmap
from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

STATUS = {
    GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED",
    GoalStatus.STATUS_ABORTED: "ABORTED",
    GoalStatus.STATUS_CANCELED: "CANCELED",
}
LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def pose_stamped(text: str, frame: str = "map") -> PoseStamped:
    x, y, yaw = (float(part) for part in text.split(","))
    pose = PoseStamped()
    pose.header.frame_id = frame
    pose.pose.position.x = x
    pose.pose.position.y = y
    pose.pose.orientation.z = math.sin(math.radians(yaw) / 2)
    pose.pose.orientation.w = math.cos(math.radians(yaw) / 2)
    return pose


def name(ns: str, relative: str) -> str:
    return f"/{ns}/{relative}" if ns else relative


def wait(node: Node, future: Any, timeout: float) -> Any:
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout)
    if not future.done():
        raise SystemExit(f"timed out after {timeout} s")
    return future.result()


def run_goal(node: Node, args: argparse.Namespace, action: Any, name_: str, goal: Any) -> dict:
    """Send ``goal``, gather feedback, cancel if asked; the result and what was seen."""
    client = ActionClient(node, action, name(args.ns, name_))
    if not client.wait_for_server(timeout_sec=args.timeout):
        raise SystemExit(f"no {name_} server")
    if args.delay:
        end = time.monotonic() + args.delay
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)
    feedback: list[dict] = []

    def on_feedback(message: Any) -> None:
        fb = message.feedback
        entry = {"t": time.monotonic()}
        for field in (
            "distance_remaining",
            "number_of_recoveries",
            "number_of_poses_remaining",
            "current_waypoint",
            "angular_distance_traveled",
            "distance_traveled",
        ):
            if hasattr(fb, field):
                entry[field] = getattr(fb, field)
        if hasattr(fb, "navigation_time"):
            entry["navigation_time"] = fb.navigation_time.sec + fb.navigation_time.nanosec * 1e-9
            eta = fb.estimated_time_remaining
            entry["eta"] = eta.sec + eta.nanosec * 1e-9
            entry["x"] = fb.current_pose.pose.position.x
            entry["frame"] = fb.current_pose.header.frame_id
        feedback.append(entry)

    handle = wait(node, client.send_goal_async(goal, feedback_callback=on_feedback), args.timeout)
    out: dict[str, Any] = {"accepted": bool(handle.accepted)}
    if not handle.accepted:
        return out
    result_future = handle.get_result_async()
    if args.cancel_after is not None:
        end = time.monotonic() + args.cancel_after
        while time.monotonic() < end and not result_future.done():
            rclpy.spin_once(node, timeout_sec=0.05)
        speeds: list[tuple[float, float]] = []
        node.create_subscription(
            Odometry,
            name(args.ns, "odom"),
            lambda m: speeds.append((time.monotonic(), abs(m.twist.twist.linear.x))),
            50,
        )
        moving = feedback[-1].get("x") if feedback else None
        response = wait(node, handle.cancel_goal_async(), args.timeout)
        canceled_at = time.monotonic()
        out["cancel_accepted"] = len(response.goals_canceling) == 1
        out["x_before_cancel"] = moving
        wait(node, result_future, args.timeout)
        end = time.monotonic() + 2.0
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)
        stopped = [t for t, v in speeds if t >= canceled_at and v == 0.0]
        out["stopped_after"] = stopped[0] - canceled_at if stopped else None
        out["speeds_after_cancel"] = [v for t, v in speeds if t >= canceled_at][:60]
        out["moving_at_end"] = bool(speeds) and speeds[-1][1] != 0.0
    result = wait(node, result_future, args.timeout)
    out["status"] = STATUS.get(result.status, str(result.status))
    out["error_code"] = int(result.result.error_code)
    out["error_msg"] = result.result.error_msg
    if hasattr(result.result, "missed_waypoints"):
        out["missed"] = [
            {"index": int(m.index), "error_code": int(m.error_code)}
            for m in result.result.missed_waypoints
        ]
    out["feedback"] = feedback
    return out


def navigate(node: Node, args: argparse.Namespace) -> dict:
    goal = NavigateToPose.Goal(pose=pose_stamped(args.poses[0], args.frame))
    return run_goal(node, args, NavigateToPose, "navigate_to_pose", goal)


def through(node: Node, args: argparse.Namespace) -> dict:
    goal = NavigateThroughPoses.Goal(poses=[pose_stamped(p, args.frame) for p in args.poses])
    return run_goal(node, args, NavigateThroughPoses, "navigate_through_poses", goal)


def waypoints(node: Node, args: argparse.Namespace) -> dict:
    goal = FollowWaypoints.Goal(poses=[pose_stamped(p, args.frame) for p in args.poses])
    return run_goal(node, args, FollowWaypoints, "follow_waypoints", goal)


def path(node: Node, args: argparse.Namespace) -> dict:
    client = ActionClient(node, ComputePathToPose, name(args.ns, "compute_path_to_pose"))
    if not client.wait_for_server(timeout_sec=args.timeout):
        raise SystemExit("no compute_path_to_pose server")
    goal = ComputePathToPose.Goal(goal=pose_stamped(args.poses[0], args.frame), use_start=False)
    handle = wait(node, client.send_goal_async(goal), args.timeout)
    result = wait(node, handle.get_result_async(), args.timeout)
    poses = result.result.path.poses
    return {
        "status": STATUS.get(result.status, str(result.status)),
        "error_code": int(result.result.error_code),
        "points": len(poses),
        "frame": result.result.path.header.frame_id,
        "last": [poses[-1].pose.position.x, poses[-1].pose.position.y] if poses else None,
    }


def refusals(node: Node, args: argparse.Namespace) -> dict:
    """Each refused goal's status and error code, by what it tried."""
    from nav_msgs.msg import Path

    somewhere = pose_stamped("-1.0,-0.5,0")
    cases = {
        "through no goals": (
            ComputePathThroughPoses,
            "compute_path_through_poses",
            ComputePathThroughPoses.Goal(),
        ),
        "through unknown planner": (
            ComputePathThroughPoses,
            "compute_path_through_poses",
            ComputePathThroughPoses.Goal(goals=[somewhere], planner_id="SmacHybrid"),
        ),
        "path unknown frame": (
            ComputePathToPose,
            "compute_path_to_pose",
            ComputePathToPose.Goal(goal=pose_stamped("-1.0,-0.5,0", "nowhere")),
        ),
        "smooth empty path": (SmoothPath, "smooth_path", SmoothPath.Goal(path=Path())),
        "smooth unknown smoother": (
            SmoothPath,
            "smooth_path",
            SmoothPath.Goal(path=Path(poses=[somewhere]), smoother_id="savitzky_golay"),
        ),
        "follow unknown controller": (
            FollowPath,
            "follow_path",
            FollowPath.Goal(path=Path(poses=[somewhere]), controller_id="DWB"),
        ),
        "follow empty path": (FollowPath, "follow_path", FollowPath.Goal(path=Path())),
    }
    out = {}
    for what, (action, server, goal) in cases.items():
        client = ActionClient(node, action, name(args.ns, server))
        if not client.wait_for_server(timeout_sec=args.timeout):
            raise SystemExit(f"no {server} server")
        handle = wait(node, client.send_goal_async(goal), args.timeout)
        result = wait(node, handle.get_result_async(), args.timeout)
        out[what] = [STATUS.get(result.status, str(result.status)), int(result.result.error_code)]
    return out


def manage(node: Node, args: argparse.Namespace) -> dict:
    from nav2_msgs.srv import ManageLifecycleNodes
    from std_srvs.srv import Trigger

    command = getattr(ManageLifecycleNodes.Request, args.poses[0].upper())
    out: dict[str, Any] = {}
    manager = "lifecycle_manager_navigation"
    client = node.create_client(ManageLifecycleNodes, name(args.ns, f"{manager}/manage_nodes"))
    if not client.wait_for_service(timeout_sec=args.timeout):
        raise SystemExit("no manage_nodes")
    request = ManageLifecycleNodes.Request(command=command)
    out["success"] = wait(node, client.call_async(request), args.timeout).success
    active = node.create_client(Trigger, name(args.ns, f"{manager}/is_active"))
    active.wait_for_service(timeout_sec=args.timeout)
    out["is_active"] = wait(node, active.call_async(Trigger.Request()), args.timeout).success
    state = node.create_client(GetState, name(args.ns, "bt_navigator/get_state"))
    state.wait_for_service(timeout_sec=args.timeout)
    reply = wait(node, state.call_async(GetState.Request()), args.timeout)
    out["bt_navigator"] = reply.current_state.label
    spin = ActionClient(node, Spin, name(args.ns, "spin"))
    spin.wait_for_server(timeout_sec=args.timeout)
    handle = wait(node, spin.send_goal_async(Spin.Goal(target_yaw=0.1)), args.timeout)
    out["spin_accepted"] = bool(handle.accepted)
    if handle.accepted:
        wait(node, handle.get_result_async(), args.timeout)
    return out


def filters(node: Node, args: argparse.Namespace) -> dict:
    from nav2_msgs.msg import CostmapFilterInfo
    from nav2_msgs.srv import ManageLifecycleNodes
    from nav_msgs.srv import GetMap
    from std_srvs.srv import Trigger

    masks: list[OccupancyGrid] = []
    infos: list[Any] = []
    node.create_subscription(
        OccupancyGrid, name(args.ns, "keepout_filter_mask"), masks.append, LATCHED
    )
    node.create_subscription(
        CostmapFilterInfo, name(args.ns, "keepout_costmap_filter_info"), infos.append, LATCHED
    )

    def until(done: Any) -> None:
        end = time.monotonic() + args.timeout
        while not done() and time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)

    def service(kind: Any, service_name: str) -> Any:
        client = node.create_client(kind, name(args.ns, service_name))
        if not client.wait_for_service(timeout_sec=args.timeout):
            raise SystemExit(f"no {service_name}")
        return client

    manager = "lifecycle_manager_keepout_zone"
    manage = service(ManageLifecycleNodes, f"{manager}/manage_nodes")
    is_active = service(Trigger, f"{manager}/is_active")
    servers = ("keepout_filter_mask_server", "keepout_costmap_filter_info_server")
    states = {server: service(GetState, f"{server}/get_state") for server in servers}
    get_map = service(GetMap, "keepout_filter_mask_server/map")

    def look() -> dict:
        out: dict[str, Any] = {
            "is_active": wait(node, is_active.call_async(Trigger.Request()), args.timeout).success
        }
        for server, client in states.items():
            reply = wait(node, client.call_async(GetState.Request()), args.timeout)
            out[server] = reply.current_state.label
        served = wait(node, get_map.call_async(GetMap.Request()), args.timeout).map
        out["map_service"] = [served.info.width, served.info.height]
        return out

    until(lambda: masks and infos)
    seen: dict[str, Any] = {"at_start": look()}
    for command in ("pause", "resume"):
        request = ManageLifecycleNodes.Request(
            command=getattr(ManageLifecycleNodes.Request, command.upper())
        )
        success = wait(node, manage.call_async(request), args.timeout).success
        seen[command] = {"success": success, **look()}
    until(lambda: len(masks) >= 2 and len(infos) >= 2)
    seen["masks"] = [[m.info.width, m.info.height, m.header.frame_id] for m in masks]
    seen["infos"] = [[i.type, i.filter_mask_topic] for i in infos]
    return seen


def late_map(node: Node, args: argparse.Namespace) -> dict:
    got: list[OccupancyGrid] = []
    node.create_subscription(OccupancyGrid, name(args.ns, "map"), got.append, LATCHED)
    end = time.monotonic() + args.timeout
    while not got and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    if not got:
        return {"map": None}
    grid = got[0]
    return {
        "map": [grid.info.width, grid.info.height, round(grid.info.resolution, 4)],
        "frame": grid.header.frame_id,
        "cells": {str(v): sum(1 for value in grid.data if value == v) for v in (-1, 0, 100)},
    }


def behavior(node: Node, args: argparse.Namespace) -> dict:
    """One behaviour goal (see the module doc) and the robot's motion in ``odom``."""
    from builtin_interfaces.msg import Duration

    kind = args.poses[0]
    if kind == "assisted_teleop":
        return teleop(node, args)
    allowance = Duration(sec=int(args.allowance), nanosec=int(args.allowance % 1 * 1e9))
    if kind == "spin":
        action, goal = Spin, Spin.Goal(target_yaw=args.value, time_allowance=allowance)
    elif kind == "wait":
        seconds = Duration(sec=int(args.value), nanosec=int(args.value % 1 * 1e9))
        action, goal = Wait, Wait.Goal(time=seconds)
    else:
        action = BackUp if kind == "backup" else DriveOnHeading
        goal = action.Goal(speed=args.speed, time_allowance=allowance)
        goal.target.x, goal.target.y = args.value, args.target_y
    poses = odom_poses(node, args)
    before = poses[-1]
    started = time.monotonic()
    out = run_goal(node, args, action, kind, goal)
    out["took"] = time.monotonic() - started
    return {**out, **motion(node, poses, before)}


def odom_poses(node: Node, args: argparse.Namespace) -> list[tuple[float, float, float]]:
    """The robot's ``odom -> base`` poses as they come on ``/tf`` (one at least)."""
    poses: list[tuple[float, float, float]] = []

    def on_tf(message: TFMessage) -> None:
        # odom -> base: Nav2's loopback simulator publishes odom only while moving.
        for transform in message.transforms:
            if transform.header.frame_id.endswith("odom") and "base" in transform.child_frame_id:
                t, q = transform.transform.translation, transform.transform.rotation
                poses.append((t.x, t.y, 2 * math.atan2(q.z, q.w)))

    node.create_subscription(TFMessage, "/tf", on_tf, 100)
    end = time.monotonic() + args.timeout
    while not poses and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    if not poses:
        raise SystemExit("no odom -> base transform on /tf")
    return poses


def motion(
    node: Node, poses: list[tuple[float, float, float]], before: tuple[float, float, float]
) -> dict:
    """How far the robot moved since ``before``, once it settled (1 s)."""
    out: dict[str, float] = {}
    settle = time.monotonic() + 1.0
    while time.monotonic() < settle:
        rclpy.spin_once(node, timeout_sec=0.05)
    after = poses[-1]
    out["moved"] = math.hypot(after[0] - before[0], after[1] - before[1])
    # Forward (+) or backward (-) along the heading the robot started with.
    out["advanced"] = (after[0] - before[0]) * math.cos(before[2]) + (
        after[1] - before[1]
    ) * math.sin(before[2])
    out["turned"] = math.remainder(after[2] - before[2], math.tau)
    return out


def teleop(node: Node, args: argparse.Namespace) -> dict:
    """An assisted_teleop goal driven by ``cmd_vel_teleop``, ended by ``preempt_teleop``."""
    from builtin_interfaces.msg import Duration
    from geometry_msgs.msg import Twist
    from std_msgs.msg import Empty

    allowance = Duration(sec=int(args.allowance), nanosec=int(args.allowance % 1 * 1e9))
    client = ActionClient(node, AssistedTeleop, name(args.ns, "assisted_teleop"))
    if not client.wait_for_server(timeout_sec=args.timeout):
        raise SystemExit("no assisted_teleop server")
    command = node.create_publisher(Twist, name(args.ns, "cmd_vel_teleop"), 10)
    preempt = node.create_publisher(Empty, name(args.ns, "preempt_teleop"), 10)
    poses = odom_poses(node, args)
    before = poses[-1]
    durations: list[float] = []

    def on_feedback(message: Any) -> None:
        elapsed = message.feedback.current_teleop_duration
        durations.append(elapsed.sec + elapsed.nanosec * 1e-9)

    goal = AssistedTeleop.Goal(time_allowance=allowance)
    handle = wait(node, client.send_goal_async(goal, feedback_callback=on_feedback), args.timeout)
    if not handle.accepted:
        return {"accepted": False}
    result_future = handle.get_result_async()
    twist = Twist()
    twist.linear.x = args.speed
    started = time.monotonic()
    end = started + args.timeout
    preempted = False
    while not result_future.done() and time.monotonic() < end:
        command.publish(twist)
        if args.value > 0 and not preempted and time.monotonic() - started >= args.value:
            preempt.publish(Empty())
            preempted = True
        for _ in range(2):
            rclpy.spin_once(node, timeout_sec=0.05)
    command.publish(Twist())
    result = wait(node, result_future, args.timeout)
    out: dict[str, Any] = {
        "status": STATUS.get(result.status, str(result.status)),
        "error_code": int(result.result.error_code),
        "took": time.monotonic() - started,
        "feedback": durations,
    }
    return {**out, **motion(node, poses, before)}


def map_pose(node: Node, args: argparse.Namespace) -> list[float] | None:
    """The robot's pose in ``map`` (``map -> odom -> base`` on ``/tf``), once heard."""
    frames: dict[str, tuple[float, float, float]] = {}

    def on_tf(message: TFMessage) -> None:
        for transform in message.transforms:
            t, q = transform.transform.translation, transform.transform.rotation
            child = transform.child_frame_id
            key = "odom" if child.endswith("odom") else "base" if "base" in child else None
            if key is not None:
                frames[key] = (t.x, t.y, 2 * math.atan2(q.z, q.w))

    subscription = node.create_subscription(TFMessage, "/tf", on_tf, 100)
    end = time.monotonic() + 5.0
    while len(frames) < 2 and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    node.destroy_subscription(subscription)
    if len(frames) < 2:
        return None
    (ox, oy, oyaw), (bx, by, byaw) = frames["odom"], frames["base"]
    return [
        ox + bx * math.cos(oyaw) - by * math.sin(oyaw),
        oy + bx * math.sin(oyaw) + by * math.cos(oyaw),
        math.remainder(oyaw + byaw, math.tau),
    ]


def docking(node: Node, args: argparse.Namespace, undock: bool) -> dict:
    """A dock_robot goal (by id, or at a pose X,Y,YAW with --frame) or an undock_robot goal."""
    if undock:
        action, server, goal = UndockRobot, "undock_robot", UndockRobot.Goal()
    else:
        action, server = DockRobot, "dock_robot"
        target = args.poses[0]
        if "," in target:
            goal = DockRobot.Goal(use_dock_id=False, dock_pose=pose_stamped(target, args.frame))
        else:
            goal = DockRobot.Goal(use_dock_id=True, dock_id=target)
        goal.navigate_to_staging_pose = args.value <= 0
    client = ActionClient(node, action, name(args.ns, server))
    if not client.wait_for_server(timeout_sec=args.timeout):
        raise SystemExit(f"no {server} server")
    states: list[int] = []

    def on_feedback(message: Any) -> None:
        states.append(int(message.feedback.state))

    handle = wait(node, client.send_goal_async(goal, feedback_callback=on_feedback), args.timeout)
    if not handle.accepted:
        return {"accepted": False}
    result_future = handle.get_result_async()
    if args.cancel_after is not None:
        end = time.monotonic() + args.cancel_after
        while time.monotonic() < end and not result_future.done():
            rclpy.spin_once(node, timeout_sec=0.05)
        wait(node, handle.cancel_goal_async(), args.timeout)
    result = wait(node, result_future, args.timeout)
    settle = time.monotonic() + 0.5
    while time.monotonic() < settle:
        rclpy.spin_once(node, timeout_sec=0.05)
    return {
        "status": STATUS.get(result.status, str(result.status)),
        "success": bool(result.result.success),
        "error_code": int(result.result.error_code),
        "states": [state for index, state in enumerate(states) if state not in states[:index]],
        "pose": map_pose(node, args),
    }


def dock(node: Node, args: argparse.Namespace) -> dict:
    return docking(node, args, undock=False)


def undock(node: Node, args: argparse.Namespace) -> dict:
    return docking(node, args, undock=True)


def ready(node: Node, args: argparse.Namespace) -> dict:
    out: dict[str, Any] = {}
    for server in ("bt_navigator", "amcl"):
        client = node.create_client(GetState, name(args.ns, f"{server}/get_state"))
        if not client.wait_for_service(timeout_sec=args.timeout):
            raise SystemExit(f"no {server}/get_state")
        state = wait(node, client.call_async(GetState.Request()), args.timeout)
        out[server] = state.current_state.label
    amcl: list[PoseWithCovarianceStamped] = []
    node.create_subscription(
        PoseWithCovarianceStamped, name(args.ns, "amcl_pose"), amcl.append, LATCHED
    )
    publisher = node.create_publisher(PoseWithCovarianceStamped, name(args.ns, "initialpose"), 10)
    initial = PoseWithCovarianceStamped()
    target = pose_stamped(args.poses[0] if args.poses else "-1.5,-0.5,90")
    initial.header = target.header
    initial.pose.pose = target.pose
    end = time.monotonic() + args.timeout
    while not amcl and time.monotonic() < end:
        publisher.publish(initial)  # until someone listens: what the commander does too
        for _ in range(5):
            rclpy.spin_once(node, timeout_sec=0.05)
    out["amcl_pose"] = (
        [amcl[-1].pose.pose.position.x, amcl[-1].pose.pose.position.y] if amcl else None
    )
    for costmap in ("global_costmap", "local_costmap"):
        client = node.create_client(
            ClearEntireCostmap, name(args.ns, f"{costmap}/clear_entirely_{costmap}")
        )
        if not client.wait_for_service(timeout_sec=args.timeout):
            raise SystemExit(f"no {costmap} clear service")
        wait(node, client.call_async(ClearEntireCostmap.Request()), args.timeout)
        out[costmap] = "cleared"
    return out


VERBS = {
    "navigate": navigate,
    "through": through,
    "waypoints": waypoints,
    "path": path,
    "map": late_map,
    "ready": ready,
    "behavior": behavior,
    "refusals": refusals,
    "manage": manage,
    "filters": filters,
    "dock": dock,
    "undock": undock,
}


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("verb", choices=sorted(VERBS))
    parser.add_argument("poses", nargs="*", help="x,y,yaw (degrees)")
    parser.add_argument("--ns", default="")
    parser.add_argument("--frame", default="map")
    parser.add_argument("--delay", type=float, default=0.0)
    parser.add_argument("--cancel-after", type=float)
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--value", type=float, default=0.0)
    parser.add_argument("--speed", type=float, default=0.0)
    parser.add_argument("--target-y", type=float, default=0.0)
    parser.add_argument("--allowance", type=float, default=10.0)
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
