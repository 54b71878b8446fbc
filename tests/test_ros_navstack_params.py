"""The robot profile from a running move_base's parameters (navseq.roscore.stack_profile).

The parsing is checked in process on parameter trees shaped like move_base's; the
whole path — parameters on a real rosmaster, ``navseq run --navigator ros1`` reading
them after the server answers, the note on stderr and the report — in a subprocess.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cli_support import NAVSEQ, write_mission
from navseq.errors import NavseqError
from navseq.mission.robot import TURTLEBOT3_BURGER, TURTLEBOT3_WAFFLE
from navseq.roscore.stack_profile import parse_footprint, profile_from_navstack_params
from ros_clients import start_scripted_server
from ros_support import RosMaster

WAFFLE_LIKE = "[[-0.205, -0.155], [-0.205, 0.155], [0.077, 0.155], [0.077, -0.155]]"


def move_base_tree(**overrides):
    """Parameters as turtlebot3_navigation's move_base.launch leaves them (waffle)."""
    tree = {
        "base_local_planner": "dwa_local_planner/DWAPlannerROS",
        "global_costmap": {
            "footprint": WAFFLE_LIKE,
            "inflation_layer": {"inflation_radius": 1.0, "cost_scaling_factor": 3.0},
        },
        "local_costmap": {"footprint": WAFFLE_LIKE, "inflation_radius": 1.0},
        "DWAPlannerROS": {
            "xy_goal_tolerance": 0.05,
            "yaw_goal_tolerance": 0.17,
            "max_vel_x": 0.26,
            "max_vel_theta": 1.82,
            "acc_lim_x": 2.5,
            "acc_lim_theta": 3.2,
        },
    }
    tree.update(overrides)
    return tree


def test_a_waffles_move_base_params_give_the_waffles_profile():
    profile, note = profile_from_navstack_params(move_base_tree(), "/move_base")
    assert profile.footprint == TURTLEBOT3_WAFFLE.footprint
    assert profile.max_linear_speed == 0.26 and profile.max_angular_speed == 1.82
    assert profile.goal_tolerance == TURTLEBOT3_WAFFLE.goal_tolerance
    assert profile.source == "/move_base parameters"
    assert note == (
        "robot from /move_base parameters: footprint 4 points, circumscribed 0.26 m, "
        "inflation 1 m x 3, tolerance 0.05 m / 10°, max 0.26 m/s / 1.82 rad/s"
    )


def test_robot_radius_gives_a_round_robot_and_missing_values_keep_the_base():
    tree = {
        "local_costmap": {"robot_radius": 0.3},
        "TrajectoryPlannerROS": {"xy_goal_tolerance": 0.2, "max_rot_vel": 1.0},
    }
    profile, note = profile_from_navstack_params(tree, "/robot1/move_base")
    assert profile.circumscribed_radius == pytest.approx(0.3)
    assert profile.goal_tolerance.xy_m == 0.2
    assert profile.goal_tolerance.yaw_rad == TURTLEBOT3_BURGER.goal_tolerance.yaw_rad
    assert profile.max_angular_speed == 1.0
    assert profile.max_linear_speed == TURTLEBOT3_BURGER.max_linear_speed
    assert profile.inflation_radius == TURTLEBOT3_BURGER.inflation_radius
    assert note.startswith("robot from /robot1/move_base parameters: robot_radius 0.3 m")


def test_nothing_to_read_keeps_the_base_profile_and_says_so():
    profile, note = profile_from_navstack_params({"controller_frequency": 10.0}, "/move_base")
    assert profile == TURTLEBOT3_BURGER
    assert "no robot parameters in /move_base parameters" in note and "turtlebot3_burger" in note


