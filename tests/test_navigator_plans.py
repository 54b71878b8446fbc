"""A published plan is the goal's it ends at: a stale plan of a replaced goal is not.

Nav2 keeps following (and reporting distance along) the preempted goal's path until
its tree re-plans; move_base's planner may finish the old goal's plan after the new
goal went out. Both navigators take plans through :class:`PlanMatcher`.
"""

from __future__ import annotations

from navseq.geometry import Pose2D
from navseq.navigators.base import GoalPlan
from navseq.navigators.plans import PLAN_END_WITHIN, PlanMatcher

OLD = Pose2D(0.0, 0.0, 0.0)
NEW = Pose2D(3.0, 0.0, 0.0)
TO_OLD = [(-1.0, 0.0), (-0.5, 0.0), (0.0, 0.0)]
TO_NEW = [(0.0, 0.0), (1.5, 0.0), (3.0, 0.0)]


def test_the_old_goals_plan_is_not_taken_for_the_new_goal() -> None:
    plans = PlanMatcher()
    plans.track(1, OLD, "map")
    assert plans.plan_for(TO_OLD, "map") == GoalPlan(1, tuple(TO_OLD))
    plans.track(2, NEW, "map")  # preempted
    assert plans.plan_for(TO_OLD, "map") is None
    assert not plans.distance_is_this_goals()
    assert plans.plan_for(TO_NEW, "map") == GoalPlan(2, tuple(TO_NEW))
    assert plans.distance_is_this_goals()


def test_a_plan_ending_within_the_planners_tolerance_is_the_goals() -> None:
    plans = PlanMatcher()
    plans.track(1, NEW, "map")
    near = [(0.0, 0.0), (3.0, PLAN_END_WITHIN - 0.01)]  # a goal in an obstacle
    far = [(0.0, 0.0), (3.0, PLAN_END_WITHIN + 0.01)]
    assert plans.plan_for(far, "map") is None
    assert plans.plan_for(near, "map") is not None


def test_without_a_goal_or_with_an_empty_plan_nothing_is_taken() -> None:
    plans = PlanMatcher()
    assert plans.plan_for(TO_NEW, "map") is None
    plans.track(1, NEW, "map")
    assert plans.plan_for([], "map") is None
    plans.track(None)
    assert plans.plan_for(TO_NEW, "map") is None


def test_a_plan_in_another_frame_cannot_be_compared_and_is_taken() -> None:
    plans = PlanMatcher()
    plans.track(1, NEW, "map")
    assert plans.plan_for(TO_OLD, "odom") == GoalPlan(1, tuple(TO_OLD))


def test_where_no_plan_topic_speaks_the_stacks_distance_is_believed() -> None:
    plans = PlanMatcher()
    plans.track(1, NEW, "map")
    assert plans.distance_is_this_goals()  # no plan seen at all: nothing tells otherwise
    plans.plan_for(TO_OLD, "map")
    assert not plans.distance_is_this_goals()
