"""The robot as Nav2's node parameters describe it (no ROS 2 needed: the rules are pure)."""

from __future__ import annotations

import math

import pytest

from navseq.errors import NavseqError
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.ros2.nav2_params import navstack_tree, profile_from_nav2_params

# What Nav2's TurtleBot3 waffle configuration holds (nav2_bringup's nav2_params.yaml,
# DWB controller), as `ros2 param dump` gives it: dotted names per node.
WAFFLE_DWB = {
    "controller_server": {
        "controller_plugins": ["FollowPath"],
        "goal_checker_plugins": ["general_goal_checker"],
        "general_goal_checker.xy_goal_tolerance": 0.25,
        "general_goal_checker.yaw_goal_tolerance": 0.25,
        "FollowPath.max_vel_x": 0.26,
        "FollowPath.max_vel_theta": 1.0,
        "FollowPath.acc_lim_x": 2.5,
        "FollowPath.acc_lim_theta": 3.2,
    },
    "local_costmap": {
        "footprint": "[[-0.205, -0.155], [-0.205, 0.155], [0.077, 0.155], [0.077, -0.155]]",
        "robot_radius": 0.1,
        "inflation_layer.inflation_radius": 0.55,
        "inflation_layer.cost_scaling_factor": 3.0,
    },
}


def test_nav2_s_goal_checker_controller_and_costmap_make_the_profile() -> None:
    robot, note = profile_from_nav2_params(WAFFLE_DWB, "")
    assert robot.goal_tolerance.xy_m == 0.25
    assert robot.goal_tolerance.yaw_rad == pytest.approx(0.25)
    assert robot.max_linear_speed == 0.26 and robot.max_angular_speed == 1.0
    assert robot.max_linear_accel == 2.5 and robot.max_angular_accel == 3.2
    assert len(robot.footprint) == 4 and robot.footprint[0] == (-0.205, -0.155)
    assert robot.inflation_radius == 0.55
    assert note.startswith("robot from Nav2's parameters under /: footprint 4 points")
    assert "tolerance 0.25 m / 14°" in note


def test_regulated_pure_pursuit_names_and_a_round_robot_are_read_too() -> None:
    params = {
        "controller_server": {
            "controller_plugins": ["FollowPath"],
            "goal_checker_plugins": ["goal_checker"],
            "goal_checker.xy_goal_tolerance": 0.2,
            "FollowPath.desired_linear_vel": 0.5,
            "FollowPath.rotate_to_heading_angular_vel": 1.8,
        },
        "global_costmap": {"footprint": "[]", "robot_radius": 0.3},
    }
    robot, note = profile_from_nav2_params(params, "robot1")
    assert robot.max_linear_speed == 0.5 and robot.max_angular_speed == 1.8
    assert robot.goal_tolerance.xy_m == 0.2
    assert robot.goal_tolerance.yaw_rad == DEFAULT_PROFILE.goal_tolerance.yaw_rad  # not said
    assert max(math.hypot(x, y) for x, y in robot.footprint) == pytest.approx(0.3, abs=1e-6)
    assert "under /robot1" in note and "robot_radius 0.3 m" in note


def test_a_nav2_that_says_nothing_leaves_the_default_and_says_so() -> None:
    robot, note = profile_from_nav2_params({}, "")
    assert robot == DEFAULT_PROFILE
    assert "no robot parameters" in note and "turtlebot3_burger" in note
    assert navstack_tree({"controller_server": {"controller_plugins": []}}) == {}


def test_a_bad_value_names_the_parameter() -> None:
    params = {"local_costmap": {"footprint": "[[0.1, 0.1]]"}}
    with pytest.raises(NavseqError, match="local_costmap/footprint"):
        profile_from_nav2_params(params, "")
