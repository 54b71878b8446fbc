"""Robots other than the burger: profiles from the mission or --robot, and the real
footprint in planning, pre-flight and the simulator (never trapped in a narrow gap)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cli_support import assert_clean_error, navseq, write_mission
from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission import load_mission, validate_mission_file
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import (
    BUILTIN_PROFILES,
    TURTLEBOT3_BURGER,
    TURTLEBOT3_WAFFLE,
    RobotProfile,
    circle_footprint,
)
from navseq.mission.robot_format import robot_from_option
from navseq.preflight import check_mission
from navseq.sim.costmap import Costmap
from navseq.sim.mapgen import save_map
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.profile import SimSettings
from navseq.sim.world import SimWorld

RESOLUTION = 0.05
ARENA = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"


def wall_with_gaps(gaps: list[tuple[float, float]], *, width: float = 6.0) -> OccupancyGrid:
    """A walled 6 m x 3 m room split at x = 3 m by a wall with openings ``(y_low, y_high)``."""
    cells_x, cells_y = round(width / RESOLUTION), round(3.0 / RESOLUTION)
    data = np.zeros((cells_y, cells_x), np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    wall_col = round(3.0 / RESOLUTION)
    data[:, wall_col : wall_col + 2] = 100
    for low, high in gaps:
        data[round(low / RESOLUTION) : round(high / RESOLUTION), wall_col : wall_col + 2] = 0
    return OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0), "gaps.yaml")


def world_for(grid: OccupancyGrid, start: Pose2D, robot: RobotProfile) -> SimWorld:
    sim = SimSettings.of(robot)
    costmap = Costmap.from_grid(grid, sim.costmap_params)
    return SimWorld(
        grid, start, costmap=costmap, nav_params=sim.nav_params, footprint=sim.footprint
    )


def drive(world: SimWorld, goal: Pose2D, seconds: float = 180.0) -> None:
    world.server.set_goal(goal)
    for _ in range(round(seconds / world.dt)):
        world.step()
        if world.server.state is not NavState.ACTIVE:
            return
    raise AssertionError(f"goal still active after {seconds} s at {world.robot.pose}")


def mission_of(points: list[tuple[float, float]], start: Pose2D | None = None) -> Mission:
    waypoints = tuple(Waypoint(x, y, where=f"m.yaml:{10 + i}") for i, (x, y) in enumerate(points))
    return Mission(waypoints=waypoints, start=start, source="m.yaml")


# -- the planner, pre-flight and the simulator use the real footprint --------------------

NARROW = (0.85, 1.10)  # 0.25 m: wider than the burger (0.21 m) but not its turning circle


def test_a_gap_the_robot_cannot_turn_in_is_planned_around_and_never_traps_it() -> None:
    """The 0.25 m gap is the short way; the burger's corners reach 0.148 m, so a plan
    through it would leave the robot unable to turn (move_base on Nav2's maps got stuck
    for good). The plan takes the 1 m door, and the robot gets there."""
    grid = wall_with_gaps([NARROW, (2.0, 2.9)])
    start, goal = Pose2D(1.0, 0.975, 0.0), Pose2D(5.0, 0.975, 0.0)
    world = world_for(grid, start, TURTLEBOT3_BURGER)
    plan = world.server.make_plan(start, goal)
    assert plan is not None
    assert plan.points[:, 1].max() > 2.0  # by the door
    drive(world, goal)
    assert world.server.state is NavState.SUCCEEDED
    assert world.collisions == 0
    assert check_mission(mission_of([(goal.x, goal.y)], start), world.costmap) == []


def test_with_only_a_narrow_gap_preflight_says_unreachable_and_the_robot_is_not_stuck() -> None:
    grid = wall_with_gaps([NARROW])
    start, goal = Pose2D(1.0, 0.975, 0.0), Pose2D(5.0, 0.975, 0.0)
    world = world_for(grid, start, TURTLEBOT3_BURGER)
    (problem,) = check_mission(mission_of([(goal.x, goal.y)], start), world.costmap)
    assert "cannot be reached from the start pose" in str(problem)
    # Run anyway (--no-preflight): the server gives up after its recovery behaviours,
    # with the robot still free to go elsewhere.
    drive(world, goal)
    assert world.server.state is NavState.ABORTED
    assert "unreachable" in world.server.status_text
    assert world.robot.pose.x < 2.5
    home = Pose2D(1.0, 2.0, 0.0)
    drive(world, home)
    assert world.server.state is NavState.SUCCEEDED


def test_a_waffle_refuses_a_gap_the_burger_passes() -> None:
    grid = wall_with_gaps([(0.3, 0.75)])  # 0.45 m
    start, goal = Pose2D(1.0, 0.975, 0.0), Pose2D(5.0, 0.975, 0.0)
    mission = mission_of([(goal.x, goal.y)], start)
    burger = world_for(grid, start, TURTLEBOT3_BURGER)
    assert check_mission(mission, burger.costmap, robot=TURTLEBOT3_BURGER) == []
    drive(burger, goal)
    assert burger.server.state is NavState.SUCCEEDED
    waffle_costmap = Costmap.from_grid(grid, SimSettings.of(TURTLEBOT3_WAFFLE).costmap_params)
    (problem,) = check_mission(mission, waffle_costmap, robot=TURTLEBOT3_WAFFLE)
    assert "cannot be reached" in str(problem)


def test_a_waypoint_2_cm_from_an_open_map_edge_is_refused() -> None:
    data = np.zeros((60, 60), np.int8)  # no walls: the edge is where knowledge ends
    grid = OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0), "open.yaml")
    costmap = Costmap.from_grid(grid)
    (problem,) = check_mission(mission_of([(1.5, 2.98)]), costmap)
    assert "0.020 m from an obstacle, unknown space or the map edge" in str(problem)
    assert "circumscribed radius (0.148 m" in str(problem)
    assert check_mission(mission_of([(1.5, 1.5)]), costmap) == []


def test_the_suggested_spot_leaves_room_to_turn_and_the_simulator_reaches_it() -> None:
    grid = load_map(ARENA)
    costmap = Costmap.from_grid(grid)
    start = Pose2D(-2.0, -0.5, 0.0)
    (problem,) = check_mission(mission_of([(0.27, 0.0)], start), costmap)
    x, y = (float(v) for v in str(problem).split("spot is at ")[1].strip("()").split(","))
    assert costmap.clearance_at(x, y) >= TURTLEBOT3_BURGER.circumscribed_radius + 0.02
    assert check_mission(mission_of([(x, y)], start), costmap) == []
    world = world_for(grid, start, TURTLEBOT3_BURGER)
    drive(world, Pose2D(x, y, math.pi / 2))
    assert world.server.state is NavState.SUCCEEDED
    assert world.collisions == 0


def test_the_suggested_spot_is_reachable_from_the_previous_waypoint() -> None:
    """A waypoint hugging the inside of a walled pocket, coming from outside: the spot
    suggested is outside, where the robot can get, not deeper in the pocket."""
    data = np.zeros((80, 80), np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    data[30:51, 30] = data[30:51, 50] = data[30, 30:51] = data[50, 30:51] = 100
    costmap = Costmap.from_grid(OccupancyGrid(data, RESOLUTION, Pose2D(0, 0, 0), "p.yaml"))
    (problem,) = check_mission(mission_of([(0.5, 0.5), (1.6, 2.0)]), costmap)
    x, y = (float(v) for v in str(problem).split("spot is at ")[1].strip("()").split(","))
    assert check_mission(mission_of([(0.5, 0.5), (x, y)]), costmap) == []


# -- profiles from the mission file and --robot ---------------------------------------


def test_robot_by_name_and_by_mapping_with_overrides(tmp_path: Path) -> None:
    named = write_mission(tmp_path / "a.yaml", "  - [0, 0]\n", "robot: turtlebot3_waffle\n")
    assert load_mission(named).robot == TURTLEBOT3_WAFFLE
    custom = write_mission(
        tmp_path / "b.yaml",
        "  - [0, 0]\n",
        "robot:\n"
        "  base: turtlebot3_waffle\n"
        "  radius: 0.2\n"
        "  max_angular_speed: 90\n"
        "  max_linear_speed: 0.3\n"
        "  yaw_goal_tolerance: 10\n"
        "  xy_goal_tolerance: 0.1\n"
        "  inflation_radius: 0.5\n"
        "  clearance_margin: 0.05\n",
    )
    robot = load_mission(custom).robot
    assert robot is not None
    assert robot.circumscribed_radius == pytest.approx(0.2)
    assert robot.max_angular_speed == pytest.approx(math.pi / 2)  # deg/s in files
    assert robot.max_linear_speed == 0.3
    assert robot.max_linear_accel == TURTLEBOT3_WAFFLE.max_linear_accel  # from the base
    assert robot.goal_tolerance.yaw_rad == pytest.approx(math.radians(10))
    assert robot.goal_tolerance.xy_m == 0.1
    assert (robot.inflation_radius, robot.clearance_margin_m) == (0.5, 0.05)
    assert robot.source == f"{custom}:3"


def test_every_bad_robot_value_is_named_with_its_line(tmp_path: Path) -> None:
    path = write_mission(
        tmp_path / "m.yaml",
        "  - [0, 0]\n",
        "robot:\n"
        "  base: turtlebot3_wafle\n"
        "  footprint: [[0.1, 0.1], [0.2, 0.1]]\n"
        "  max_linear_speed: 0\n"
        "  inflaton_radius: 0.5\n",
    )
    text = [str(problem) for problem in validate_mission_file(path)]
    assert len(text) == 4, text
    assert any(
        f"{path}:3, robot, field base" in t and "did you mean 'turtlebot3_waffle'" in t
        for t in text
    )
    assert any(f"{path}:4, robot, field footprint" in t and "3 points" in t for t in text)
    assert any(f"{path}:5, robot, field max_linear_speed" in t and "> 0" in t for t in text)
    assert any(
        f"{path}:6, robot, field inflaton_radius" in t and "did you mean 'inflation_radius'" in t
        for t in text
    )


def test_unknown_robot_name_names_the_closest(tmp_path: Path) -> None:
    path = write_mission(tmp_path / "m.yaml", "  - [0, 0]\n", "robot: turtlebot3_burgr\n")
    (problem,) = validate_mission_file(path)
    assert f"{path}:2, field robot" in str(problem)
    assert "did you mean 'turtlebot3_burger'" in str(problem)
    with pytest.raises(NavseqError, match="did you mean 'turtlebot3_waffle_pi'"):
        robot_from_option("turtlebot3_waffle_py")


def test_a_footprint_must_enclose_the_robot_centre(tmp_path: Path) -> None:
    outline = "robot: {footprint: [[0.1, 0.1], [0.3, 0.1], [0.2, 0.3]]}\n"
    path = write_mission(tmp_path / "m.yaml", "  - [0, 0]\n", outline)
    (problem,) = validate_mission_file(path)
    assert "enclose the robot centre" in str(problem)


@settings(max_examples=30, deadline=None)
@given(st.floats(min_value=0.05, max_value=1.0))
def test_a_round_robot_has_the_radius_it_was_given(radius: float) -> None:
    robot = TURTLEBOT3_BURGER.with_changes(footprint=circle_footprint(radius))
    assert robot.circumscribed_radius == pytest.approx(radius)
    assert radius * math.cos(math.pi / 16) - 1e-9 <= robot.inscribed_radius <= radius
    assert SimSettings.of(robot).footprint.circumscribed_radius == pytest.approx(radius)


def test_builtin_profiles_are_named_as_their_keys() -> None:
    assert all(profile.name == name for name, profile in BUILTIN_PROFILES.items())


# -- the command line -----------------------------------------------------------------


@pytest.fixture
def gap_mission(tmp_path: Path) -> Path:
    """A mission through a 0.45 m gap: the burger passes, the waffle does not."""
    save_map(wall_with_gaps([(0.3, 0.75)]), tmp_path / "gap.yaml")
    return write_mission(
        tmp_path / "m.yaml",
        "  - {x: 5.0, y: 0.5}\n",
        "map: gap.yaml\nstart: {x: 1.0, y: 0.5, yaw: 0}\n",
    )


def test_validate_with_robot_option_and_precedence(gap_mission: Path, tmp_path: Path) -> None:
    assert navseq("validate", gap_mission, cwd=tmp_path).returncode == 0
    refused = navseq("validate", gap_mission, "--robot", "turtlebot3_waffle", cwd=tmp_path)
    assert_clean_error(refused)
    assert "cannot be reached from the start pose" in refused.stderr
    # The mission says waffle; --robot wins over it.
    text = gap_mission.read_text().replace("navseq: 1\n", "navseq: 1\nrobot: turtlebot3_waffle\n")
    gap_mission.write_text(text)
    assert_clean_error(navseq("validate", gap_mission, cwd=tmp_path))
    done = navseq("validate", gap_mission, "--robot", "turtlebot3_burger", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "for robot turtlebot3_burger" in done.stdout


def test_bad_robot_option_is_a_clean_error(gap_mission: Path, tmp_path: Path) -> None:
    for command in ("validate", "run"):
        result = navseq(command, gap_mission, "--robot", "turtlebot_waffle", cwd=tmp_path)
        assert_clean_error(result)
        assert "did you mean 'turtlebot3_waffle'" in result.stderr
    robot_file = tmp_path / "robot.yaml"
    robot_file.write_text("base: turtlebot3_burger\nradius: -0.2\n")
    result = navseq("validate", gap_mission, "--robot", robot_file, cwd=tmp_path)
    assert_clean_error(result)
    assert f"{robot_file}:2, robot, field radius" in result.stderr


def test_run_with_a_robot_file_reports_the_robot(gap_mission: Path, tmp_path: Path) -> None:
    robot_file = tmp_path / "robot.yaml"
    robot_file.write_text("name: small_round\nradius: 0.12\nmax_linear_speed: 0.3\n")
    out = tmp_path / "out"
    result = navseq("run", gap_mission, "--robot", robot_file, "--out", out, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["navigator"]["robot"] == "small_round"
