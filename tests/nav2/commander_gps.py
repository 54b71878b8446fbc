"""nav2_simple_commander's GPS waypoints, as Nav2's GPS waypoint follower demo sends them.

usage: commander_gps.py LAT,LON LAT,LON ...  (run with the real Nav2 tree's ROS 2
environment, against a simulator started with --datum)

``setInitialPose`` at (-2, -0.5), ``waitUntilNav2Active``, ``followGpsWaypoints`` through
the given positions (heading 0), then the ``fromLL`` service of the first position when
it is served. Prints one JSON object: the task's result, missed waypoints, the robot's
last ``amcl_pose`` and fromLL's map point. Every call goes through ``BasicNavigator``
unchanged: a call the server does not answer hangs, and the test's timeout says so.
"""

from __future__ import annotations

import json
import sys

import rclpy
from geographic_msgs.msg import GeoPose
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from nav2_simple_commander.robot_navigator import BasicNavigator
from rclpy.qos import DurabilityPolicy, QoSProfile


def geo_pose(latitude: float, longitude: float) -> GeoPose:
    pose = GeoPose()
    pose.position.latitude = latitude
    pose.position.longitude = longitude
    pose.orientation.w = 1.0
    return pose


def main(argv: list[str]) -> int:
    rclpy.init()
    navigator = BasicNavigator()
    last: list[tuple[float, float]] = []
    navigator.create_subscription(
        PoseWithCovarianceStamped,
        "amcl_pose",
        lambda message: last.append((message.pose.pose.position.x, message.pose.pose.position.y)),
        QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL),
    )
    start = PoseStamped()
    start.header.frame_id = "map"
    start.header.stamp = navigator.get_clock().now().to_msg()
    start.pose.position.x, start.pose.position.y = -2.0, -0.5
    start.pose.orientation.w = 1.0
    navigator.setInitialPose(start)
    navigator.waitUntilNav2Active()
    positions = [tuple(float(v) for v in text.split(",")) for text in argv]
    navigator.followGpsWaypoints([geo_pose(lat, lon) for lat, lon in positions])
    feedback = 0
    while not navigator.isTaskComplete():
        if navigator.getFeedback() is not None:
            feedback += 1
    out: dict[str, object] = {"result": navigator.getResult().name, "feedback": feedback}
    for _ in range(20):  # the amcl_pose after the robot stopped
        rclpy.spin_once(navigator, timeout_sec=0.1)
    out["pose"] = [round(v, 3) for v in last[-1]] if last else None
    try:
        from robot_localization.srv import FromLL
    except ImportError:
        out["fromLL"] = "no type"
    else:
        client = navigator.create_client(FromLL, "fromLL")
        if client.wait_for_service(timeout_sec=5.0):
            request = FromLL.Request()
            request.ll_point.latitude, request.ll_point.longitude = positions[0]
            future = client.call_async(request)
            rclpy.spin_until_future_complete(navigator, future, timeout_sec=10.0)
            point = future.result().map_point
            out["fromLL"] = [round(point.x, 3), round(point.y, 3)]
        else:
            out["fromLL"] = "not served"
    print(json.dumps(out), flush=True)
    navigator.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
