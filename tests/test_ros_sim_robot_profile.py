"""The simulator's ROS nodes take the robot profile ``~robot``, against a real rosmaster.

Both nodes get the profile from the same function as the in-process simulator
(:meth:`navseq.sim.profile.SimSettings.of`), so a TurtleBot3 waffle simulated as ROS
nodes is as wide, as fast and as careful about narrow gaps as ``navseq run --robot
turtlebot3_waffle``. The tests drive a waffle on a room split by a wall with two ways
through: a 0.40 m gap the burger fits through (its turning circle is 0.30 m across) but
the waffle does not (0.51 m), and a wide opening far round.
"""

from __future__ import annotations

import itertools
import json
import math
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from navseq.geometry import Pose2D
from navseq.mission.robot import TURTLEBOT3_BURGER, TURTLEBOT3_WAFFLE, RobotProfile
from navseq.sim.costmap import Costmap
from navseq.sim.mapgen import save_map
from navseq.sim.navserver import NavigationServer
from navseq.sim.occupancy import OCCUPIED, OccupancyGrid
from navseq.sim.profile import SimSettings
from ros_clients import MAP, SPEED, SUCCEEDED
from ros_support import REPO_ROOT, RosMaster, RosProcess

RESOLUTION = 0.05
START = (1.0, 1.0, 0.0)
GOAL = (3.0, 1.0, 0.0)
GAP = (0.8, 1.2)  # y range of the narrow gap in the wall at x = 2.0 .. 2.1
OPENING = (2.8, 3.6)  # y range of the wide opening, far from the straight line


def gap_room() -> OccupancyGrid:
    """4 m x 4 m, walled; a wall across x = 2.0..2.1 with the narrow gap and the opening."""
    data = np.zeros((80, 80), dtype=np.int8)
    data[:2, :] = data[-2:, :] = data[:, :2] = data[:, -2:] = OCCUPIED
    data[:, 40:42] = OCCUPIED
    for low, high in (GAP, OPENING):
        data[round(low / RESOLUTION) : round(high / RESOLUTION), 40:42] = 0
    return OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0), "gap room")


def plan_in_process(profile: RobotProfile) -> list[tuple[float, float]]:
    """The in-process simulator's plan from START to GOAL for ``profile``."""
    settings = SimSettings.of(profile)
    costmap = Costmap.from_grid(gap_room(), settings.costmap_params)
    server = NavigationServer(costmap, settings.nav_params, settings.footprint)
    plan = server.make_plan(Pose2D(*START), Pose2D(*GOAL))
    assert plan is not None
    return [(float(x), float(y)) for x, y in plan.points]


def through_the_gap(points: list[tuple[float, float]] | list[list[float]]) -> bool:
    return any(2.0 <= x <= 2.1 and GAP[0] <= y <= GAP[1] for x, y in points)


def length(points: list[tuple[float, float]] | list[list[float]]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))


def test_the_gap_room_has_a_gap_the_burger_passes_and_the_waffle_does_not():
    """Guards the map the ROS test relies on, with the in-process simulator's planner."""
    burger, waffle = plan_in_process(TURTLEBOT3_BURGER), plan_in_process(TURTLEBOT3_WAFFLE)
    assert through_the_gap(burger) and length(burger) < 2.5
    assert not through_the_gap(waffle)
    assert max(y for _, y in waffle) > OPENING[0]


# -- against a rosmaster ---------------------------------------------------------------------

