"""Simulated robots that see each other under ROS 2: ``--other-robots`` of the sim node,
``launch/multi_robot.launch.py``, and the ROS-free part they share with ROS 1
(:mod:`navseq.sim.fleet`).

The ROS 2 test launches both robots with ``ros2 launch`` on a private ROS_DOMAIN_ID and
runs a watcher (an rclpy script, as a subprocess like every ROS 2 client of the tests)
that sends robot1 its ``navigate_to_pose`` goal and, until the result comes, samples
both robots' poses from their ``odom`` (each odom frame starts at the robot's start
pose, so the map pose is the start composed with the odometry) and robot1's ``plan``.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from navseq.commands.sim_options import add_arguments, config_from_args
from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.sim.fleet import SeenRobots, other_robots_problem
from navseq.sim.footprint import TURTLEBOT3_BURGER, Footprint
from ros2_support import ros2_environment, ros2_prefix

REPO = Path(__file__).resolve().parents[1]
MAP = REPO / "maps" / "turtlebot3_world.yaml"

# -- the ROS-free part: who the other robots are, where they were seen ------------------------


def test_seen_robots_composes_the_two_transforms_of_each_robot_and_ignores_the_rest():
    square = Footprint(np.array([[0.2, 0.2], [-0.2, 0.2], [-0.2, -0.2], [0.2, -0.2]]))
    seen = SeenRobots(("robot2",), tolerance=1.0, footprint=square)
    assert seen.poses(0.0) == ([], ["robot2"])  # nothing heard yet: not avoided
    seen.heard("map", "robot2/odom", Pose2D(1.0, 0.0, math.pi / 2), at=0.0)
    assert seen.poses(0.0) == ([], ["robot2"])  # half a pose is no pose
    seen.heard("/robot2/odom", "/robot2/base_footprint", Pose2D(2.0, 0.0, 0.0), at=0.1)
    # ours and unrelated frames change nothing
    seen.heard("map", "robot1/odom", Pose2D(9.0, 9.0, 0.0), at=0.1)
    seen.heard("robot1/odom", "robot2/base_footprint", Pose2D(9.0, 9.0, 0.0), at=0.1)
    (found, footprint), *rest = seen.poses(0.5)[0]
    assert not rest
    assert (found.x, found.y, found.yaw) == pytest.approx((1.0, 2.0, math.pi / 2))
    assert footprint is square  # the fleet's one model


def test_seen_robots_hears_a_robot_on_its_own_tf_with_plain_frames():
    """Nav2's multi-robot convention: robot2's map -> odom -> base_footprint on /robot2/tf."""
    seen = SeenRobots(("robot2",), tolerance=1.0)
    seen.heard_from("robot2", "map", "odom", Pose2D(1.0, 0.0, math.pi / 2), at=0.0)
    seen.heard_from("robot2", "odom", "base_footprint", Pose2D(2.0, 0.0, 0.0), at=0.0)
    seen.heard_from("robot3", "map", "odom", Pose2D(9.0, 9.0, 0.0), at=0.0)  # not ours
    (found, _footprint), *rest = seen.poses(0.5)[0]
    assert not rest
    assert (found.x, found.y) == pytest.approx((1.0, 2.0))


def test_a_robot_not_heard_from_for_the_tolerance_is_left_out_and_reported():
    seen = SeenRobots(("robot2", "robot3"), tolerance=1.0)
    for robot, at in (("robot2", 0.0), ("robot3", 5.0)):
        seen.heard("map", f"{robot}/odom", Pose2D(0.0, 0.0, 0.0), at=at)
        seen.heard(f"{robot}/odom", f"{robot}/base_footprint", Pose2D(1.0, 0.0, 0.0), at=at)
    found, missing = seen.poses(5.5)
    assert len(found) == 1 and found[0][1] is TURTLEBOT3_BURGER
    assert missing == ["robot2"]


@pytest.mark.parametrize(
    ("names", "message"),
    [
        (("robot2", ""), "is empty"),
        (("robot2", "robot1"), "own namespace 'robot1'"),
        (("robot2", "robot2"), "robot2 more than once"),
    ],
)
def test_a_bad_list_of_other_robots_is_explained(names: tuple[str, ...], message: str):
    problem = other_robots_problem(names, "robot1", "namespace")
    assert problem is not None and message in problem
    assert other_robots_problem(("robot2", "robot3"), "robot1", "namespace") is None


def config(*argv: str) -> Any:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return config_from_args(parser.parse_args(["--map", str(MAP), *argv]))


def test_other_robots_option_takes_comma_separated_namespaces():
    assert config("--ns", "robot1", "--other-robots", "/robot2/,robot3").other_robots == (
        "robot2",
        "robot3",
    )
    assert config().other_robots == ()
    assert config("--other-robots", "").other_robots == ()  # the launch file's default


def test_follow_clock_is_a_flag_or_a_launch_files_true_false():
    assert config("--follow-clock").follow_clock
    assert config("--follow-clock=true").sim_time  # stamps with the clock it follows
    assert not config("--follow-clock=true").publishes_clock
    assert not config("--follow-clock=false").follow_clock
    fast = config("--speed", "4", "--other-robots", "robot2")
    assert fast.publishes_clock and not fast.follow_clock


@pytest.mark.parametrize(
    ("argv", "option", "message"),
    [
        (("--ns", "robot1", "--other-robots", "robot1"), "--other-robots", "own namespace"),
        (("--other-robots", "robot2,2bad"), "--other-robots", "not a ROS 2 namespace"),
        (("--follow-clock=yes",), "--follow-clock", "expected true or false"),
        (("--follow-clock", "--speed", "2"), "--follow-clock", "publishes /clock sets the speed"),
    ],
)
def test_a_bad_fleet_option_names_the_option(argv: tuple[str, ...], option: str, message: str):
    with pytest.raises(NavseqError) as caught:
        config(*argv)
    assert option in str(caught.value) and message in str(caught.value)


def test_navseq_sim_help_explains_other_robots():
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    assert "--other-robots NS[,NS...]" in " ".join(parser.format_help().split())


# -- real ROS 2: robot1 drives round robot2 --------------------------------------------------

WATCHER = textwrap.dedent(
    """
    import json, math, sys, time
    import rclpy
    from action_msgs.msg import GoalStatus
    from nav2_msgs.action import NavigateToPose
    from nav_msgs.msg import Odometry, Path
    from rosgraph_msgs.msg import Clock
    from rclpy.action import ActionClient
    from rclpy.node import Node
    from navseq.geometry import Pose2D, compose
    from navseq.sim.footprint import TURTLEBOT3_BURGER, footprints_overlap

    setup = json.loads(sys.argv[1])
    rclpy.init()
    node = Node("fleet_watcher")
    latest = {}
    stats = {"samples": 0, "min_distance": math.inf, "overlaps": 0, "robot2_moved": 0.0,
             "robot1_off_line": 0.0, "plans": 0, "plan_min_distance": math.inf,
             "clock": None, "stamps": {}}
    robot2_start = Pose2D(*setup["starts"]["robot2"])

    def on_odom(robot):
        start = Pose2D(*setup["starts"][robot])

        def callback(msg):
            p, q = msg.pose.pose.position, msg.pose.pose.orientation
            pose = compose(start, Pose2D(p.x, p.y, 2.0 * math.atan2(q.z, q.w)))
            latest[robot] = pose
            stats["stamps"][robot] = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
            if robot == "robot2":
                moved = math.hypot(pose.x - start.x, pose.y - start.y)
                stats["robot2_moved"] = max(stats["robot2_moved"], moved)
            else:
                stats["robot1_off_line"] = max(stats["robot1_off_line"], abs(pose.x - start.x))
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

    def on_plan(msg):
        if not msg.poses:
            return
        stats["plans"] += 1
        stats["plan_min_distance"] = min(
            stats["plan_min_distance"],
            min(math.hypot(p.pose.position.x - robot2_start.x, p.pose.position.y - robot2_start.y)
                for p in msg.poses),
        )

    for robot in ("robot1", "robot2"):
        node.create_subscription(Odometry, f"/{robot}/odom", on_odom(robot), 100)
    node.create_subscription(Path, "/robot1/plan", on_plan, 10)

    def on_clock(msg):
        stats["clock"] = msg.clock.sec + msg.clock.nanosec * 1e-9

    node.create_subscription(Clock, "/clock", on_clock, 10)
    deadline = time.monotonic() + 60
    while len(latest) < 2 and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.05)
    if len(latest) < 2:
        sys.exit(f"no odometry from both robots: {sorted(latest)}")
    # Give robot1 time to hear robot2's transforms: a goal sent at once may plan
    # straight through a robot it has not seen yet (ROS 1 waits the same way).
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    client = ActionClient(node, NavigateToPose, "/robot1/navigate_to_pose")
    if not client.wait_for_server(timeout_sec=60):
        sys.exit("no /robot1/navigate_to_pose action server")
    x, y, yaw = setup["goal"]
    goal = NavigateToPose.Goal()
    goal.pose.header.frame_id = "map"
    goal.pose.pose.position.x, goal.pose.pose.position.y = x, y
    goal.pose.pose.orientation.z = math.sin(yaw / 2)
    goal.pose.pose.orientation.w = math.cos(yaw / 2)
    sent = client.send_goal_async(goal)
    rclpy.spin_until_future_complete(node, sent, timeout_sec=30)
    handle = sent.result()
    result = handle.get_result_async()
    rclpy.spin_until_future_complete(node, result, timeout_sec=setup["timeout"])
    end = time.monotonic() + 0.5  # the last odometry
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    status = result.result().status if result.done() else None
    final = latest["robot1"]
    print(json.dumps({"succeeded": status == GoalStatus.STATUS_SUCCEEDED, "status": status,
                      "robot1": [final.x, final.y, final.yaw], **stats}), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    """
)


def while_launched(
    speed: str,
    robot1: tuple[float, float, float],
    robot2: tuple[float, float, float],
    command: list[str],
    tf_convention: str = "nav2",
) -> tuple[subprocess.CompletedProcess[str], str]:
    """Run ``command`` while ``multi_robot.launch.py`` runs; its result, the launch's
    output (the launch is stopped with SIGINT, as Ctrl-C would, and must exit 0)."""
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    launch = subprocess.Popen(
        [
            "ros2",
            "launch",
            "launch/multi_robot.launch.py",
            f"robot1_start:={robot1[0]},{robot1[1]},{math.degrees(robot1[2]):g}",
            f"robot2_start:={robot2[0]},{robot2[1]},{math.degrees(robot2[2]):g}",
            f"speed:={speed}",
            f"tf_convention:={tf_convention}",
            f"python:={sys.executable}",
        ],
        cwd=REPO,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=200)
    finally:
        launch.send_signal(signal.SIGINT)
        try:
            output, _ = launch.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            launch.kill()
            output, _ = launch.communicate()
    assert done.returncode == 0, f"{done.stderr}\n{output}"
    assert launch.returncode == 0, output
    assert "Traceback" not in output, output
    return done, output


@pytest.mark.ros2
@pytest.mark.flaky(reruns=1)  # two robots in real time: under load a goal can take long
@pytest.mark.parametrize(("speed", "tf_convention"), [("1", "nav2"), ("4", "ros1")])
def test_robot1_drives_around_robot2_parked_on_its_straight_path(
    tmp_path: Path, speed: str, tf_convention: str
):
    """``ros2 launch launch/multi_robot.launch.py``, robot2 parked on robot1's way; at 4x
    robot1 publishes /clock and robot2 steps with it. The robots see each other in both
    TF conventions: Nav2's (each on its own ``/NS/tf``, plain frames) and ROS 1's."""
    # robot1 goes north along x = -2 to (-2, 1.2); robot2 is parked on that line at
    # (-2, 0.3): room round it on both sides, between the west wall and the pillars.
    robot1, robot2, goal = (-2.0, -0.5, math.pi / 2), (-2.0, 0.3, 0.0), (-2.0, 1.2, math.pi / 2)
    script = tmp_path / "fleet_watcher.py"
    script.write_text(WATCHER)
    setup = {"starts": {"robot1": robot1, "robot2": robot2}, "goal": goal, "timeout": 120}
    watcher, output = while_launched(
        speed, robot1, robot2, [sys.executable, str(script), json.dumps(setup)], tf_convention
    )
    report = json.loads(watcher.stdout.strip().splitlines()[-1])
    assert report["succeeded"], (report, output[-3000:])
    assert math.dist(report["robot1"][:2], goal[:2]) < 0.1, report
    assert report["robot2_moved"] < 0.01, report  # parked all along
    assert report["samples"] > 100, report
    # The centres never came closer than the two inscribed radii (a sure overlap), and
    # the exact test found no overlap at any sample either.
    assert report["min_distance"] >= 2 * TURTLEBOT3_BURGER.inscribed_radius, report
    assert report["overlaps"] == 0, report
    # Round robot2, not through it: every plan keeps clear of robot2's centre, and
    # robot1 left the straight line x = -2 on the way.
    assert report["plans"] >= 1, report
    assert report["plan_min_distance"] > 2 * TURTLEBOT3_BURGER.inscribed_radius, report
    assert report["robot1_off_line"] > 0.15, report
    assert "other robots robot2" in output and "other robots robot1" in output, output
    if speed == "1":
        assert report["clock"] is None, report  # wall-clock time: nobody publishes /clock
    else:
        # One simulated time: robot2's odometry is stamped with robot1's /clock (wall time
        # would be 1.8e9 s off; at 4x a loaded machine lags a step or two behind).
        assert report["clock"] is not None, report
        assert abs(report["stamps"]["robot2"] - report["clock"]) < 2.0, report
        assert abs(report["stamps"]["robot1"] - report["clock"]) < 2.0, report
        assert "following /clock" in output, output


@pytest.mark.ros2
def test_a_robot_whose_other_robot_is_not_running_still_navigates_and_warns():
    """No pose from robot2: robot1 is not blocked by a guess, and says why it ignores it."""
    from test_ros2_sim import SimProcess

    prefix = ros2_prefix()
    assert prefix is not None
    sim = SimProcess(
        ros2_environment(prefix),
        "--map",
        str(MAP),
        "--start=-2,-0.5,0",
        "--ns",
        "robot1",
        "--other-robots",
        "robot2",
    )
    try:
        seen = sim.client("navigate", "-1.6,-0.5,0", ns="robot1")
    finally:
        err = sim.stop()
        code = sim.process.returncode
    assert seen["status"] == "SUCCEEDED", seen
    assert "other robot(s) robot2: no recent pose in 'map'" in err, err
    assert code == 0 and "Traceback" not in err, err


@pytest.mark.ros2
def test_the_robot_that_follows_the_clock_navigates_too():
    """At 4x robot2 steps only with robot1's /clock: a goal of its own still succeeds,
    in about the simulated time the distance takes (not wall time, not stalled)."""
    from test_ros2_sim import client_command

    robot1, robot2 = (-2.0, -0.5, 0.0), (2.0, 0.5, math.pi)
    command = client_command("navigate", ("1.5,0.5,180",), {"ns": "robot2", "timeout": 90})
    done, output = while_launched("4", robot1, robot2, command)
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert seen["status"] == "SUCCEEDED", seen
    assert "following /clock" in output, output
    # navigation_time is simulated time: 0.5 m at the burger's 0.22 m/s is a few
    # simulated seconds, which at 4x is about a quarter of that in wall time.
    sim_seconds = seen["feedback"][-1]["navigation_time"]
    wall_seconds = seen["feedback"][-1]["t"] - seen["feedback"][0]["t"]
    assert 1.5 < sim_seconds < 15, seen["feedback"][-1]
    assert wall_seconds < sim_seconds / 2, (wall_seconds, sim_seconds)
