"""Ordering by time: the turns at the waypoints count, so a route that turns about less wins."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE
from navseq.route.legs import LegPlanner, StraightLegs
from navseq.route.order import shortest_order
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.planner import compiled_search_available, reach_routes


def facing_mission() -> Mission:
    """From a start facing east: "ahead" 1 m east facing east, "behind" 0.95 m west facing
    west. Behind first drives 0.05 m less but turns about twice (to leave west, then to
    leave east); ahead first turns about once."""
    return Mission(
        waypoints=(
            Waypoint(-0.95, 0.0, yaw_deg=180, name="behind"),
            Waypoint(1.0, 0.0, yaw_deg=0, name="ahead"),
        ),
        start=Pose2D(0.0, 0.0, 0.0),
    )


def names(mission: Mission, order: tuple[int, ...]) -> list[str | None]:
    return [mission.waypoints[i].name for i in order]


def test_with_the_robot_the_order_with_fewer_turns_wins_over_a_few_centimetres() -> None:
    mission = facing_mission()
    by_metres = shortest_order(mission, StraightLegs(), time_limit_s=0.2)
    by_time = shortest_order(mission, StraightLegs(), time_limit_s=0.2, robot=DEFAULT_PROFILE)
    assert names(mission, by_metres.order) == ["behind", "ahead"]  # the file's: shortest
    assert names(mission, by_time.order) == ["ahead", "behind"]


def test_pass_through_waypoints_are_not_turned_at() -> None:
    """Passing through, the robot keeps going: the waypoint's yaw costs nothing there."""
    mission = facing_mission()
    passing = Mission(
        waypoints=tuple(
            Waypoint(w.x, w.y, yaw_rad=w.yaw_rad, name=w.name, overrides={"pass_through_m": 0.3})
            for w in mission.waypoints
        ),
        start=mission.start,
    )
    by_time = shortest_order(passing, StraightLegs(), time_limit_s=0.2, robot=DEFAULT_PROFILE)
    # The last waypoint always stops; either way one reversal remains, and the shorter wins.
    assert names(passing, by_time.order) == ["behind", "ahead"]


def corridor_costmap() -> tuple[LegPlanner, float]:
    """An L-shaped corridor: from its south-west end the way goes north, then east."""
    from navseq.commands.common import costmap_for_robot

    data = np.full((120, 120), 100, np.int8)
    data[10:110, 10:30] = 0  # the west arm, south to north
    data[90:110, 10:110] = 0  # the north arm, west to east
    grid = OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0), "corridor")
    return LegPlanner(costmap_for_robot(grid)), 0.5


@pytest.mark.parametrize("compiled", [False, True])
def test_a_route_s_headings_follow_the_corridor_not_the_straight_line(compiled: bool) -> None:
    if compiled and not compiled_search_available():
        pytest.skip("the compiled search is not built")
    planner, anchor = corridor_costmap()
    start, goal = (1.0, 1.5), (5.0, 5.0)  # south-west end, east end
    (metres, depart, arrive), (back_m, back_depart, back_arrive) = (
        reach_routes(planner.costmap, start, [goal], anchor, use_compiled=compiled)[0],
        reach_routes(planner.costmap, goal, [start], anchor, use_compiled=compiled)[0],
    )
    assert metres > math.dist(start, goal) + 1.0
    assert abs(depart - math.pi / 2) < 0.35  # leaves north, up the west arm
    assert abs(arrive) < 0.35  # arrives heading east, along the north arm
    assert back_m == pytest.approx(metres, rel=0.02)
    assert abs(abs(back_depart) - math.pi) < 0.35 and abs(back_arrive + math.pi / 2) < 0.35


def test_headings_measured_once_serve_the_next_ordering_both_ways() -> None:
    from navseq.route.distances import known_distances

    planner, anchor = corridor_costmap()
    places = [(1.0, 1.5), (5.0, 5.0), (1.0, 5.0)]
    first = planner.routes(places, anchor)
    searched = known_distances(planner.costmap).searched
    again = planner.routes(places[::-1], anchor)
    assert known_distances(planner.costmap).searched == searched  # nothing searched again
    order = [2, 1, 0]
    np.testing.assert_allclose(again.metres, first.metres[np.ix_(order, order)], rtol=0.02)
    turn = np.angle(np.exp(1j * (again.depart - first.depart[np.ix_(order, order)])))
    finite = np.isfinite(turn)
    assert finite.sum() == 6 and np.all(np.abs(turn[finite]) < 0.35)


def test_progress_is_shown_on_a_terminal_and_not_elsewhere() -> None:
    from rich.console import Console

    from navseq.commands.order_progress import order_progress

    planner, _ = corridor_costmap()
    climb = [Waypoint(1.0, y, yaw_deg=90) for y in (1.5, 2.5, 3.5, 4.5)]
    mission = Mission(waypoints=(*climb, Waypoint(5.0, 5.0, yaw_deg=0)))
    screen = io.StringIO()
    terminal = Console(file=screen, force_terminal=True, width=100)
    with order_progress(terminal) as progress:
        assert progress is not None
        shortest_order(mission, planner, 0.2, robot=DEFAULT_PROFILE, progress=progress)
    shown = screen.getvalue()
    assert "distances" in shown and "4/4" in shown and "solving" in shown
    with order_progress(Console(file=io.StringIO(), force_terminal=False)) as progress:
        assert progress is None