# Prints one JSON line per step: the footprints both nodes publish, make_plan's path,
# then a goal driven through, with the fastest forward speed odometry showed on the way.
PROFILE_CLIENT = textwrap.dedent(
    """
    import json, math, sys
    import actionlib, rospy, tf2_ros
    from geometry_msgs.msg import PolygonStamped, PoseStamped
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
    from nav_msgs.msg import Odometry
    from nav_msgs.srv import GetPlan, GetPlanRequest

    goal_x, goal_y = json.loads(sys.argv[1])
    rospy.init_node("profile_client")
    tf_buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(tf_buffer)

    def report(**fields):
        print(json.dumps(fields), flush=True)

    def polygon(topic):
        msg = rospy.wait_for_message(topic, PolygonStamped, timeout=20)
        return msg.header.frame_id, [[p.x, p.y] for p in msg.polygon.points]

    frame, points = polygon("footprint")
    report(op="robot_footprint", frame=frame, points=points)
    frame, points = polygon("move_base/local_costmap/footprint")
    report(op="nav_footprint", frame=frame, points=points)

    target = PoseStamped()
    target.header.frame_id = "map"
    target.pose.position.x, target.pose.position.y = goal_x, goal_y
    target.pose.orientation.w = 1.0
    rospy.wait_for_service("move_base/make_plan", timeout=20)
    plan = rospy.ServiceProxy("move_base/make_plan", GetPlan)(GetPlanRequest(goal=target)).plan
    report(op="make_plan", points=[[p.pose.position.x, p.pose.position.y] for p in plan.poses])

    top = {"v": 0.0}
    def on_odom(msg):
        top["v"] = max(top["v"], msg.twist.twist.linear.x)
    rospy.Subscriber("odom", Odometry, on_odom)
    client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
    client.wait_for_server(rospy.Duration(20))
    target.header.stamp = rospy.Time.now()
    client.send_goal(MoveBaseGoal(target_pose=target))
    finished = client.wait_for_result(rospy.Duration(300))
    t = tf_buffer.lookup_transform("map", "base_footprint", rospy.Time(0), rospy.Duration(5))
    report(op="goal", finished=finished, state=client.get_state(),
           text=client.get_goal_status_text(), top_speed=top["v"],
           pose=[t.transform.translation.x, t.transform.translation.y])
    """
)


def start_sim_nodes(
    master: RosMaster, map_yaml: Path, start: tuple[float, float, float], *params: str
) -> tuple[RosProcess, RosProcess]:
    """Both sim nodes with the same extra ``_name:=value`` params, on sim time."""
    master.set_param("/use_sim_time", True)
    x, y, yaw = start
    robot = master.start(
        [
            REPO_ROOT / "nodes" / "sim_robot_node",
            f"_map:={map_yaml}",
            f"_x:={x}",
            f"_y:={y}",
            f"_yaw:={yaw}",
            f"_speed:={SPEED}",
            *params,
        ],
        label="sim_robot",
    )
    nav = master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={map_yaml}", *params], label="move_base"
    )
    master.wait_for_action_server("/move_base", timeout=30)
    return robot, nav


def run_profile_client(master: RosMaster, tmp_path: Path) -> dict[str, dict[str, Any]]:
    script = tmp_path / "profile_client.py"
    script.write_text(PROFILE_CLIENT)
    client = master.start_python(script, json.dumps(GOAL[:2]))
    assert client.wait(timeout=180) == 0, client.output()[-4000:]
    lines = [json.loads(line) for line in client.output().splitlines() if line.startswith("{")]
    return {line["op"]: line for line in lines}


def flat(points: Any) -> list[float]:
    """[[x, y], ...] as [x, y, ...] (pytest.approx compares flat sequences only)."""
    return [float(v) for point in points for v in point]


