"""A SUCCEEDED is judged on a pose at least as recent as the result.

On the real Nav2 on a busy machine, /tf lagged the goal's result by up to a second, and
navseq judged true arrivals on older poses ("succeeded 24° off the goal yaw"): the ROS 2
navigator now holds the result in a :class:`ResultHold` until /tf caught up.
"""

from __future__ import annotations

from navseq.navigators.base import GoalDone, GoalOutcome
from navseq.navigators.catchup import MAX_HOLD, SAME_CLOCK, STAMP_SLACK, ResultHold

DONE = GoalDone(7, GoalOutcome.SUCCEEDED, "SUCCEEDED", "")


def test_a_success_waits_for_a_pose_stamped_at_the_result() -> None:
    hold = ResultHold()
    hold.saw_pose(100.0)
    assert hold.should_hold(DONE, 101.0)
    hold.hold(DONE, 101.0, wall_now=0.0)
    assert not hold.ready(0.1) and hold.release(0.1) == []
    hold.saw_pose(101.0 - STAMP_SLACK / 2)  # fresh enough
    assert hold.ready(0.2)
    assert hold.release(0.2) == [DONE]
    assert hold.release(0.3) == []  # once


def test_a_pose_that_never_comes_costs_the_longest_wait_once() -> None:
    hold = ResultHold()
    hold.saw_pose(100.0)
    hold.hold(DONE, 200.0 - SAME_CLOCK / 2, wall_now=5.0)
    assert hold.release(5.0 + MAX_HOLD - 0.01) == []
    assert hold.release(5.0 + MAX_HOLD) == [DONE]


def test_failures_poses_on_another_clock_or_no_poses_are_never_held() -> None:
    hold = ResultHold()
    assert not hold.should_hold(DONE, 100.0)  # no pose seen yet: nothing to wait for
    hold.saw_pose(100.0)
    assert not hold.should_hold(GoalDone.failed(7, "ABORTED", ""), 100.5)
    assert not hold.should_hold(DONE, 100.0 + SAME_CLOCK + 1)  # sim time vs wall time


def test_a_held_result_of_a_replaced_goal_is_dropped() -> None:
    hold = ResultHold()
    hold.saw_pose(100.0)
    hold.hold(DONE, 101.0, wall_now=0.0)
    hold.drop()
    assert hold.release(10.0) == []
