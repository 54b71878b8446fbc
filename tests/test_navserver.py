"""The move_base stand-in: plans, follows, replans, succeeds, aborts, cancels — never hangs."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from navseq.geometry import Pose2D, normalize_angle
from navseq.sim.costmap import Costmap, CostmapParams
from navseq.sim.footprint import TURTLEBOT3_BURGER, footprint_collides
from navseq.sim.navserver import (
    PLAN_FAILED,
    RECOVERY_BEHAVIOURS,
    NavigationServer,
    NavParams,
    NavState,
)
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.robot import DiffDriveRobot

DT = 0.05
MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"


@pytest.fixture(scope="module")
def arena() -> Costmap:
    return Costmap.from_grid(load_map(MAP))


def boxed_grid(size_m: float = 4.0) -> OccupancyGrid:
    """A free square room centred on the origin with one-cell walls all round."""
    cells = round(size_m / 0.05)
    data = np.zeros((cells, cells), dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    return OccupancyGrid(data, 0.05, Pose2D(-size_m / 2, -size_m / 2))


def run(server: NavigationServer, robot: DiffDriveRobot, seconds: float = 120.0) -> list[Pose2D]:
    """Drive until the goal is no longer ACTIVE; the poses visited. Fails if it never ends."""
    poses = [robot.pose]
    for _ in range(round(seconds / DT)):
        cmd = server.compute_velocity(robot.pose, robot.v, robot.w, DT)
        if server.state is not NavState.ACTIVE:
            assert cmd == (0.0, 0.0)
            return poses
        poses.append(robot.step(*cmd, DT))
    raise AssertionError(f"goal still active after {seconds} s at {robot.pose}")


def test_reaches_a_goal_across_the_arena(arena: Costmap) -> None:
    server = NavigationServer(arena)
    robot = DiffDriveRobot(Pose2D(-2.0, -0.5, 0.0))
    goal = Pose2D(1.6, 0.5, math.pi / 2)
    server.set_goal(goal)
    poses = run(server, robot)
    assert server.state is NavState.SUCCEEDED
    assert robot.pose.distance_to(goal) <= 0.05
    assert abs(normalize_angle(robot.pose.yaw - goal.yaw)) <= 0.17
    assert not any(footprint_collides(arena.grid, TURTLEBOT3_BURGER, p) for p in poses)
    assert server.plan is not None and server.plan_version == 1
    # Driven about as far as planned: pure pursuit cuts the plan's grid corners a little.
    driven = sum(a.distance_to(b) for a, b in itertools.pairwise(poses))
    assert 0.9 * server.plan.length < driven < 1.02 * server.plan.length


def test_plan_starts_at_the_robot_and_ends_exactly_at_the_goal(arena: Costmap) -> None:
    server = NavigationServer(arena)
    start, goal = Pose2D(-2.0, -0.49, 0.0), Pose2D(0.53, -1.61, 0.0)
    plan = server.make_plan(start, goal)
    assert plan is not None
    assert tuple(plan.points[0]) == (start.x, start.y)
    assert tuple(plan.points[-1]) == (goal.x, goal.y)
    assert plan.length == pytest.approx(np.hypot(*np.diff(plan.points, axis=0).T).sum())
    assert server.state is NavState.IDLE  # make_plan starts nothing


def test_distance_remaining_shrinks_along_the_way(arena: Costmap) -> None:
    server = NavigationServer(arena)
    robot = DiffDriveRobot(Pose2D(-2.0, -0.5, 0.0))
    server.set_goal(Pose2D(-0.5, -1.8, 0.0))
    remaining = []
    while server.state is NavState.ACTIVE:
        robot.step(*server.compute_velocity(robot.pose, robot.v, robot.w, DT), DT)
        remaining.append(server.distance_remaining)
    assert server.state is NavState.SUCCEEDED
    assert server.plan is not None
    assert remaining[0] == pytest.approx(server.plan.length, abs=0.05)
    assert remaining[-1] < 0.06
    assert remaining[len(remaining) // 2] < 0.75 * remaining[0]


@pytest.mark.parametrize(
    ("goal", "reason"),
    [
        (Pose2D(0.0, 0.0), "in an obstacle"),  # the centre pillar
        (Pose2D(1.1, 1.32), "in an obstacle"),  # next to a pillar, inside the inscribed band
        (Pose2D(50.0, 0.0), "outside the map"),
        (Pose2D(-3.0, 2.5), "in an obstacle"),  # unknown space outside the arena's walls
    ],
)
def test_goal_that_cannot_be_planned_to_aborts_at_once(
    arena: Costmap, goal: Pose2D, reason: str
) -> None:
    server = NavigationServer(arena)
    server.set_goal(goal)
    assert server.compute_velocity(Pose2D(-2.0, -0.5, 0.0), 0.0, 0.0, DT) == (0.0, 0.0)
    assert server.state is NavState.ABORTED
    assert reason in server.status_text
    assert server.make_plan(Pose2D(-2.0, -0.5, 0.0), goal) is None


def test_unreachable_goal_aborts_at_once() -> None:
    grid = boxed_grid()
    grid.data[:, 40] = 100  # a wall splitting the room in two
    server = NavigationServer(Costmap.from_grid(grid))
    server.set_goal(Pose2D(1.0, 0.0))
    assert server.compute_velocity(Pose2D(-1.0, 0.0, 0.0), 0.0, 0.0, DT) == (0.0, 0.0)
    assert server.state is NavState.ABORTED
    assert "unreachable" in server.status_text
    assert server.recoveries_run == 0  # no move of the robot can open a way


def test_backs_out_of_a_dead_end_it_cannot_turn_in() -> None:
    """A burger 0.3 m deep in a 0.25 m wide dead end, facing its end: it can drive but
    not turn there, and no cell near it is one to plan from. Like move_base's recovery
    behaviours, the server backs up, plans, and gets out."""
    grid = boxed_grid()  # cell (row, col) spans x in [-2 + col / 20, ...), y likewise
    grid.data[36, 60:] = 100  # a niche from x = 1.0 m to the east wall, y in [-0.15, 0.1)
    grid.data[42, 60:] = 100
    costmap = Costmap.from_grid(grid)
    start = Pose2D(1.3, -0.025, 0.0)
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, start)
    assert not costmap.is_free(start.x, start.y)
    server = NavigationServer(costmap)
    robot = DiffDriveRobot(start)
    goal = Pose2D(-1.0, 0.0, math.pi)
    server.set_goal(goal)
    poses = run(server, robot)
    assert server.state is NavState.SUCCEEDED, server.status_text
    assert server.recoveries_run >= 1
    assert not any(footprint_collides(grid, TURTLEBOT3_BURGER, p) for p in poses)


def test_boxed_in_robot_gives_up_after_the_recovery_behaviours() -> None:
    """Shut in a box it fits in but cannot turn in: the server tries clearing the
    costmap, turning (not possible) and backing up, then aborts with move_base's text."""
    grid = boxed_grid()
    grid.data[36, 40:49] = grid.data[42, 40:49] = 100  # y in [-0.15, 0.1)
    grid.data[36:43, 40] = grid.data[36:43, 48] = 100  # x in [0.05, 0.4)
    start = Pose2D(0.225, -0.025, 0.0)
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, start)
    server = NavigationServer(Costmap.from_grid(grid))
    robot = DiffDriveRobot(start)
    server.set_goal(Pose2D(-1.0, -1.0, 0.0))
    poses = run(server, robot, seconds=60.0)
    assert server.state is NavState.ABORTED
    assert server.status_text.startswith(PLAN_FAILED)
    assert server.recoveries_run == len(RECOVERY_BEHAVIOURS)
    assert not any(footprint_collides(grid, TURTLEBOT3_BURGER, p) for p in poses)


