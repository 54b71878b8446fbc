"""Nav2 keepout and speed masks: pre-flight, the simulator's planner and speed, the ETA
and the picture follow them."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from cli_support import EXAMPLES, REPO, TURTLEBOT3_MAP, assert_clean_error, navseq
from navseq.errors import NavseqError
from navseq.eta.predict import predict_on_map
from navseq.executor.result import MissionResult
from navseq.geometry import Pose2D
from navseq.mission.costmap_filters import CostmapFilter, FilterType
from navseq.mission.loader import load_mission
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.navigators.sim import prepare_sim_world
from navseq.preflight import MisplacedError, check_mission
from navseq.sim.costmap import Costmap
from navseq.sim.filters import with_filters
from navseq.sim.navserver import NavState
from navseq.sim.occupancy import load_map
from navseq.sim.planner import plan_path
from navseq.sinks.picture.draw import mission_figure

KEEPOUT = REPO / "maps" / "turtlebot3_world_keepout.yaml"
SPEED = REPO / "maps" / "turtlebot3_world_speed.yaml"
# The example keepout zone: x 0.15 .. 0.95, y below -1.35 (the south corridor).
IN_KEEPOUT = (0.55, -1.75)
SOUTH_WEST, SOUTH_EAST = (-0.55, -1.75), (1.6, -1.75)
# The example speed zone: |x|, |y| <= 0.75, 40 % of top speed.
ZONE_HALF_WIDTH = 0.75


@pytest.fixture(scope="module")
def plain_map():
    return load_map(TURTLEBOT3_MAP)


@pytest.fixture(scope="module")
def keepout_map(plain_map):
    return with_filters(plain_map, [CostmapFilter.keepout(KEEPOUT)])


@pytest.fixture(scope="module")
def speed_map(plain_map):
    return with_filters(plain_map, [CostmapFilter.tutorial_speed(SPEED)])


def in_keepout_zone(x: float, y: float) -> bool:
    return 0.15 <= x <= 0.95 and y <= -1.35


def test_a_waypoint_in_a_keepout_zone_is_a_problem_with_the_nearest_allowed_spot(
    keepout_map,
) -> None:
    mission = Mission(
        waypoints=(Waypoint(*IN_KEEPOUT, where="m.yaml:7"), Waypoint(*SOUTH_WEST)),
        start=Pose2D(-2.0, -0.5, 0.0),
        source="m.yaml",
    )
    (problem,) = check_mission(mission, Costmap.from_grid(keepout_map))
    assert isinstance(problem, MisplacedError)
    assert str(problem).startswith("m.yaml:7, waypoint 1: at (0.55, -1.75) is in a keepout zone")
    assert problem.suggested is not None
    x, y = problem.suggested
    assert not in_keepout_zone(x, y)
    assert math.hypot(x - IN_KEEPOUT[0], y - IN_KEEPOUT[1]) < 1.0
    # Without the mask the same waypoint is fine.
    assert check_mission(mission, Costmap.from_grid(load_map(TURTLEBOT3_MAP))) == []


def test_the_planner_never_plans_through_a_keepout_zone(plain_map, keepout_map) -> None:
    direct = plan_path(Costmap.from_grid(plain_map), SOUTH_WEST, SOUTH_EAST)
    around = plan_path(Costmap.from_grid(keepout_map), SOUTH_WEST, SOUTH_EAST)
    assert direct is not None and around is not None
    assert any(in_keepout_zone(x, y) for x, y in direct.points)  # the short way crosses it
    assert not any(in_keepout_zone(x, y) for x, y in around.points)
    assert around.length > direct.length + 0.5


def drive(grid, start: Pose2D, goal: Pose2D) -> tuple[list[tuple[float, float, float]], float]:
    """The simulated robot driving to ``goal``: (x, y, speed) each step, and the time."""
    mission = Mission(waypoints=(Waypoint(goal.x, goal.y),))
    world = prepare_sim_world(mission, grid, start, DEFAULT_PROFILE).world
    world.server.set_goal(goal)
    samples = []
    for _ in range(4000):  # 200 s of simulated time at most
        world.step()
        samples.append((world.robot.pose.x, world.robot.pose.y, world.robot.v))
        if world.server.state is not NavState.ACTIVE:
            break
    assert world.server.state is NavState.SUCCEEDED, world.server.status_text
    return samples, world.time


def test_the_simulated_robot_drives_round_a_keepout_zone(keepout_map) -> None:
    samples, _ = drive(keepout_map, Pose2D(*SOUTH_WEST, 0.0), Pose2D(*SOUTH_EAST, 0.0))
    assert not any(in_keepout_zone(x, y) for x, y, _ in samples)


def test_a_speed_zone_slows_the_simulated_robot_and_its_eta(plain_map, speed_map) -> None:
    start, goal = Pose2D(-1.6, 0.55, 0.0), Pose2D(1.6, 0.55, 0.0)  # across the zone
    free, free_time = drive(plain_map, start, goal)
    slowed, slow_time = drive(speed_map, start, goal)
    top = DEFAULT_PROFILE.max_linear_speed

    def fastest_in_zone(samples) -> float:
        inside = [v for x, y, v in samples if abs(x) < ZONE_HALF_WIDTH - 0.05 and abs(y) < 0.7]
        assert inside
        return max(inside)

    assert fastest_in_zone(free) > 0.9 * top
    assert fastest_in_zone(slowed) <= 0.4 * top + 1e-6
    assert slow_time > free_time + 3.0
    mission = Mission(waypoints=(Waypoint(goal.x, goal.y),))
    free_eta = predict_on_map(mission, plain_map, DEFAULT_PROFILE, start).expected_s
    slow_eta = predict_on_map(mission, speed_map, DEFAULT_PROFILE, start).expected_s
    assert free_eta is not None and slow_eta is not None
    assert slow_eta - free_eta == pytest.approx(slow_time - free_time, rel=0.35)


def test_speed_limits_follow_nav2s_speed_filter(plain_map) -> None:
    absolute = CostmapFilter(SPEED, FilterType.SPEED_ABSOLUTE, base=0.0, multiplier=0.001)
    grid = with_filters(plain_map, [absolute])  # v = 60: 0.06 m/s
    assert grid.filters is not None
    assert grid.filters.speed_cap(grid, 0.0, 0.55, 0.22) == pytest.approx(0.06)
    assert grid.filters.speed_cap(grid, 1.6, 0.55, 0.22) == 0.22  # value 0: no limit


def test_the_picture_draws_the_zones(keepout_map) -> None:
    grid = with_filters(keepout_map, [CostmapFilter.tutorial_speed(SPEED)])
    mission = Mission(waypoints=(Waypoint(*SOUTH_WEST), Waypoint(*SOUTH_EAST), Waypoint(0, 1)))
    figure = mission_figure(mission, MissionResult(True, "done"), grid=grid)
    gids = {artist.get_gid() for artist in figure.axes[0].get_children()}
    assert {"keepout-zones", "speed-zones"} <= gids
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    pixels = np.asarray(Image.open(buffer).convert("RGB")).astype(int)
    reddish = (pixels[..., 0] > pixels[..., 1] + 40) & (pixels[..., 0] > pixels[..., 2] + 40)
    assert reddish.sum() > 200  # the hatched keepout zone shows


def test_the_keepout_example_runs_and_validate_names_the_zone(tmp_path: Path) -> None:
    result = navseq("run", EXAMPLES / "keepout.yaml", "--out", tmp_path / "run", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        f"navseq: 1\nmap: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n"
        "waypoints:\n  - {x: 0.55, y: -1.75}\n"
    )
    assert navseq("validate", bad, cwd=tmp_path).returncode == 0
    refused = navseq("validate", bad, "--keepout", KEEPOUT, cwd=tmp_path)
    assert refused.returncode == 2
    assert f"{bad}:5, waypoint 1: at (0.55, -1.75) is in a keepout zone" in refused.stderr


def test_a_bad_filter_is_refused_with_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(
        f"navseq: 1\nmap: {TURTLEBOT3_MAP}\nfilters:\n  - {{mask: {KEEPOUT}, type: 3}}\n"
        "waypoints:\n  - {x: 0.5, y: 0.5}\n"
    )
    with pytest.raises(NavseqError, match=r"m.yaml:4, field filters, item 1, field type: type is"):
        load_mission(path)
    assert_clean_error(navseq("validate", path, cwd=tmp_path))
    missing = navseq("validate", EXAMPLES / "patrol.yaml", "--keepout", "nope.yaml", cwd=tmp_path)
    assert_clean_error(missing)
    assert "--keepout: no such file: nope.yaml" in missing.stderr


def test_a_mask_that_cannot_be_read_is_named_where_the_mission_gives_it(tmp_path: Path) -> None:
    path = tmp_path / "m.yaml"
    path.write_text(
        f"navseq: 1\nmap: {TURTLEBOT3_MAP}\nfilters:\n  - {{mask: nope.yaml}}\n"
        "waypoints:\n  - {x: 0.5, y: 0.5}\n"
    )
    result = navseq("validate", path, cwd=tmp_path)
    assert_clean_error(result)
    assert f"{path}:4, filters: the mask cannot be read: {tmp_path / 'nope.yaml'}" in (
        result.stderr
    )
