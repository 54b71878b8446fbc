"""Progress (the stall timeout) is judged on one consistent measure: distance along the plan.

On Nav2's warehouse map a goal was skipped as "stalled" while the distance along the
plan fell steadily: the first progress value was the straight-line distance, later
ones along the plan, and the best distance was never reset when the measure changed.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from helpers_executor import Harness
from navseq.executor.events import AttemptFailed, WaypointOutcome
from navseq.executor.runner import run_mission
from navseq.geometry import Pose2D, remaining_along_path
from navseq.mission.model import FailureAction, Mission, Policy, Waypoint
from navseq.navigators.sim import SimNavigator
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.world import SimWorld

# ---------------------------------------------------------------- remaining_along_path


def test_remaining_along_a_path_from_the_projection_onto_it() -> None:
    ell = [(0.0, 0.0), (4.0, 0.0), (4.0, 3.0)]
    assert remaining_along_path(ell, 0.0, 0.0) == 7.0
    assert remaining_along_path(ell, 1.0, 0.5) == 6.0  # beside the first leg
    assert remaining_along_path(ell, 4.5, 1.0) == 2.0  # beside the second leg
    assert remaining_along_path(ell, 4.0, 3.0) == 0.0
    assert remaining_along_path(ell, -2.0, 0.0) == 9.0  # behind the start: get there first
    assert remaining_along_path([], 1.0, 1.0) == 0.0
    assert remaining_along_path([(3.0, 4.0)], 0.0, 0.0) == 5.0


points = st.tuples(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0))


@given(path=st.lists(points, min_size=2, max_size=12), where=points)
def test_remaining_is_never_more_than_the_path_and_zero_at_its_end(
    path: list[tuple[float, float]], where: tuple[float, float]
) -> None:
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(path))
    remaining = remaining_along_path(path, *where)
    gap_to_start = math.dist(where, path[0])
    assert 0.0 <= remaining <= length + gap_to_start + 1e-9
    # The same sum, to the rounding: the function adds the legs one by one, and sum()
    # compensates its rounding errors since Python 3.12 (the last bits may differ).
    from_start = remaining_along_path(path, *path[0])
    assert math.isclose(from_start, length, rel_tol=1e-12) or math.dist(path[0], path[1]) == 0


@given(length=st.floats(0.5, 100.0), fraction=st.floats(0.001, 1.0))
def test_driving_along_a_straight_plan_leaves_the_rest_of_it(
    length: float, fraction: float
) -> None:
    path = [(0.0, 0.0), (length / 2, 0.0), (length, 0.0)]
    assert math.isclose(
        remaining_along_path(path, fraction * length, 0.3), (1 - fraction) * length, abs_tol=1e-9
    )


# ---------------------------------------------------------------- hand-driven executor


def far_goal(stall_timeout: float = 3.0) -> Mission:
    """One waypoint 2 m north of the start, as the crow flies."""
    return Mission(
        waypoints=(Waypoint(0.0, 2.0, yaw_rad=math.pi / 2, name="beyond the wall"),),
        defaults=Policy(stall_timeout_s=stall_timeout, on_failure=FailureAction.SKIP),
    )


def stalled(h: Harness) -> bool:
    return any(f.reason == "stalled" for f in h.of_type(AttemptFailed))


def test_straight_line_first_then_longer_plan_distances_that_fall_are_progress() -> None:
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    h.tick(0.1, Pose2D(0.0, 0.0, 0.0))  # straight line: 2.0 m
    # Then the navigator's distance along its plan: a 20 m detour, falling at 0.2 m/s.
    for step in range(1, 200):
        t = 0.1 + 0.5 * step
        h.feedback(t, Pose2D(0.1 * step, 0.0, 0.0), 20.0 - 0.1 * step)
        h.tick(t, Pose2D(0.1 * step, 0.0, 0.0))
    assert not stalled(h) and not h.executor.finished


def test_a_replan_that_lengthens_the_path_is_not_a_stall() -> None:
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    h.plan(0.0, [(0.0, 0.0), (0.0, 2.0)])
    t = 0.0
    for step in range(1, 6):  # 0.5 m north along the plan
        t += 0.5
        h.tick(t, Pose2D(0.0, 0.1 * step, math.pi / 2))
    # An obstacle appears: the new plan goes 10 m east and back around it.
    detour = [(0.0, 0.5), (10.0, 0.5), (10.0, 2.0), (0.0, 2.0)]
    h.plan(t, detour)
    for step in range(1, 90):
        t += 0.5
        h.tick(t, Pose2D(0.1 * step, 0.5, 0.0))
    assert not stalled(h) and not h.executor.finished


def test_frequent_replans_of_a_robot_that_moves_slowly_are_not_a_stall() -> None:
    # move_base publishes a fresh plan every cycle (TurtleBot3: 5 Hz); a robot doing
    # 0.1 m/s gains less than PROGRESS_DISTANCE between two of them.
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    for step in range(100):
        t = 0.2 * step
        y = 0.02 * step
        h.plan(t, [(0.0, y), (0.0, 2.0)])  # each plan starts where the robot is
        h.tick(t, Pose2D(0.0, y, math.pi / 2))
        h.feedback(t, Pose2D(0.0, y, math.pi / 2))  # ros1: feedback has only a pose
    assert not stalled(h)
    h.succeed(30.0, pose=Pose2D(0.0, 2.0, math.pi / 2))
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED


def test_a_robot_that_stops_on_its_plan_still_stalls() -> None:
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    h.plan(0.0, [(0.0, 0.0), (5.0, 0.0), (5.0, 2.0), (0.0, 2.0)])
    for step in range(1, 10):
        h.tick(0.5 * step, Pose2D(0.2 * step, 0.0, 0.0))
    assert not stalled(h)
    for step in range(10, 30):  # stuck at x = 1.8, plans or no plans
        t = 0.5 * step
        if step % 2:
            h.plan(t, [(1.8, 0.0), (5.0, 0.0), (5.0, 2.0), (0.0, 2.0)])
        h.tick(t, Pose2D(1.8, 0.0, 0.0))
    assert stalled(h)


def test_plans_that_flip_between_two_detours_do_not_hide_a_stall() -> None:
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    east = [(0.0, 0.0), (6.0, 0.0), (6.0, 2.0), (0.0, 2.0)]
    west = [(0.0, 0.0), (-3.0, 0.0), (-3.0, 2.0), (0.0, 2.0)]
    for step in range(20):
        h.plan(0.5 * step, east if step % 2 else west)
        h.tick(0.5 * step, Pose2D(0.0, 0.0, 0.0))
    assert stalled(h)


def test_a_real_stall_on_the_navigators_measure_is_detected() -> None:
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    h.tick(0.1, Pose2D(0.0, 0.0, 0.0))
    for step in range(1, 20):
        h.feedback(0.1 + 0.5 * step, Pose2D(0.5, 0.0, 0.0), 20.0)
        h.tick(0.1 + 0.5 * step)
    assert stalled(h)


# ---------------------------------------------------------------- simulator


def wall_with_a_gap_at_the_far_end() -> OccupancyGrid:
    """A 10 x 4 m room split along its length by a wall, open only at the east end.

    From (1, 1) to (1, 3) is 2 m as the crow flies and about 17 m around the wall.
    """
    resolution = 0.05
    width, height = 10.0, 4.0
    cols, rows = round(width / resolution), round(height / resolution)
    data = np.zeros((rows, cols), dtype=np.int8)
    data[:4, :] = data[-4:, :] = data[:, :4] = data[:, -4:] = 100  # outer walls, 0.2 m
    wall_rows = slice(round(1.9 / resolution), round(2.1 / resolution))
    data[wall_rows, : round(8.4 / resolution)] = 100  # gap from x = 8.4 m to the east wall
    return OccupancyGrid(data, resolution, Pose2D(0.0, 0.0, 0.0), source="<wall with a gap>")


def test_a_long_detour_on_the_simulator_is_driven_to_the_end_not_stalled() -> None:
    grid = wall_with_a_gap_at_the_far_end()
    navigator = SimNavigator(SimWorld(grid, Pose2D(1.0, 1.0, 0.0)))
    mission = Mission(
        waypoints=(Waypoint(1.0, 3.0, yaw_rad=math.pi, name="behind the wall"),),
        # Far shorter than the detour takes at 0.22 m/s, longer than any pause on it.
        defaults=Policy(stall_timeout_s=20.0, on_failure=FailureAction.SKIP),
    )
    result = run_mission(mission, navigator)
    visit = result.visits[0]
    assert visit.outcome is WaypointOutcome.REACHED, visit.reason
    assert visit.attempts == 1
    assert visit.distance_driven >= 15.0  # it really went round
    assert visit.duration > 20.0


@given(
    plans=st.lists(st.lists(points, min_size=1, max_size=6), min_size=1, max_size=12),
    where=points,
)
def test_a_robot_that_never_moves_stalls_whatever_plans_arrive(
    plans: list[list[tuple[float, float]]], where: tuple[float, float]
) -> None:
    h = Harness(far_goal(stall_timeout=3.0))
    h.start(0.0)
    robot = Pose2D(where[0], where[1], 0.0)
    t = 0.0
    for plan in plans:
        h.plan(t, [*plan, (0.0, 2.0)])
        h.tick(t, robot)
        t += 0.25
    while t <= 3.5:
        h.tick(t, robot)
        t += 0.25
    assert stalled(h)