@pytest.mark.ros
def test_a_waffle_is_simulated_with_its_outline_its_speed_and_its_room_to_turn(
    ros_master: RosMaster, tmp_path: Path
):
    map_yaml = save_map(gap_room(), tmp_path / "gap_room.yaml")
    robot, nav = start_sim_nodes(ros_master, map_yaml, START, "_robot:=turtlebot3_waffle")
    steps = run_profile_client(ros_master, tmp_path)
    waffle = flat(TURTLEBOT3_WAFFLE.footprint)

    # Both nodes show the waffle's outline: the robot in its base frame, move_base at the
    # robot's pose in the map frame (the robot has not moved yet).
    assert steps["robot_footprint"]["frame"] == "base_footprint"
    assert flat(steps["robot_footprint"]["points"]) == pytest.approx(waffle, abs=1e-6)
    assert steps["nav_footprint"]["frame"] == "map"
    shifted = flat((x + START[0], y + START[1]) for x, y in TURTLEBOT3_WAFFLE.footprint)
    assert flat(steps["nav_footprint"]["points"]) == pytest.approx(shifted, abs=1e-3)

    # The 0.40 m gap is too narrow for the waffle to turn in: the plan goes round.
    plan = steps["make_plan"]["points"]
    assert plan, "the waffle can reach the goal the long way round"
    assert not through_the_gap(plan), plan
    assert max(y for _, y in plan) > OPENING[0]

    # It drives there at the waffle's top speed (the burger's is 0.22 m/s), never faster,
    # and without bumping into anything.
    driven = steps["goal"]
    assert driven["state"] == SUCCEEDED, driven
    assert math.dist(driven["pose"], GOAL[:2]) < 0.1, driven
    assert driven["top_speed"] == pytest.approx(TURTLEBOT3_WAFFLE.max_linear_speed, abs=0.005)
    assert "cmd_vel refused" not in robot.output(), robot.output()[-3000:]

    # move_base's parameters describe the waffle, so a client that reads the robot from
    # them (navseq run --navigator ros1) checks the mission with the right outline.
    from navseq.roscore.stack_profile import profile_from_navstack_params

    read, _ = profile_from_navstack_params(ros_master.get_param("/move_base"), "/move_base")
    assert flat(read.footprint) == pytest.approx(waffle)
    assert read.max_linear_speed == TURTLEBOT3_WAFFLE.max_linear_speed
    assert read.goal_tolerance == TURTLEBOT3_WAFFLE.goal_tolerance
    assert "robot turtlebot3_waffle" in nav.output()


@pytest.mark.ros
def test_explicit_nav_params_still_override_the_profile(ros_master: RosMaster, tmp_path: Path):
    robot_file = tmp_path / "round.yaml"
    robot_file.write_text("base: turtlebot3_waffle\nradius: 0.12\nxy_goal_tolerance: 0.1\n")
    map_yaml = save_map(gap_room(), tmp_path / "gap_room.yaml")
    _, nav = start_sim_nodes(
        ros_master,
        map_yaml,
        START,
        f"_robot:={robot_file}",
        "_inflation_radius:=0.4",
        "_xy_goal_tolerance:=0.07",
    )
    nav.wait_for_output("sim move_base ready", timeout=30)
    params = ros_master.get_param("/move_base")
    costmap = params["global_costmap"]
    # The robot file's round outline (16 points at 0.12 m) ...
    assert len(costmap["footprint"]) == 16
    assert max(math.hypot(x, y) for x, y in costmap["footprint"]) == pytest.approx(0.12)
    # ... its base's speed, and the node's own parameters where they are given.
    planner = params["RegulatedPurePursuit"]
    assert planner["max_vel_x"] == TURTLEBOT3_WAFFLE.max_linear_speed
    assert planner["xy_goal_tolerance"] == pytest.approx(0.07)
    assert costmap["inflation_layer"]["inflation_radius"] == pytest.approx(0.4)


@pytest.mark.ros
@pytest.mark.parametrize("node", ["sim_robot_node", "sim_nav_node"])
@pytest.mark.parametrize(
    ("value", "problem"),
    [
        ("turtlebot3_wafle", "did you mean 'turtlebot3_waffle'?"),
        ("/nonexistent/robot.yaml", "/nonexistent/robot.yaml"),
    ],
)
def test_a_bad_robot_param_stops_the_node_with_one_clear_line(
    ros_master: RosMaster, node: str, value: str, problem: str
):
    name = "sim_robot" if node == "sim_robot_node" else "move_base"
    # A map and a start pose that are fine: the robot is the only thing wrong.
    fine = (f"_map:={MAP}", "_x:=-2.0", "_y:=-0.5")
    process = ros_master.start(
        [REPO_ROOT / "nodes" / node, f"__name:={name}", *fine, f"_robot:={value}"], label=node
    )
    assert process.wait(timeout=30) == 2, process.output()
    output = process.output()
    assert f"param /{name}/robot" in output and problem in output, output
    assert "Traceback" not in output, output
