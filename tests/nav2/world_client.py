"""A Nav2 user's look at the stand-in's world, with plain rclpy (tests/test_ros2_world.py).

    python world_client.py '{"ns": "", "goal": [-1.4, -0.5], "maps": {...}}'

In order, every wait bounded: the map, a scan and the laser's static transform; a
``speed_limit`` then a ``navigate_to_pose`` goal, watching ``cmd_vel_nav``,
``cmd_vel_smoothed`` and ``cmd_vel``; teleop on ``cmd_vel``; an ``initialpose`` beside the
robot (``amcl_pose``, ``particle_cloud``, ``odom``, the ``map -> odom`` transform);
``map_server/map``; ``map_server/load_map`` with each given URL. Prints one JSON line.
"""

from __future__ import annotations

import json
import math
import sys
import time
from typing import Any

import rclpy
from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
from nav2_msgs.action import NavigateToPose
from nav2_msgs.msg import ParticleCloud, SpeedLimit
from nav2_msgs.srv import LoadMap, SetInitialPose
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.srv import GetMap
from rclpy.action import ActionClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

LATCHED = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
STATIC = QoSProfile(
    depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


def main() -> int:
    setup = json.loads(sys.argv[1])
    ns = setup.get("ns", "")
    prefix = f"/{ns}" if ns else ""
    tf_topic = setup.get("tf_topic", "/tf")
    rclpy.init()
    node = rclpy.create_node("world_client")
    out: dict[str, Any] = {}
    seen: dict[str, list[Any]] = {
        name: []
        for name in (
            "map",
            "scan",
            "static",
            "tf",
            "cmd_vel_nav",
            "cmd_vel_smoothed",
            "cmd_vel",
            "amcl_pose",
            "particle_cloud",
            "odom",
        )
    }

    def keep(name: str) -> Any:
        return seen[name].append

    node.create_subscription(OccupancyGrid, f"{prefix}/map", keep("map"), LATCHED)
    node.create_subscription(LaserScan, f"{prefix}/scan", keep("scan"), qos_profile_sensor_data)
    node.create_subscription(
        TFMessage, tf_topic.replace("/tf", "/tf_static"), keep("static"), STATIC
    )
    node.create_subscription(TFMessage, tf_topic, keep("tf"), 100)
    for name in ("cmd_vel_nav", "cmd_vel_smoothed", "cmd_vel"):
        node.create_subscription(Twist, f"{prefix}/{name}", keep(name), 100)
    node.create_subscription(
        PoseWithCovarianceStamped, f"{prefix}/amcl_pose", keep("amcl_pose"), LATCHED
    )
    node.create_subscription(
        ParticleCloud, f"{prefix}/particle_cloud", keep("particle_cloud"), qos_profile_sensor_data
    )
    node.create_subscription(Odometry, f"{prefix}/odom", keep("odom"), 100)

    def spin_until(condition: Any, seconds: float) -> bool:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if condition():
                return True
            rclpy.spin_once(node, timeout_sec=0.05)
        return bool(condition())

    # -- the map, the laser and its frame ----------------------------------------------
    spin_until(lambda: seen["map"] and seen["scan"] and seen["static"] and seen["odom"], 20)
    grid = seen["map"][-1]
    out["map"] = [grid.info.width, grid.info.height, grid.header.frame_id]
    scan = seen["scan"][-1]
    finite = [r for r in scan.ranges if math.isfinite(r)]
    out["scan"] = {
        "frame": scan.header.frame_id,
        "beams": len(scan.ranges),
        "range": [scan.range_min, scan.range_max],
        "finite": len(finite),
        "nearest": min(finite) if finite else None,
    }
    out["static"] = sorted(
        f"{t.header.frame_id}->{t.child_frame_id}" for m in seen["static"] for t in m.transforms
    )
    out["tf"] = sorted(
        {f"{t.header.frame_id}->{t.child_frame_id}" for m in seen["tf"] for t in m.transforms}
    )

    # -- speed limit, then a goal through the velocity chain -----------------------------
    limit_pub = node.create_publisher(SpeedLimit, f"{prefix}/speed_limit", 10)
    spin_until(lambda: limit_pub.get_subscription_count() > 0, 10)
    limit_pub.publish(SpeedLimit(percentage=False, speed_limit=float(setup["speed_limit"])))
    spin_until(lambda: False, 0.5)
    client = ActionClient(node, NavigateToPose, f"{prefix}/navigate_to_pose")
    client.wait_for_server(timeout_sec=20)
    goal = NavigateToPose.Goal()
    goal.pose.header.frame_id = "map"
    goal.pose.pose.position.x, goal.pose.pose.position.y = setup["goal"]
    goal.pose.pose.orientation.w = 1.0
    for name in ("cmd_vel_nav", "cmd_vel_smoothed", "cmd_vel"):
        seen[name].clear()
    sent = client.send_goal_async(goal)
    spin_until(sent.done, 10)
    result = sent.result().get_result_async()
    spin_until(result.done, 90)
    out["goal_status"] = result.result().status if result.done() else None
    spin_until(lambda: False, 0.5)
    for name in ("cmd_vel_nav", "cmd_vel_smoothed", "cmd_vel"):
        out[name] = {
            "count": len(seen[name]),
            "max_v": max((abs(m.linear.x) for m in seen[name]), default=0.0),
            "max_w": max((abs(m.angular.z) for m in seen[name]), default=0.0),
            "last": [seen[name][-1].linear.x, seen[name][-1].angular.z] if seen[name] else None,
        }

    # -- teleop ---------------------------------------------------------------------------
    spin_until(lambda: False, 1.0)  # the stand-in's own last cmd_vel is 0.5 s behind us
    before = seen["odom"][-1].pose.pose.position
    teleop = node.create_publisher(Twist, f"{prefix}/cmd_vel", 10)
    for _ in range(10):
        command = Twist()
        command.linear.x = 0.1
        teleop.publish(command)
        spin_until(lambda: False, 0.1)
    spin_until(lambda: False, 1.0)
    after = seen["odom"][-1].pose.pose.position
    out["teleop_moved"] = math.hypot(after.x - before.x, after.y - before.y)

    # -- initial pose: the estimate moves, the robot does not -------------------------------
    odom_before = seen["odom"][-1].pose.pose.position
    initial = PoseWithCovarianceStamped()
    initial.header.frame_id = "map"
    initial.pose.pose.position.x, initial.pose.pose.position.y = setup["initial_pose"]
    initial.pose.pose.orientation.w = 1.0
    pose_pub = node.create_publisher(PoseWithCovarianceStamped, f"{prefix}/initialpose", 10)
    spin_until(lambda: pose_pub.get_subscription_count() > 0, 10)
    seen["amcl_pose"].clear()
    seen["particle_cloud"].clear()
    pose_pub.publish(initial)

    def near_initial() -> bool:
        if not seen["amcl_pose"] or not seen["particle_cloud"]:
            return False
        at = seen["amcl_pose"][-1].pose.pose.position
        return math.hypot(at.x - setup["initial_pose"][0], at.y - setup["initial_pose"][1]) < 0.01

    spin_until(near_initial, 10)
    spin_until(lambda: False, 0.5)
    amcl = seen["amcl_pose"][-1] if seen["amcl_pose"] else None
    out["amcl_pose"] = (
        [amcl.pose.pose.position.x, amcl.pose.pose.position.y, amcl.header.frame_id]
        if amcl
        else None
    )
    cloud = seen["particle_cloud"][-1] if seen["particle_cloud"] else None
    out["particles"] = len(cloud.particles) if cloud else None
    odom_after = seen["odom"][-1].pose.pose.position
    out["odom_moved_on_initialpose"] = math.hypot(
        odom_after.x - odom_before.x, odom_after.y - odom_before.y
    )
    map_to_odom = [
        t.transform.translation
        for m in seen["tf"][-20:]
        for t in m.transforms
        if t.header.frame_id == "map"
    ]
    out["map_to_odom"] = [map_to_odom[-1].x, map_to_odom[-1].y] if map_to_odom else None

    # -- amcl's services: set_initial_pose as initialpose; the two Empty ones answer --------
    set_pose = node.create_client(SetInitialPose, f"{prefix}/set_initial_pose")
    set_pose.wait_for_service(timeout_sec=10)
    request = SetInitialPose.Request()
    request.pose.header.frame_id = "map"
    request.pose.pose.pose.position.x, request.pose.pose.pose.position.y = setup["service_pose"]
    request.pose.pose.pose.orientation.w = 1.0
    seen["amcl_pose"].clear()
    answer = set_pose.call_async(request)
    spin_until(answer.done, 10)
    spin_until(lambda: bool(seen["amcl_pose"]), 5)
    at = seen["amcl_pose"][-1].pose.pose.position if seen["amcl_pose"] else None
    out["set_initial_pose"] = [at.x, at.y] if at else None
    out["empty_services"] = {}
    for name in ("request_nomotion_update", "reinitialize_global_localization"):
        empty = node.create_client(Empty, f"{prefix}/{name}")
        empty.wait_for_service(timeout_sec=10)
        answer = empty.call_async(Empty.Request())
        out["empty_services"][name] = spin_until(answer.done, 10)

    # -- map_server's services ------------------------------------------------------------
    get_map = node.create_client(GetMap, f"{prefix}/map_server/map")
    get_map.wait_for_service(timeout_sec=10)
    answer = get_map.call_async(GetMap.Request())
    spin_until(answer.done, 10)
    out["get_map"] = [answer.result().map.info.width, answer.result().map.info.height]
    load = node.create_client(LoadMap, f"{prefix}/map_server/load_map")
    load.wait_for_service(timeout_sec=10)
    out["load_map"] = {}
    for key, url in setup["maps"].items():
        seen["map"].clear()
        reply = load.call_async(LoadMap.Request(map_url=url))
        spin_until(reply.done, 20)
        response = reply.result()
        spin_until(lambda: bool(seen["map"]), 2.0 if response.result == 0 else 0.5)
        out["load_map"][key] = {
            "result": response.result,
            "width": response.map.info.width,
            "published": seen["map"][-1].info.width if seen["map"] else None,
        }
    print(json.dumps(out), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
