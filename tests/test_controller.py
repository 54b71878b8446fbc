"""Regulated pure pursuit: reaches goals within tolerance, turns first, slows where it should."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navseq.geometry import Pose2D, normalize_angle
from navseq.sim.controller import ControllerParams, RegulatedPurePursuit
from navseq.sim.costmap import Costmap
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.robot import DiffDriveRobot

DT = 0.05


def open_costmap(size_m: float = 6.0, wall_at_y: float | None = None) -> Costmap:
    """A free square map centred on the origin, optionally with a wall along y = wall_at_y."""
    cells = round(size_m / 0.05)
    data = np.zeros((cells, cells), dtype=np.int8)
    origin = Pose2D(-size_m / 2, -size_m / 2)
    grid = OccupancyGrid(data, 0.05, origin)
    if wall_at_y is not None:
        row, _ = grid.world_to_cell(0.0, wall_at_y)
        data[row, :] = 100
    return Costmap.from_grid(grid)


def line(start: tuple[float, float], end: tuple[float, float], step: float = 0.05) -> np.ndarray:
    count = max(2, round(math.dist(start, end) / step) + 1)
    return np.linspace(start, end, count)


def drive(
    controller: RegulatedPurePursuit, robot: DiffDriveRobot, seconds: float = 60.0
) -> list[tuple[float, float]]:
    """Run controller + robot until the goal is reached; the commands given."""
    commands = []
    for _ in range(round(seconds / DT)):
        cmd = controller.compute(robot.pose, robot.v, robot.w)
        if controller.goal_reached:
            return commands
        commands.append(cmd)
        robot.step(*cmd, DT)
    raise AssertionError(f"goal not reached in {seconds} s; robot at {robot.pose}")


def settle(robot: DiffDriveRobot) -> None:
    """Let the robot come to rest after the last command (it keeps its momentum)."""
    for _ in range(40):
        robot.step(0.0, 0.0, DT)


@pytest.mark.parametrize(
    ("start", "goal"),
    [
        (Pose2D(0.0, 0.0, 0.0), Pose2D(2.0, 0.0, 0.0)),
        (Pose2D(0.0, 0.0, 0.0), Pose2D(2.0, 0.0, math.pi / 2)),
        (Pose2D(-1.0, -1.0, 0.5), Pose2D(1.5, 1.0, -2.5)),
        (Pose2D(1.0, 0.0, math.pi), Pose2D(0.2, 0.3, 3.1)),
    ],
)
def test_reaches_goal_within_default_tolerances(start: Pose2D, goal: Pose2D) -> None:
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap())
    controller.set_path(line((start.x, start.y), (goal.x, goal.y)), goal)
    robot = DiffDriveRobot(start)
    drive(controller, robot)
    settle(robot)
    assert robot.pose.distance_to(goal) <= 0.05
    assert abs(normalize_angle(robot.pose.yaw - goal.yaw)) <= 0.17


def test_straight_run_takes_little_more_than_distance_over_top_speed() -> None:
    goal = Pose2D(2.0, 0.0, 0.0)
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap())
    controller.set_path(line((0.0, 0.0), (2.0, 0.0)), goal)
    commands = drive(controller, DiffDriveRobot(Pose2D(0.0, 0.0, 0.0)))
    duration = len(commands) * DT
    # It may stop braking up to the xy tolerance short of the goal.
    assert (2.0 - 0.05) / 0.22 <= duration <= 1.05 * 2.0 / 0.22


def test_turns_in_place_toward_a_path_behind_before_driving() -> None:
    goal = Pose2D(-1.5, 0.0, math.pi)
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap())
    controller.set_path(line((0.0, 0.0), (-1.5, 0.0)), goal)
    robot = DiffDriveRobot(Pose2D(0.0, 0.0, 0.0))
    commands = drive(controller, robot)
    first_forward = next(i for i, (v, _) in enumerate(commands) if v > 0)
    assert first_forward > 10  # a half turn takes a while
    assert all(v == 0.0 for v, _ in commands[:first_forward])
    # By the time it drives, it faces the path within the "done turning" angle.
    replay = DiffDriveRobot(Pose2D(0.0, 0.0, 0.0))
    for cmd in commands[:first_forward]:
        replay.step(*cmd, DT)
    assert abs(normalize_angle(replay.pose.yaw - math.pi)) < 0.6
    assert math.hypot(replay.pose.x, replay.pose.y) < 1e-9


def test_custom_tolerances_are_honoured() -> None:
    params = ControllerParams(xy_tolerance=0.3, yaw_tolerance=0.5)
    goal = Pose2D(2.0, 0.0, 1.0)
    controller = RegulatedPurePursuit(params, open_costmap())
    controller.set_path(line((0.0, 0.0), (2.0, 0.0)), goal)
    robot = DiffDriveRobot(Pose2D(0.0, 0.0, 0.0))
    drive(controller, robot)
    settle(robot)
    distance = robot.pose.distance_to(goal)
    assert 0.15 < distance <= 0.3  # stopped early, as allowed
    assert 0.1 < abs(normalize_angle(robot.pose.yaw - goal.yaw)) <= 0.5


def speed_at(controller: RegulatedPurePursuit, pose: Pose2D) -> float:
    v, _ = controller.compute(pose, 0.22, 0.0)
    return v


def test_slows_down_close_to_an_obstacle() -> None:
    goal = Pose2D(2.5, 0.0, 0.0)
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap(wall_at_y=0.15))
    controller.set_path(line((-2.5, 0.0), (2.5, 0.0)), goal)
    near_wall = speed_at(controller, Pose2D(-2.0, 0.0, 0.0))  # 0.15 m from the wall
    controller.set_path(line((-2.5, -1.5), (2.5, -1.5)), Pose2D(2.5, -1.5, 0.0))
    in_the_open = speed_at(controller, Pose2D(-2.0, -1.5, 0.0))
    assert in_the_open == pytest.approx(0.22)
    assert near_wall < 0.8 * in_the_open


def test_slows_down_on_tight_curves() -> None:
    """On an arc of radius 0.25 m (below the 0.3 m regulation radius) speed scales by 0.25/0.3."""
    radius = 0.25
    angles = np.linspace(-math.pi / 2, math.pi, 60)  # three quarters of a circle, leftward
    arc = np.column_stack((radius * np.cos(angles), radius + radius * np.sin(angles)))
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap())
    controller.set_path(arc, Pose2D(float(arc[-1, 0]), float(arc[-1, 1]), -math.pi / 2))
    v, w = controller.compute(Pose2D(0.0, 0.0, 0.0), 0.22, 0.0)
    assert v == pytest.approx(0.22 * radius / 0.3, rel=0.05)
    assert w == pytest.approx(v / radius, rel=0.05)  # and it steers along the arc


def test_brakes_before_the_goal() -> None:
    goal = Pose2D(2.0, 0.0, 0.0)
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap())
    path = line((0.0, 0.0), (2.0, 0.0))
    speeds = []
    for x in (1.0, 1.9, 1.96, 1.99):
        controller.set_path(path, goal)
        speeds.append(speed_at(controller, Pose2D(x, 0.0, 0.0)))
    assert speeds[0] == pytest.approx(0.22)
    assert speeds[0] >= speeds[1] > speeds[2]
    assert speeds[3] == 0.0  # within tolerance once stopped: position is done


def test_progress_along_the_path_is_reported() -> None:
    goal = Pose2D(2.0, 0.0, 0.0)
    controller = RegulatedPurePursuit(ControllerParams(), open_costmap())
    controller.set_path(line((0.0, 0.0), (2.0, 0.0)), goal)
    controller.compute(Pose2D(0.0, 0.1, 0.0), 0.0, 0.0)
    assert controller.distance_to_path == pytest.approx(0.1)
    assert controller.distance_remaining == pytest.approx(2.1, abs=0.01)
    for x in np.arange(0.0, 1.01, 0.01):  # the controller tracks progress incrementally
        controller.compute(Pose2D(float(x), 0.0, 0.0), 0.2, 0.0)
    assert controller.distance_remaining == pytest.approx(1.0, abs=0.03)
    assert controller.distance_to_path < 0.03
