"""SimWorld: the robot never collides, on the TurtleBot3 arena and on generated maps."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D, normalize_angle
from navseq.sim.costmap import Costmap, CostmapParams
from navseq.sim.footprint import TURTLEBOT3_BURGER, footprint_collides
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.world import SimWorld, default_start

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
GOAL_TIME_LIMIT = 300.0  # s of simulated time; a goal still active then is a hang


@pytest.fixture(scope="module")
def arena() -> OccupancyGrid:
    return load_map(MAP)


def test_start_in_an_obstacle_is_a_user_error(arena: OccupancyGrid) -> None:
    with pytest.raises(NavseqError, match="overlap an obstacle") as raised:
        SimWorld(arena, Pose2D(0.0, 0.0))  # the centre pillar
    assert raised.value.subject == "start"
    assert "turtlebot3_world.yaml" in str(raised.value)


def test_idle_world_keeps_time_and_the_robot_still(arena: OccupancyGrid) -> None:
    world = SimWorld(arena, Pose2D(-2.0, -0.5, 0.3), dt=0.05)
    for _ in range(1000):
        world.step()
    assert world.time == 50.0  # exact: the clock counts steps
    assert world.robot.pose == Pose2D(-2.0, -0.5, 0.3)


def test_the_body_refuses_to_drive_into_a_wall(arena: OccupancyGrid) -> None:
    """Even with a server gone mad (full speed at the west wall), the robot stops short."""
    world = SimWorld(arena, Pose2D(-2.0, -0.5, math.pi))
    world.server.compute_velocity = lambda pose, v, w, dt: (0.22, 0.0)  # type: ignore[method-assign]
    for _ in range(200):
        world.step()
        assert not footprint_collides(arena, TURTLEBOT3_BURGER, world.robot.pose)
    assert world.collisions > 0
    assert world.robot.pose.x < -2.1  # it did get close


def test_teleport_checks_the_pose_and_replans(arena: OccupancyGrid) -> None:
    world = SimWorld(arena, Pose2D(-2.0, -0.5, 0.0))
    with pytest.raises(NavseqError):
        world.teleport(Pose2D(1.1, 1.1))  # a pillar
    goal = Pose2D(1.6, -0.5, 0.0)
    world.server.set_goal(goal)
    world.run(2.0)
    world.teleport(Pose2D(0.5, 1.6, 0.0))
    world.run(60.0)
    assert world.server.state is NavState.SUCCEEDED
    assert world.robot.pose.distance_to(goal) <= 0.05
    assert world.server.plan is not None and world.server.plan.points[0][1] > 1.0


def test_default_start_is_roomy_and_free(arena: OccupancyGrid) -> None:
    start = default_start(arena)
    assert -2.2 < start.x < 2.2 and -2.2 < start.y < 2.2  # inside the arena
    world = SimWorld(arena, start)  # does not raise
    for yaw in np.linspace(-math.pi, math.pi, 16, endpoint=False):
        assert not footprint_collides(arena, TURTLEBOT3_BURGER, Pose2D(start.x, start.y, yaw))
    assert world.costmap.is_free(start.x, start.y)


def generated_map(seed: int) -> OccupancyGrid:
    """A walled 5 x 5 m room with random boxes and round pillars, some unknown patches."""
    rng = np.random.default_rng(seed)
    cells = 100
    data = np.zeros((cells, cells), dtype=np.int8)
    data[:2, :] = data[-2:, :] = data[:, :2] = data[:, -2:] = 100
    rows, cols = np.mgrid[0:cells, 0:cells]
    for _ in range(rng.integers(4, 9)):
        r, c = rng.integers(10, cells - 10, size=2)
        if rng.random() < 0.5:
            radius = rng.integers(2, 8)
            data[(rows - r) ** 2 + (cols - c) ** 2 <= radius**2] = 100
        else:
            h, w = rng.integers(2, 20, size=2)
            data[r : r + h, c : c + w] = 100 if rng.random() < 0.8 else -1
    return OccupancyGrid(data, 0.05, Pose2D(-2.5, -2.5), source=f"<generated map {seed}>")


def random_free_pose(world: SimWorld, rng: np.random.Generator) -> Pose2D:
    """A pose the planner accepts and the footprint fits at (not necessarily reachable)."""
    xmin, ymin, xmax, ymax = world.grid.bounds
    while True:
        pose = Pose2D(
            float(rng.uniform(xmin, xmax)),
            float(rng.uniform(ymin, ymax)),
            float(rng.uniform(-math.pi, math.pi)),
        )
        if world.costmap.is_free(pose.x, pose.y) and not footprint_collides(
            world.grid, world.footprint, pose
        ):
            return pose


def drive_random_goals(world: SimWorld, goals: int, seed: int) -> Counter[NavState]:
    """Send reachable random goals one after the other; check the footprint on every step."""
    rng = np.random.default_rng(seed)
    outcomes: Counter[NavState] = Counter()
    server, robot = world.server, world.robot
    for _ in range(goals):
        goal = random_free_pose(world, rng)
        while server.make_plan(robot.pose, goal) is None:
            goal = random_free_pose(world, rng)
        server.set_goal(goal)
        deadline = world.time + GOAL_TIME_LIMIT
        while server.state is NavState.ACTIVE:
            assert world.time < deadline, f"goal {goal} hangs"
            world.step()
            assert not footprint_collides(world.grid, world.footprint, robot.pose)
        world.run(1.0)  # come to rest; still checked below
        assert not footprint_collides(world.grid, world.footprint, robot.pose)
        outcomes[server.state] += 1
        if server.state is NavState.SUCCEEDED:
            assert robot.pose.distance_to(goal) <= server.params.xy_tolerance
            yaw_error = normalize_angle(robot.pose.yaw - goal.yaw)
            assert abs(yaw_error) <= server.params.yaw_tolerance
        else:
            assert server.state is NavState.ABORTED
            assert server.status_text.startswith("stopped:")  # reachable: only when blocked
    assert world.collisions == 0
    return outcomes


def test_no_collision_on_random_goals_in_the_arena(arena: OccupancyGrid) -> None:
    world = SimWorld(arena, Pose2D(-2.0, -0.5, 0.0))
    outcomes = drive_random_goals(world, goals=150, seed=1)
    assert outcomes[NavState.SUCCEEDED] >= 0.9 * 150


@pytest.mark.parametrize("seed", range(6))
def test_no_collision_on_random_goals_on_generated_maps(seed: int) -> None:
    grid = generated_map(seed)
    world = SimWorld(grid, default_start(grid))
    outcomes = drive_random_goals(world, goals=25, seed=100 + seed)
    assert outcomes[NavState.SUCCEEDED] >= 0.85 * 25


def test_a_prebuilt_costmap_is_the_one_the_server_plans_on(arena: OccupancyGrid) -> None:
    # Not the default parameters, so the world cannot have built an equal one itself.
    costmap = Costmap.from_grid(arena, CostmapParams(inflation_radius=1.5))
    world = SimWorld(arena, Pose2D(-2.0, -0.5, 0.0), costmap=costmap)
    assert world.costmap is costmap and world.server.costmap is costmap
    world.server.set_goal(Pose2D(1.6, -0.5, 0.0))
    world.run(GOAL_TIME_LIMIT)
    assert world.server.state is NavState.SUCCEEDED and world.collisions == 0


def test_a_costmap_of_another_grid_is_refused(arena: OccupancyGrid) -> None:
    other = load_map(MAP)  # same file, another grid object: not what the body moves on
    with pytest.raises(ValueError, match="another grid"):
        SimWorld(arena, Pose2D(-2.0, -0.5, 0.0), costmap=Costmap.from_grid(other))
    with pytest.raises(ValueError, match="costmap_params"):
        SimWorld(
            arena,
            Pose2D(-2.0, -0.5, 0.0),
            costmap=Costmap.from_grid(arena),
            costmap_params=CostmapParams(inflation_radius=0.5),
        )
