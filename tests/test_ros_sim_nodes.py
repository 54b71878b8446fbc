"""The simulator's ROS nodes serve ordinary move_base clients, against a real rosmaster.

Each test starts its own rosmaster, the sim robot node and the move_base stand-in
(``nodes/sim_robot_node``, ``nodes/sim_nav_node``) on the TurtleBot3 world at several
times real time, and drives them with plain rospy/actionlib clients run as
subprocesses (``ros_clients.SIM_CLIENT`` is written to a file and fed a JSON list of
steps; it prints one JSON line per step).
"""

from __future__ import annotations

import itertools
import math
import textwrap
import time
from pathlib import Path

import pytest

from ros_clients import (
    ABORTED,
    EXAMPLE_MISSION,
    MAP,
    PREEMPTED,
    START,
    SUCCEEDED,
    TUTORIAL_DONE_CB_CLIENT,
    goal,
    reports,
    run_client,
    start_client,
    start_sim,
)
from ros_support import REPO_ROOT, RosMaster

pytestmark = pytest.mark.ros

PILLAR = (0.0, 0.0)  # the centre pillar of the arena: no robot fits there


# -- helpers ---------------------------------------------------------------------------------


def yaw_error(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def example_mission_goals() -> tuple[tuple[float, float, float], list[tuple[float, float, float]]]:
    """Start pose and (x, y, yaw radians) of every waypoint of the example mission."""
    from navseq.mission import load_mission

    mission = load_mission(EXAMPLE_MISSION)
    start = mission.start
    assert start is not None, "the example mission names its start pose"
    return (start.x, start.y, start.yaw), [(w.x, w.y, w.yaw_rad) for w in mission.waypoints]


# -- move_base clients ------------------------------------------------------------------------


def test_plain_sequence_client_reaches_every_waypoint_of_the_example_mission(
    ros_master: RosMaster, tmp_path: Path
):
    start, waypoints = example_mission_goals()
    start_sim(ros_master, start)
    results = run_client(ros_master, tmp_path, [goal(*w) for w in waypoints], timeout=240)
    for (x, y, yaw), result in zip(waypoints, results, strict=True):
        assert result["state"] == SUCCEEDED, result
        px, py, pyaw = result["pose"]
        assert math.hypot(px - x, py - y) < 0.1, result
        assert yaw_error(pyaw, yaw) < 0.25, result


def test_tutorial_done_cb_client_gets_its_first_goal_then_stalls(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master)
    points = [(-1.5, -0.5, 0.0), (-0.5, -1.6, 0.0), (0.5, -1.6, 90.0)]
    ros_master.set_param("/move_base_seq/p_seq", [v for x, y, _ in points for v in (x, y, 0.0)])
    ros_master.set_param("/move_base_seq/yea_seq", [yaw for _, _, yaw in points])
    # A bystander that prints every result the sim publishes.
    monitor = start_client(
        ros_master, tmp_path, [{"op": "watch_results", "count": 2}], label="monitor"
    )
    monitor.wait_for_output('"op": "watching"', timeout=30)
    script = tmp_path / "move_base_seq.py"
    script.write_text(TUTORIAL_DONE_CB_CLIENT)
    tutorial = ros_master.start_python(script)
    tutorial.wait_for_output("DONE 1 status 3", timeout=60)
    # Goal 2, sent from inside done_cb, reaches the sim and succeeds there ...
    assert monitor.wait(timeout=60) == 0, monitor.output()
    assert reports(monitor)[-1] == {"op": "watch_results", "results": [SUCCEEDED] * 2}
    # ... but the tutorial never hears of it: a bounded wait of several goal durations.
    time.sleep(3.0)
    assert tutorial.running(), tutorial.output()
    assert "DONE 2" not in tutorial.output(), tutorial.output()


def test_goal_in_a_wall_is_aborted_and_the_robot_stays(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    aborted, reachable = run_client(ros_master, tmp_path, [goal(*PILLAR), goal(-1.5, -0.5)])
    assert aborted["state"] == ABORTED, aborted
    assert aborted["text"], "an aborted goal says why"
    assert math.hypot(aborted["pose"][0] - START[0], aborted["pose"][1] - START[1]) < 0.01
    # The server is not stuck on the failure: the next goal is served.
    assert reachable["state"] == SUCCEEDED, reachable


def test_a_goal_from_another_client_preempts_the_active_one(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    first = start_client(
        ros_master,
        tmp_path,
        [goal(1.6, 0.5, op="send"), {"op": "wait_moving"}, {"op": "wait_result"}],
        label="first",
    )
    first.wait_for_output('"op": "wait_moving"', timeout=60)
    second = run_client(ros_master, tmp_path, [goal(-1.5, -1.0)])
    assert first.wait(timeout=60) == 0, first.output()
    preempted = reports(first)[-1]
    assert preempted["state"] == PREEMPTED, preempted
    assert second[0]["state"] == SUCCEEDED, second


def test_cancel_ends_the_goal_preempted_and_the_robot_stops(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    _, moving, canceled, settled = run_client(
        ros_master,
        tmp_path,
        [goal(1.6, 0.5, op="send"), {"op": "wait_moving"}, {"op": "cancel"}, {"op": "settle"}],
    )
    assert moving["v"] > 0.05, moving
    assert canceled["state"] == PREEMPTED, canceled
    assert settled["moved"] < 0.005 and settled["turned"] < 0.01, settled
    assert settled["v"] == 0.0 and settled["w"] == 0.0, settled


def test_initialpose_teleports_the_robot_and_odometry_stays_continuous(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master)
    odom_before, teleported, odom_after, refused, driven = run_client(
        ros_master,
        tmp_path,
        [
            {"op": "odom_pose"},
            {"op": "initialpose", "x": 1.6, "y": 0.5, "yaw": math.pi / 2},
            {"op": "odom_pose"},
            {"op": "initialpose", "x": PILLAR[0], "y": PILLAR[1], "yaw": 0.0},
            goal(1.6, 1.6, math.pi / 2),
        ],
    )
    assert (odom_before["frame"], odom_before["child"]) == ("odom", "base_footprint")
    assert odom_before["pose"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    assert teleported["pose"] == pytest.approx([1.6, 0.5, math.pi / 2], abs=1e-3)
    # Like a localisation jump: map -> odom moves, odometry itself does not jump.
    assert odom_after["pose"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    # A pose inside a pillar is refused; the robot stays where it was put.
    assert refused["pose"] == pytest.approx([1.6, 0.5, math.pi / 2], abs=1e-3)
    # Navigation plans from the new place.
    assert driven["state"] == SUCCEEDED, driven


def test_make_plan_and_clear_costmaps_services(ros_master: RosMaster, tmp_path: Path):
    start_sim(ros_master)
    from_robot, given_start, into_wall, cleared = run_client(
        ros_master,
        tmp_path,
        [
            {"op": "make_plan", "goal": [1.6, 0.5, 0.0]},
            {"op": "make_plan", "start": [-0.5, -1.6, 0.0], "goal": [-0.5, 1.6, 0.0]},
            {"op": "make_plan", "goal": [*PILLAR, 0.0]},
            {"op": "clear_costmaps"},
        ],
    )
    assert from_robot["frame"] == "map"
    points = from_robot["points"]
    assert points[0] == pytest.approx(list(START[:2]), abs=0.05)
    assert points[-1] == pytest.approx([1.6, 0.5], abs=0.05)
    # A path around the pillars is longer than the straight line through them.
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    assert length > math.dist(START[:2], (1.6, 0.5)) + 0.1
    assert given_start["points"][0] == pytest.approx([-0.5, -1.6], abs=0.05)
    assert given_start["points"][-1] == pytest.approx([-0.5, 1.6], abs=0.05)
    assert into_wall["points"] == []
    assert cleared == {"op": "clear_costmaps"}


def test_rviz_2d_nav_goal_on_move_base_simple_drives_the_robot(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master)
    (result,) = run_client(ros_master, tmp_path, [goal(-1.5, -1.0, -math.pi / 2, "simple_goal")])
    assert result["results"] == [SUCCEEDED], result
    assert result["pose"][:2] == pytest.approx([-1.5, -1.0], abs=0.1)


def test_a_goal_without_a_robot_is_aborted_not_hung(ros_master: RosMaster, tmp_path: Path):
    # Only the navigation node, in wall time: no TF ever arrives.
    nav = ros_master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={MAP}", "_pose_timeout:=1.0"],
        label="move_base",
    )
    ros_master.wait_for_action_server("/move_base", timeout=30)
    script = tmp_path / "lonely_client.py"
    script.write_text(
        textwrap.dedent(
            """
            import actionlib, rospy
            from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
            rospy.init_node("lonely_client")
            client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
            assert client.wait_for_server(rospy.Duration(30))
            goal = MoveBaseGoal()
            goal.target_pose.header.frame_id = "map"
            goal.target_pose.pose.position.x = -1.5
            goal.target_pose.pose.orientation.w = 1.0
            client.send_goal(goal)
            assert client.wait_for_result(rospy.Duration(20))
            print("STATE", client.get_state(), client.get_goal_status_text(), flush=True)
            """
        )
    )
    client = ros_master.start_python(script)
    assert client.wait(timeout=40) == 0, client.output() + nav.output()
    assert f"STATE {ABORTED}" in client.output()
    assert "base_footprint" in client.output()
