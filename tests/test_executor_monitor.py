"""AttemptMonitor: when one goal counts as progressing, stalled or out of time.

The goal is 2 m north of the robot's start, facing north; times are seconds on the
navigator's clock from the goal's send.
"""

from __future__ import annotations

import math

from navseq.executor.monitor import (
    PROGRESS_DISTANCE,
    PROGRESS_YAW,
    YAW_PROGRESS_RADIUS,
    AttemptMonitor,
)
from navseq.geometry import Pose2D
from navseq.navigators.base import Goal

NORTH = math.pi / 2
GOAL = Goal(1, Pose2D(0.0, 2.0, NORTH))


def monitor() -> AttemptMonitor:
    return AttemptMonitor(GOAL, sent_at=0.0)


def at(y: float, yaw: float = NORTH, x: float = 0.0) -> Pose2D:
    return Pose2D(x, y, yaw)


def test_a_robot_that_never_moves_stalls_when_the_stall_timeout_runs_out() -> None:
    m = monitor()
    for t in (0.5, 1.0, 2.0, 2.9):
        assert not m.observe(t, at(0.0))
        assert m.overdue(t, None, 3.0) is None
    assert m.overdue(3.0, None, 3.0) == "stalled"


def test_driving_towards_the_goal_restarts_the_stall_clock() -> None:
    m = monitor()
    m.observe(0.1, at(0.0))  # the first value only sets the best distance
    assert m.observe(2.0, at(0.5))
    assert m.last_progress_at == 2.0
    assert m.overdue(4.9, None, 3.0) is None
    assert m.overdue(5.0, None, 3.0) == "stalled"


def test_creeping_counts_once_the_gain_adds_up_to_the_progress_distance() -> None:
    m = monitor()
    m.observe(0.0, at(0.0))
    step = PROGRESS_DISTANCE * 0.6
    assert not m.observe(1.0, at(step))
    assert m.observe(2.0, at(2 * step))
    assert m.last_progress_at == 2.0


def test_moving_away_and_back_is_not_progress() -> None:
    m = monitor()
    m.observe(0.0, at(0.5))
    assert not m.observe(1.0, at(0.0))  # backing away
    assert not m.observe(2.0, at(0.5))  # back where it was: no better than its best
    assert m.overdue(3.0, None, 3.0) == "stalled"


def test_the_goal_timeout_runs_from_the_send_whatever_the_progress() -> None:
    m = monitor()
    for step in range(1, 10):
        m.observe(float(step), at(0.2 * step))
    assert m.overdue(9.9, 10.0, 3.0) is None
    assert m.overdue(10.0, 10.0, 3.0) == "timeout"
    assert m.overdue(100.0, None, None) is None  # no timeouts set: never overdue


def test_switching_to_the_navigators_longer_measure_is_neither_progress_nor_loss() -> None:
    m = monitor()
    m.observe(0.0, at(0.0))  # straight line: 2 m
    # The navigator's own distance along its 20 m detour restarts the best distance.
    assert not m.observe(1.0, at(0.0), navigator_distance=20.0)
    assert m.observe(2.0, at(0.0), navigator_distance=20.0 - PROGRESS_DISTANCE)
    # A pose alone says nothing on the navigator's measure, however close it looks.
    assert not m.observe(3.0, at(1.9))


def test_a_replan_around_an_obstacle_shifts_the_best_distance() -> None:
    m = monitor()
    m.adopt_plan(((0.0, 0.0), (0.0, 2.0)), at(0.0))
    m.observe(0.0, at(0.0))  # along the plan: 2 m
    assert m.observe(1.0, at(0.5))  # 1.5 m to go
    # A 10 m detour from where the robot stands: 10 m longer, not a lost 10 m.
    m.adopt_plan(((0.0, 0.5), (5.0, 0.5), (5.0, 2.0), (0.0, 2.0)), at(0.5))
    assert m.best_distance is not None and math.isclose(m.best_distance, 11.5)
    assert m.observe(2.0, at(0.5, x=1.0))  # 1 m along the detour is progress
    assert m.remaining(at(0.5, x=1.0)) == 10.5


def test_turning_in_place_near_the_goal_is_progress_far_from_it_not() -> None:
    near = monitor()
    close = 2.0 - YAW_PROGRESS_RADIUS / 2
    near.observe(0.0, at(close, yaw=0.0))
    assert near.observe(1.0, at(close, yaw=2 * PROGRESS_YAW))
    assert not near.observe(2.0, at(close, yaw=2.5 * PROGRESS_YAW))  # less than the step

    far = monitor()
    far.observe(0.0, at(0.0, yaw=0.0))
    assert not far.observe(1.0, at(0.0, yaw=NORTH))


def test_a_goal_sent_again_after_a_pause_keeps_its_deadlines_moved_on() -> None:
    m = monitor()
    m.observe(0.0, at(0.0))
    m.observe(2.0, at(0.5))  # progress at 2 s
    again = m.resumed(Goal(2, GOAL.pose), paused_for=100.0)
    assert again.goal.goal_id == 2
    assert (again.sent_at, again.last_progress_at) == (100.0, 102.0)
    assert again.overdue(104.9, 10.0, 3.0) is None
    assert again.overdue(105.0, 10.0, 3.0) == "stalled"
    assert again.overdue(110.0, 10.0, None) == "timeout"
    # Progress starts afresh: the first pose after the pause only sets the best.
    assert not again.observe(103.0, at(0.5))


def test_remaining_for_display_is_straight_until_a_plan_is_known() -> None:
    m = monitor()
    assert m.remaining(at(0.0, x=0.0)) == 2.0
    m.adopt_plan(((0.0, 0.0), (3.0, 0.0), (3.0, 2.0), (0.0, 2.0)), at(0.0))
    assert m.remaining(at(0.0)) == 8.0
    m.adopt_plan((), at(0.0))  # an empty plan says nothing: the last one stays
    assert m.remaining(at(0.0)) == 8.0
