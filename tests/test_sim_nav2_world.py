"""The world of the Nav2 stand-in without ROS: localisation with drifting odometry, the
laser, the velocity chain and a map replaced at run time (issue 20)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pytest

from navseq.commands.sim_options import add_arguments, config_from_args
from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.ros2.standin import Nav2StandIn, Navigator, NavTask, Outcome
from navseq.sim.footprint import TURTLEBOT3_BURGER
from navseq.sim.localization import Localization
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.options import SimConfig
from navseq.sim.scan import TURTLEBOT3_LDS, ray_cast
from navseq.sim.velocity_chain import SpeedLimit, VelocitySmoother
from navseq.sim.world import SimWorld

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
START = Pose2D(-2.0, -0.5, 0.0)


@pytest.fixture(scope="module")
def grid() -> OccupancyGrid:
    return load_map(MAP)


def run_until_done(standin: Nav2StandIn, task: NavTask, seconds: float = 120.0) -> None:
    for _ in range(round(seconds / standin.world.dt)):
        if task.ending is not None:
            return
        standin.step()
    raise AssertionError(f"not done after {seconds} simulated seconds")


def drive_straight(localization: Localization, metres: float, step: float = 0.01) -> Pose2D:
    pose = Pose2D(0.0, 0.0, 0.0)
    for _ in range(round(metres / step)):
        pose = Pose2D(pose.x + step, pose.y, pose.yaw)
        localization.moved(pose)
    return pose


# -- localisation --------------------------------------------------------------------------


def test_exact_odometry_keeps_the_belief_on_the_truth():
    localization = Localization(Pose2D(0.0, 0.0, 0.0))
    true = drive_straight(localization, 2.0)
    assert localization.error() < 1e-9
    assert localization.odom_pose.x == pytest.approx(true.x)


def test_drifting_odometry_errs_and_the_estimate_corrects_it():
    localization = Localization(Pose2D(0.0, 0.0, 0.0), drift=0.05)
    true = drive_straight(localization, 4.0)
    odometry_alone = localization.odom_pose  # where odometry alone puts the robot (start 0)
    assert odometry_alone.distance_to(true) > 0.2  # 5 % and 0.05 rad per metre over 4 m
    # amcl-like updates every 0.25 m keep the belief far nearer than odometry alone.
    assert localization.error() < 0.05
    assert localization.updates >= 10


def test_an_initial_pose_moves_the_belief_and_driving_pulls_it_back_to_the_truth():
    localization = Localization(Pose2D(0.0, 0.0, 0.0))
    localization.set_pose(Pose2D(0.5, 0.3, 0.2))
    assert localization.believed_pose.x == pytest.approx(0.5)
    assert localization.error() == pytest.approx(math.hypot(0.5, 0.3))
    drive_straight(localization, 0.1)  # less than update_min_d: no correction yet
    assert localization.error() > 0.5
    drive_straight(localization, 3.0)
    assert localization.error() < 0.01


def test_a_standin_goal_is_steered_from_the_belief_not_the_truth(grid: OccupancyGrid):
    """A wrong initial pose makes the robot stop short of the goal in truth, until amcl's
    corrections catch up; a right one changes nothing."""
    standin = Nav2StandIn(SimWorld(grid, START))
    standin.set_initial_pose(Pose2D(START.x + 0.3, START.y, 0.0))  # believes 0.3 m ahead
    assert standin.world.robot.pose == START  # the robot did not move
    task = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.7, -0.5, 0.0)])
    run_until_done(standin, task)
    assert task.ending is not None and task.ending.outcome is Outcome.SUCCEEDED
    # Believing itself at -1.7 after barely 0.25 m of driving (no update yet), it is short.
    assert standin.world.robot.pose.x < -1.85
    assert standin.localization.believed_pose.x == pytest.approx(-1.7, abs=0.06)


# -- the laser -------------------------------------------------------------------------------


def test_the_scan_sees_the_map_where_the_map_is_occupied(grid: OccupancyGrid):
    ranges = ray_cast(grid, START)
    assert ranges.shape == (360,) and ranges.dtype == np.float32
    finite = np.isfinite(ranges)
    assert finite.sum() > 100
    assert ranges[finite].min() >= TURTLEBOT3_LDS.range_min
    assert ranges[finite].max() <= TURTLEBOT3_LDS.range_max
    # Each finite beam ends in an occupied cell, with free space half a range before it.
    occupied = grid.occupied_mask()
    sensor_x = START.x + TURTLEBOT3_LDS.mount_x
    for beam in np.flatnonzero(finite)[::20]:
        angle, distance = beam * TURTLEBOT3_LDS.angle_increment, float(ranges[beam])
        end = grid.world_to_cell(
            sensor_x + distance * math.cos(angle), START.y + distance * math.sin(angle)
        )
        middle = grid.world_to_cell(
            sensor_x + distance / 2 * math.cos(angle), START.y + distance / 2 * math.sin(angle)
        )
        assert occupied[end] and not occupied[middle], beam


def test_the_scan_sees_another_robot_in_front(grid: OccupancyGrid):
    other = Pose2D(START.x + 1.0, START.y, 0.0)
    ranges = ray_cast(grid, START, others=[(other, TURTLEBOT3_BURGER)])
    back_edge = other.x + float(TURTLEBOT3_BURGER.polygon[:, 0].min())
    expected = back_edge - (START.x + TURTLEBOT3_LDS.mount_x)
    assert float(ranges[0]) == pytest.approx(expected, abs=1e-4)
    assert float(ray_cast(grid, START)[0]) > expected + 0.1  # without it: farther


# -- the velocity chain ------------------------------------------------------------------------


def test_the_smoother_ramps_clips_and_stops_when_commands_stop():
    smoother = VelocitySmoother()
    smoother.command(1.0, 3.0, now=0.0)
    outputs = [smoother.step(now=k * 0.05, dt=0.05) for k in range(1, 21)]
    assert outputs[0] == pytest.approx((0.125, 0.16))  # 2.5 m/s² and 3.2 rad/s² for 50 ms
    assert outputs[-1] == pytest.approx((0.5, 2.0))  # nav2_bringup's max_velocity
    assert smoother.step(now=2.5, dt=0.05) == (0.0, 0.0)  # 1 s without a command


def test_the_speed_limit_caps_linear_speed_and_keeps_the_curvature():
    limit = SpeedLimit(max_linear=0.22)
    limit.set(percentage=True, value=50.0)
    assert limit.apply(0.22, 1.0) == pytest.approx((0.11, 0.5))
    limit.set(percentage=False, value=0.05)
    assert limit.apply(-0.2, 0.0) == pytest.approx((-0.05, 0.0))
    assert limit.apply(0.0, 1.5) == (0.0, 1.5)  # turning in place is not limited
    limit.set(percentage=False, value=0.0)  # Nav2's "no limit"
    assert limit.apply(0.22, 1.0) == (0.22, 1.0)


def test_a_speed_limit_slows_a_standin_goal(grid: OccupancyGrid):
    fastest = []
    for value in (0.0, 0.1):
        standin = Nav2StandIn(SimWorld(grid, START))
        standin.speed_limit.set(percentage=False, value=value)
        task = standin.navigate(Navigator.TO_POSE, [Pose2D(-1.0, -0.5, 0.0)])
        top = 0.0
        while task.ending is None:
            standin.step()
            top = max(top, standin.world.robot.v)
        fastest.append(top)
    assert fastest[0] > 0.2 and fastest[1] == pytest.approx(0.1, abs=1e-6)


def test_teleop_drives_the_robot_only_while_no_goal_runs(grid: OccupancyGrid):
    standin = Nav2StandIn(SimWorld(grid, START))
    assert standin.command(0.1, 0.0)
    for _ in range(20):
        standin.step()
    assert standin.world.robot.pose.x > START.x + 0.03  # 0.1 m/s for its 0.5 s timeout
    standin.navigate(Navigator.TO_POSE, [Pose2D(-1.0, -0.5, 0.0)])
    assert not standin.command(-0.1, 0.0)


# -- a new map ---------------------------------------------------------------------------------


def test_a_new_map_replaces_the_world(grid: OccupancyGrid):
    standin = Nav2StandIn(SimWorld(grid, START))
    goal = Pose2D(-1.0, -0.5, 0.0)
    # The same arena with a wall across the robot's way, x = -1.5 from y = -1.2 to 0.2.
    data = grid.data.copy()
    rows, cols = np.indices(data.shape)
    xs, ys = grid.cells_to_world(rows.ravel(), cols.ravel()).T
    wall = (np.abs(xs + 1.5) < 0.05) & (ys > -1.2) & (ys < 0.2)
    data.ravel()[wall] = 100
    walled = OccupancyGrid(data, grid.resolution, grid.origin, source="walled")
    assert standin.replace_map(walled) is None  # the robot does not overlap the wall
    assert standin.world.server.costmap.grid is walled
    task = standin.navigate(Navigator.TO_POSE, [goal])
    run_until_done(standin, task)
    assert task.ending is not None and task.ending.outcome is Outcome.SUCCEEDED
    plan = standin.world.server.plan
    assert plan is not None
    assert (plan.points[:, 1] < -1.2).any() or (plan.points[:, 1] > 0.2).any()  # round it
    assert standin.world.collisions == 0
    full = OccupancyGrid(np.full_like(grid.data, 100), grid.resolution, grid.origin)
    warning = standin.replace_map(full)
    assert warning is not None and "overlaps an obstacle" in warning


# -- the options -------------------------------------------------------------------------------


def sim_config(*argv: str, ros1: bool = False) -> SimConfig:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return config_from_args(parser.parse_args(["--map", str(MAP), *argv]), ros1=ros1)


def test_a_namespaced_robot_takes_nav2s_tf_convention_unless_told_otherwise():
    nav2 = sim_config("--ns", "robot1")
    assert nav2.tf_topics == ("/robot1/tf", "/robot1/tf_static") and nav2.frame_prefix == ""
    ros1 = sim_config("--ns", "robot1", "--tf-convention", "ros1")
    assert ros1.tf_topics == ("/tf", "/tf_static") and ros1.frame_prefix == "robot1/"
    assert sim_config().tf_topics == ("/tf", "/tf_static")  # no namespace: the same
    assert sim_config("--ns", "robot1", ros1=True).frame_prefix == "robot1/"  # ROS 1's nodes


@pytest.mark.parametrize(
    ("argv", "ros1", "option"),
    [
        (("--tf-convention", "nav2"), True, "--tf-convention"),
        (("--odom-drift", "-0.1"), False, "--odom-drift"),
        (("--odom-drift", "nan"), False, "--odom-drift"),
        (("--odom-drift", "0.1"), True, "--odom-drift"),
    ],
)
def test_a_bad_world_option_names_itself(argv: tuple[str, ...], ros1: bool, option: str):
    with pytest.raises(NavseqError) as raised:
        sim_config(*argv, ros1=ros1)
    assert raised.value.source == option
