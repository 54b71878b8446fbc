"""Pre-flight: every unreachable waypoint is reported at once, before the robot moves."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import TURTLEBOT3_BURGER
from navseq.preflight import check_mission
from navseq.sim.costmap import Costmap
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.planner import plan_path

REPO_MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"

# Free floor between the TurtleBot3 arena's pillars (3 x 3 grid 1.1 m apart).
GOOD = [(-0.55, -0.55), (0.55, -0.55), (0.55, 0.55), (-0.55, 0.55), (-1.6, 0.0), (1.6, 0.0)]


@pytest.fixture(scope="module")
def arena() -> Costmap:
    return Costmap.from_grid(load_map(REPO_MAP))


@pytest.fixture(scope="module")
def pocket_map() -> Costmap:
    """4 m x 4 m room with a walled-in 1 m x 1 m pocket in the middle."""
    data = np.zeros((80, 80), np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    data[30:51, 30] = data[30:51, 50] = data[30, 30:51] = data[50, 30:51] = 100
    return Costmap.from_grid(OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0), "pocket.yaml"))


def mission_of(points, *, names=None, loops: int | None = 1, start=None) -> Mission:
    waypoints = tuple(
        Waypoint(
            x, y, yaw_rad=0.0, name=(names[i] if names else None), where=f"mission.yaml:{10 + i}"
        )
        for i, (x, y) in enumerate(points)
    )
    return Mission(waypoints=waypoints, loops=loops, start=start, source="mission.yaml")


def messages(problems: list[NavseqError]) -> list[str]:
    return [str(problem) for problem in problems]


def test_a_good_mission_has_no_problems(arena: Costmap) -> None:
    mission = mission_of(GOOD, loops=None, start=Pose2D(-2.0, -0.5, 0.0))
    assert check_mission(mission, arena) == []


def test_all_problems_are_reported_at_once(arena: Costmap) -> None:
    mission = mission_of(
        [GOOD[0], (0.2, 0.0), (50.0, 3.0), (0.27, 0.0), GOOD[2], (1.1, 1.1)],
        names=["a", "pillar wall", "far away", "hugging", "b", "pillar inside"],
    )
    problems = check_mission(mission, arena)
    assert [p.subject for p in problems] == [
        "waypoint 2 'pillar wall'",
        "waypoint 3 'far away'",
        "waypoint 4 'hugging'",
        "waypoint 6 'pillar inside'",
    ]
    text = messages(problems)
    assert "inside an obstacle" in text[0] and "(0.20, 0.00)" in text[0]
    assert "outside the map" in text[1] and "(50.00, 3.00)" in text[1]
    assert "circumscribed radius (0.148 m" in text[2] and "(0.27, 0.00)" in text[2]
    assert "unmapped space" in text[3]
    # Each names the line the user wrote the waypoint on.
    assert [p.source for p in problems] == [
        "mission.yaml:11",
        "mission.yaml:12",
        "mission.yaml:13",
        "mission.yaml:15",
    ]


def test_too_close_to_a_wall_suggests_a_free_spot(arena: Costmap) -> None:
    problems = check_mission(mission_of([(0.27, 0.0)]), arena)
    assert len(problems) == 1
    x, y = suggested_spot(problems[0])
    assert arena.is_free(x, y)
    assert arena.clearance_at(x, y) >= TURTLEBOT3_BURGER.circumscribed_radius + 0.02
    assert abs(x - 0.27) + abs(y) < 0.2


def suggested_spot(problem: NavseqError) -> tuple[float, float]:
    suggestion = str(problem).split("nearest free spot is at ")[1]
    x, y = (float(v) for v in suggestion.strip("()").split(","))
    return x, y


def test_outside_the_map_says_where_the_map_is(arena: Costmap) -> None:
    (problem,) = check_mission(mission_of([(-10.5, 0.0)]), arena)
    assert "x -10.00 .. 9.20" in str(problem)
    assert str(REPO_MAP) in str(problem)


def test_waypoint_without_location_uses_the_mission_source(arena: Costmap) -> None:
    mission = Mission(waypoints=(Waypoint(0.2, 0.0),), source="param ~p_seq")
    (problem,) = check_mission(mission, arena)
    assert problem.source == "param ~p_seq"
    assert problem.subject == "waypoint 1"


def test_start_pose_in_an_obstacle(arena: Costmap) -> None:
    mission = mission_of(GOOD[:2], start=Pose2D(0.2, 0.0, 0.0))
    (problem,) = check_mission(mission, arena)
    assert problem.subject == "start"
    assert problem.source == "mission.yaml"
    assert "inside an obstacle" in str(problem)
    # A start given by the caller (e.g. --start) overrides the mission's.
    assert check_mission(mission, arena, start=Pose2D(-2.0, -0.5, 0.0)) == []


def test_start_pose_off_the_map(arena: Costmap) -> None:
    problems = check_mission(mission_of(GOOD[:1]), arena, start=Pose2D(30.0, 0.0, 0.0))
    assert [p.subject for p in problems] == ["start"]
    assert "outside the map" in str(problems[0])


def test_pocket_unreachable_from_previous_waypoint(pocket_map: Costmap) -> None:
    inside, outside = (2.0, 2.0), (0.5, 0.5)
    mission = mission_of([outside, inside, (3.5, 3.5)], names=["door", "pocket", "corner"])
    problems = check_mission(mission, pocket_map)
    # The pocket is blamed once; the corner, reachable from the door, is not.
    assert [p.subject for p in problems] == ["waypoint 2 'pocket'"]
    assert "cannot be reached from waypoint 1 'door' at (0.50, 0.50)" in str(problems[0])
    # The planner agrees: there is no path in.
    assert plan_path(pocket_map, outside, inside) is None


def test_first_waypoint_unreachable_from_the_start(pocket_map: Costmap) -> None:
    mission = mission_of([(2.0, 2.0)])
    assert check_mission(mission, pocket_map) == []  # no start known: nothing to check
    (problem,) = check_mission(mission, pocket_map, start=Pose2D(0.5, 0.5, 0.0))
    assert problem.subject == "waypoint 1"
    assert "cannot be reached from the start pose" in str(problem)


def test_looping_mission_must_get_back_to_its_first_waypoint(pocket_map: Costmap) -> None:
    # Start inside the pocket: the single pass is fine only if the robot never has to
    # come back; it does when the mission loops.
    points = [(2.0, 2.0), (1.8, 2.2)]
    assert check_mission(mission_of(points, loops=3), pocket_map) == []
    points = [(0.5, 0.5), (3.5, 0.5)]
    assert check_mission(mission_of(points, loops=None), pocket_map) == []


def test_a_looping_mission_blames_an_unreachable_waypoint_once(pocket_map: Costmap) -> None:
    # Waypoint 2 is unreachable from 1; the loop back from it to 1 is the same fault.
    points = [(0.5, 0.5), (2.0, 2.0)]
    once = check_mission(mission_of(points, loops=1), pocket_map)
    looped = check_mission(mission_of(points, loops=2), pocket_map)
    assert [p.subject for p in once] == ["waypoint 2"]
    assert messages(looped) == messages(once)


def test_without_a_start_the_odd_one_out_is_blamed(pocket_map: Costmap) -> None:
    # The first waypoint is the isolated one: the three others are not blamed for it.
    mission = mission_of([(2.0, 2.0), (0.5, 0.5), (3.5, 0.5), (3.5, 3.5)], loops=None)
    (problem,) = check_mission(mission, pocket_map)
    assert problem.subject == "waypoint 1"
    assert "cut off from the mission's other waypoints" in str(problem)


def test_thirteen_isolated_points_are_thirteen_problems() -> None:
    """The issue's map: 13 walled-in pockets; a mission that visits each between
    points of the open floor gets one problem per pocket, and each leg after a pocket
    is checked from the last point the robot can reach."""
    size = 200  # 10 m at 0.05 m
    data = np.zeros((size, size), np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    pockets = []
    for n in range(13):
        row, col = 20 + (n // 5) * 60, 20 + (n % 5) * 35
        data[row : row + 21, col] = data[row : row + 21, col + 20] = 100
        data[row, col : col + 21] = data[row + 20, col : col + 21] = 100
        pockets.append(((col + 10.5) * 0.05, (row + 10.5) * 0.05))
    costmap = Costmap.from_grid(OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0), "pockets.yaml"))
    points = []
    for n, pocket in enumerate(pockets):
        points += [(0.6 + 0.1 * n, 9.4), pocket]
    problems = check_mission(mission_of(points), costmap, start=Pose2D(0.5, 9.5, 0.0))
    assert len(problems) == 13
    assert [p.subject for p in problems] == [f"waypoint {2 * n + 2}" for n in range(13)]
    # Each pocket is compared with the open-floor point before it, never with a pocket.
    for n, problem in enumerate(problems):
        floor = f"waypoint {2 * n + 1} at ({0.6 + 0.1 * n:.2f}, 9.40)"
        assert f"cannot be reached from {floor}" in str(problem), str(problem)


def test_reachability_skips_over_a_bad_waypoint(pocket_map: Costmap) -> None:
    # Waypoint 2 is in the wall; waypoint 3 is compared with waypoint 1 instead.
    mission = mission_of([(0.5, 0.5), (1.5, 2.0), (3.5, 3.5)])
    problems = check_mission(mission, pocket_map)
    assert [p.subject for p in problems] == ["waypoint 2"]
    assert "inside an obstacle" in str(problems[0])


@pytest.mark.parametrize("yaw", [0.0, 0.7])
def test_every_waypoint_gets_the_verdict_of_the_close_look(yaw: float) -> None:
    """The one-pass screen of thousands of waypoints agrees with looking at each one:
    on the map, off it, in pillars, grazing walls, on a map turned against the world."""
    from navseq.preflight import _FreeRegions, _placement_problem

    grid = load_map(REPO_MAP)
    turned = OccupancyGrid(grid.data, grid.resolution, Pose2D(-1.0, 2.0, yaw), grid.source)
    free = _FreeRegions(Costmap.from_grid(turned), TURTLEBOT3_BURGER)
    rng = np.random.default_rng(7)
    xmin, ymin, xmax, ymax = turned.bounds
    points = rng.uniform((xmin - 0.5, ymin - 0.5), (xmax + 0.5, ymax + 0.5), size=(4000, 2))
    waypoints = [Waypoint(float(x), float(y), yaw_rad=0.0) for x, y in points]
    one_by_one = [
        free.region_at(w.x, w.y) if _placement_problem(free, w.x, w.y, "", None) is None else None
        for w in waypoints
    ]
    assert free.regions_of(waypoints) == one_by_one
    assert {None} < set(one_by_one)  # both verdicts are among the points