@pytest.mark.parametrize(
    ("tree", "param", "complaint"),
    [
        (
            {"global_costmap": {"footprint": "[[0.1, 0.1], [0.2]]"}},
            "/move_base/global_costmap/footprint",
            "[x, y]",
        ),
        (
            {"global_costmap": {"footprint": [[0.1, 0.1], [0.2, -0.1]]}},
            "/move_base/global_costmap/footprint",
            "2 point",
        ),
        (
            {"local_costmap": {"footprint": "0.1, 0.2"}},
            "/move_base/local_costmap/footprint",
            "at least 3 points",
        ),
        (
            {"global_costmap": {"robot_radius": "big"}},
            "/move_base/global_costmap/robot_radius",
            "expected a number",
        ),
        (
            {"DWAPlannerROS": {"xy_goal_tolerance": -0.1}},
            "/move_base/DWAPlannerROS/xy_goal_tolerance",
            "> 0",
        ),
        (
            {"global_costmap": {"inflation_layer": {"inflation_radius": True}}},
            "/move_base/global_costmap/inflation_layer/inflation_radius",
            "expected a number",
        ),
    ],
)
def test_a_bad_value_is_a_clear_error_naming_the_param(tree, param, complaint):
    with pytest.raises(NavseqError) as raised:
        profile_from_navstack_params(tree, "/move_base")
    message = str(raised.value)
    assert f"param {param}" in message and complaint in message, message


coordinate = st.floats(min_value=-2.0, max_value=2.0, allow_nan=False).map(lambda v: round(v, 4))


@given(st.lists(st.tuples(coordinate, coordinate), min_size=3, max_size=12))
def test_the_string_form_of_a_footprint_reads_as_the_list_form(points):
    as_list = [[x, y] for x, y in points]
    as_string = "[" + ", ".join(f"[{x!r}, {y!r}]" for x, y in points) + "]"
    assert parse_footprint(as_string, "p") == parse_footprint(as_list, "p") == tuple(points)


# -- on a real rosmaster -------------------------------------------------------------------


@pytest.mark.ros
def test_navseq_run_reads_the_robot_from_the_running_move_base(
    ros_master: RosMaster, tmp_path: Path
):
    for name, value in {
        "/move_base/global_costmap/footprint": WAFFLE_LIKE,
        "/move_base/DWAPlannerROS/xy_goal_tolerance": 0.1,
        "/move_base/DWAPlannerROS/yaw_goal_tolerance": math.radians(20),
    }.items():
        ros_master.set_param(name, value)
    start_scripted_server(ros_master, "--then", "succeed:0.1")
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 1, y: 0, yaw: 0}\n")
    out = tmp_path / "out"
    navseq = ros_master.start(
        [NAVSEQ, "run", mission, "--navigator", "ros1", "--out", out],
        cwd=tmp_path,
        label="navseq",
    )
    assert navseq.wait(timeout=60) == 0, navseq.output()[-3000:]
    note = (
        "robot from /move_base parameters: footprint 4 points, circumscribed 0.26 m, "
        "tolerance 0.1 m / 20°"
    )
    assert f"navseq run: {note}" in navseq.output()
    navigator = json.loads((out / "report.json").read_text())["navigator"]
    assert navigator["robot"] == "navstack:/move_base"
    assert navigator["robot_source"] == note


@pytest.mark.ros
def test_a_bad_move_base_param_stops_navseq_run_before_the_robot_moves(
    ros_master: RosMaster, tmp_path: Path
):
    ros_master.set_param("/move_base/local_costmap/footprint", "[[0.1, 0.1]]")
    log = tmp_path / "server.jsonl"
    start_scripted_server(ros_master, "--log", str(log))
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 1, y: 0, yaw: 0}\n")
    navseq = ros_master.start(
        [NAVSEQ, "run", mission, "--navigator", "ros1", "--out", tmp_path / "out"],
        cwd=tmp_path,
        label="navseq",
    )
    assert navseq.wait(timeout=60) == 2, navseq.output()[-3000:]
    assert "param /move_base/local_costmap/footprint" in navseq.output()
    assert "Traceback" not in navseq.output()
    assert not (tmp_path / "out").exists()
    assert "goal" not in (log.read_text() if log.exists() else "")