def test_never_turns_its_corners_into_a_wall() -> None:
    """Facing along a wall 12 cm away, a half turn in place would swing the rear corners
    into it. The server tries the long way round, creeping along the wall and its
    recovery behaviours, and gets away from the wall without touching it."""
    grid = boxed_grid()
    wall_row, _ = grid.world_to_cell(0.0, 0.2)
    grid.data[wall_row, :] = 100  # wall cells span y in [0.2, 0.25)
    costmap = Costmap.from_grid(grid)
    robot = DiffDriveRobot(Pose2D(0.0, 0.08, 0.0))
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, robot.pose)
    server = NavigationServer(costmap)
    goal = Pose2D(-1.5, -0.5, math.pi)
    server.set_goal(goal)
    poses = run(server, robot)
    assert server.state is NavState.SUCCEEDED, server.status_text
    assert robot.pose.distance_to(goal) <= 0.05
    # Every pose it passed through, and where it comes to rest, are collision free.
    for _ in range(40):
        poses.append(robot.step(0.0, 0.0, DT))
    assert not any(footprint_collides(grid, TURTLEBOT3_BURGER, p) for p in poses)


def test_cancel_stops_the_robot() -> None:
    server = NavigationServer(Costmap.from_grid(boxed_grid()))
    robot = DiffDriveRobot(Pose2D(-1.5, 0.0, 0.0))
    server.set_goal(Pose2D(1.5, 0.0))
    for _ in range(40):
        robot.step(*server.compute_velocity(robot.pose, robot.v, robot.w, DT), DT)
    assert robot.v > 0.2
    server.cancel()
    assert server.state is NavState.CANCELED
    assert server.compute_velocity(robot.pose, robot.v, robot.w, DT) == (0.0, 0.0)
    server.cancel()  # twice is harmless
    assert server.state is NavState.CANCELED


