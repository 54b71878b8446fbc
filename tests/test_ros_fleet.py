"""Simulated robots that see each other, as ROS nodes: ``multi_robot.launch`` and the
``~other_robots`` parameter of the sim nodes, against a real rosmaster.

A watcher (a rospy/actionlib script run as a subprocess, like the other ROS clients)
sends robot1 its goal and, until the result comes, samples both robots' poses from
their ``odom`` (each odom frame starts at the robot's start pose, so the map pose is
the start composed with the odometry) and reads robot1's costmap topic.
"""

from __future__ import annotations

import json
import math
import textwrap
from pathlib import Path
from typing import Any

import pytest

from ros_clients import MAP, SPEED, SUCCEEDED
from ros_support import REPO_ROOT, RosMaster

pytestmark = pytest.mark.ros

WATCHER = textwrap.dedent(
    """
    import json, math, sys, threading, time
    import actionlib, rospy
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
    from nav_msgs.msg import OccupancyGrid, Odometry
    from navseq.geometry import Pose2D, compose
    from navseq.sim.footprint import TURTLEBOT3_BURGER, footprints_overlap

    setup = json.loads(sys.argv[1])
    rospy.init_node("fleet_watcher", anonymous=True)
    lock = threading.Lock()
    latest = {}
    stats = {"samples": 0, "min_distance": math.inf, "overlaps": 0, "robot2_moved": 0.0,
             "costmap_at_robot2": None}

    def on_odom(robot):
        start = Pose2D(*setup["starts"][robot])

        def callback(msg):
            p, q = msg.pose.pose.position, msg.pose.pose.orientation
            pose = compose(start, Pose2D(p.x, p.y, 2.0 * math.atan2(q.z, q.w)))
            with lock:
                latest[robot] = pose
                if robot == "robot2":
                    moved = math.hypot(pose.x - start.x, pose.y - start.y)
                    stats["robot2_moved"] = max(stats["robot2_moved"], moved)
                if len(latest) < 2:
                    return
                first, second = latest["robot1"], latest["robot2"]
                stats["samples"] += 1
                distance = math.hypot(first.x - second.x, first.y - second.y)
                stats["min_distance"] = min(stats["min_distance"], distance)
                stats["overlaps"] += footprints_overlap(
                    TURTLEBOT3_BURGER, first, TURTLEBOT3_BURGER, second
                )

        return callback

    for robot in ("robot1", "robot2"):
        rospy.Subscriber(f"/{robot}/odom", Odometry, on_odom(robot), queue_size=100)

    def on_costmap(msg):
        x, y, _ = setup["starts"]["robot2"]
        info = msg.info
        col = math.floor((x - info.origin.position.x) / info.resolution)
        row = math.floor((y - info.origin.position.y) / info.resolution)
        stats["costmap_at_robot2"] = msg.data[row * info.width + col]

    rospy.Subscriber("/robot1/move_base/global_costmap/costmap", OccupancyGrid, on_costmap)
    deadline = time.monotonic() + 30
    while len(latest) < 2 and time.monotonic() < deadline and not rospy.is_shutdown():
        time.sleep(0.05)
    if len(latest) < 2:
        sys.exit(f"no odometry from both robots: {sorted(latest)}")
    client = actionlib.SimpleActionClient("/robot1/move_base", MoveBaseAction)
    if not client.wait_for_server(rospy.Duration(30)):
        sys.exit("no /robot1/move_base action server")
    x, y, yaw = setup["goal"]
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = "map"
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose.position.x, goal.target_pose.pose.position.y = x, y
    goal.target_pose.pose.orientation.z = math.sin(yaw / 2)
    goal.target_pose.pose.orientation.w = math.cos(yaw / 2)
    client.send_goal(goal)
    finished = client.wait_for_result(rospy.Duration(setup["timeout"]))
    with lock:
        end = latest["robot1"]
        print(json.dumps({"finished": finished, "state": client.get_state(),
                          "text": client.get_goal_status_text(),
                          "robot1": [end.x, end.y, end.yaw], **stats}), flush=True)
    """
)


def watch(master: RosMaster, tmp_path: Path, setup: dict[str, Any], timeout: float) -> dict:
    """Run the watcher; its one JSON report."""
    script = tmp_path / "fleet_watcher.py"
    script.write_text(WATCHER)
    watcher = master.start_python(script, json.dumps(setup), label="fleet_watcher")
    assert watcher.wait(timeout=timeout) == 0, watcher.output()[-4000:]
    lines = [line for line in watcher.output().splitlines() if line.startswith("{")]
    assert lines, watcher.output()[-4000:]
    return json.loads(lines[-1])


# Two simulated robots in real time: a recovery or a wait can exceed the budget under load.
@pytest.mark.flaky(reruns=2)
def test_robot1_drives_around_robot2_parked_on_its_straight_path(
    ros_master: RosMaster, tmp_path: Path
) -> None:
    # robot1 goes north along x = -2 to (-2, 1.2); robot2 is parked on that line at
    # (-2, 0.3). There is room round it on both sides, between the west wall and the
    # first column of pillars.
    robot1, robot2, goal = (-2.0, -0.5, 0.0), (-2.0, 0.3, 0.0), (-2.0, 1.2, math.pi / 2)
    ros_master.start(
        [
            "roslaunch",
            "navseq",
            "multi_robot.launch",
            f"speed:={SPEED}",
            *(f"robot1_{k}:={v}" for k, v in zip(("x", "y", "yaw"), robot1, strict=True)),
            *(f"robot2_{k}:={v}" for k, v in zip(("x", "y", "yaw"), robot2, strict=True)),
        ],
        label="roslaunch",
    )
    for robot in ("robot1", "robot2"):
        ros_master.wait_for_action_server(f"/{robot}/move_base", timeout=60)
    report = watch(
        ros_master,
        tmp_path,
        # Simulated seconds: the way round may include waiting for the other robot's
        # pose to settle and a recovery (replan, rotate), which can take a while.
        {"starts": {"robot1": robot1, "robot2": robot2}, "goal": goal, "timeout": 300},
        timeout=150,
    )
    assert report["finished"] and report["state"] == SUCCEEDED, report
    assert math.dist(report["robot1"][:2], goal[:2]) < 0.1, report
    assert report["robot2_moved"] < 0.01, report  # parked all along
    assert report["samples"] > 100, report
    from navseq.sim.footprint import TURTLEBOT3_BURGER

    # The centres never came closer than the two inscribed radii (a sure overlap), and
    # the exact test found no overlap at any sample either.
    assert report["min_distance"] >= 2 * TURTLEBOT3_BURGER.inscribed_radius, report
    assert report["overlaps"] == 0, report
    # robot1's costmap for RViz shows robot2 as an obstacle (costmap_2d's 100: lethal).
    assert report["costmap_at_robot2"] == 100, report


@pytest.mark.parametrize(
    ("node", "value", "message"),
    [
        ("sim_robot_node", "robot2/base_footprint", "expected a list of non-empty strings"),
        ("sim_nav_node", "[robot2/base_footprint, '']", "expected a list of non-empty strings"),
        ("sim_nav_node", "[base_footprint]", "own base frame"),
    ],
)
def test_a_bad_other_robots_param_stops_the_node_naming_it(
    ros_master: RosMaster, node: str, value: str, message: str
) -> None:
    process = ros_master.start(
        [REPO_ROOT / "nodes" / node, f"_map:={MAP}", f"_other_robots:={value}"], label=node
    )
    assert process.wait(timeout=30) == 2, process.output()
    output = process.output()
    assert "other_robots" in output and message in output, output