def test_new_goal_replaces_the_active_one() -> None:
    server = NavigationServer(Costmap.from_grid(boxed_grid()))
    robot = DiffDriveRobot(Pose2D(-1.5, 0.0, 0.0))
    server.set_goal(Pose2D(1.5, 0.0))
    for _ in range(40):
        robot.step(*server.compute_velocity(robot.pose, robot.v, robot.w, DT), DT)
    second = Pose2D(-1.0, 1.0, math.pi)
    server.set_goal(second)
    run(server, robot)
    assert server.state is NavState.SUCCEEDED
    assert robot.pose.distance_to(second) <= 0.05
    assert server.plan_version == 2


def test_replans_when_the_robot_is_pushed_off_the_plan() -> None:
    server = NavigationServer(Costmap.from_grid(boxed_grid()))
    robot = DiffDriveRobot(Pose2D(-1.5, 0.0, 0.0))
    goal = Pose2D(1.5, 0.0)
    server.set_goal(goal)
    for _ in range(20):
        robot.step(*server.compute_velocity(robot.pose, robot.v, robot.w, DT), DT)
    assert server.plan_version == 1
    robot.teleport(Pose2D(robot.pose.x, -1.0, 0.0))  # kidnapped 1 m sideways
    run(server, robot)
    assert server.plan_version >= 2
    assert server.plan is not None and server.plan.points[0][1] < -0.5
    assert server.state is NavState.SUCCEEDED
    assert robot.pose.distance_to(goal) <= 0.05


def test_periodic_replanning_when_asked() -> None:
    server = NavigationServer(Costmap.from_grid(boxed_grid()), NavParams(replan_period=1.0))
    robot = DiffDriveRobot(Pose2D(-1.5, 0.0, 0.0))
    server.set_goal(Pose2D(1.5, 0.0))
    run(server, robot)
    assert server.state is NavState.SUCCEEDED
    assert server.plan_version >= 12  # about 14 s of driving


def test_clear_costmaps_replans_and_goes_on(arena: Costmap) -> None:
    server = NavigationServer(arena)
    robot = DiffDriveRobot(Pose2D(-2.0, -0.5, 0.0))
    server.set_goal(Pose2D(-0.5, -1.8, 0.0))
    for _ in range(40):
        robot.step(*server.compute_velocity(robot.pose, robot.v, robot.w, DT), DT)
    server.clear_costmaps()
    run(server, robot)
    assert server.state is NavState.SUCCEEDED
    assert server.plan_version == 2


def test_starts_from_a_pose_too_close_to_a_wall_for_the_planner() -> None:
    """Like move_base, a robot that stopped within the inscribed band can still leave.

    A cautious costmap (inscribed radius 0.2 m) forbids the robot centre 0.18 m from a
    wall although the robot itself fits there and can turn.
    """
    grid = boxed_grid()
    costmap = Costmap.from_grid(grid, CostmapParams(inscribed_radius=0.2))
    start = Pose2D(-1.8, 0.0, math.pi)
    assert not costmap.is_free(start.x, start.y)
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, start)
    server = NavigationServer(costmap)
    robot = DiffDriveRobot(start)
    goal = Pose2D(0.5, 0.5)
    server.set_goal(goal)
    run(server, robot)
    assert server.state is NavState.SUCCEEDED
    assert robot.pose.distance_to(goal) <= 0.05
