"""The sim navigator's events, as an executor polling it sees them."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import pytest

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.navigators.base import (
    Goal,
    GoalAccepted,
    GoalDone,
    GoalFeedback,
    GoalOutcome,
    GoalPlan,
    Navigator,
)
from navseq.navigators.sim import SimNavigator

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
START = Pose2D(-2.0, -0.5, 0.0)


@pytest.fixture
def nav() -> SimNavigator:
    return SimNavigator.from_map(MAP, START)


def spin_until_done(nav: SimNavigator, limit: float = 120.0) -> list[object]:
    events: list[object] = []
    deadline = nav.now() + limit
    while nav.now() < deadline:
        nav.spin(0.1)
        events.extend(nav.poll())
        if any(isinstance(e, GoalDone) for e in events):
            return events
    raise AssertionError(f"no GoalDone within {limit} s")


def test_is_a_navigator_with_a_server_always_there(nav: SimNavigator) -> None:
    assert isinstance(nav, Navigator)
    assert nav.wait_for_server(0.0) is True
    assert nav.robot_pose() == START
    assert nav.now() == 0.0
    assert nav.poll() == []


def test_goal_to_success_event_sequence(nav: SimNavigator) -> None:
    goal = Goal(7, Pose2D(-0.5, -1.8, math.pi / 2))
    nav.send_goal(goal)
    assert nav.poll() == [GoalAccepted(7)]
    events = spin_until_done(nav)
    assert isinstance(events[0], GoalPlan) and events[0].goal_id == 7
    assert events[0].path[0] == (START.x, START.y)
    assert events[0].path[-1] == (goal.pose.x, goal.pose.y)
    assert events[-1] == GoalDone.succeeded(7, "goal reached")
    feedback = [e for e in events if isinstance(e, GoalFeedback)]
    assert all(f.goal_id == 7 for f in feedback)
    # One feedback per 0.2 s of simulated time, distance remaining shrinking.
    duration = nav.now()
    assert abs(len(feedback) - duration / 0.2) <= 2
    remaining = [f.distance_remaining for f in feedback]
    assert remaining[0] > 1.0 and remaining[-1] < 0.1
    assert all(b <= a + 0.01 for a, b in itertools.pairwise(remaining))
    pose = nav.robot_pose()
    assert pose is not None and pose.distance_to(goal.pose) <= 0.05
    assert nav.poll() == []  # nothing after the end


def test_goal_in_an_obstacle_is_accepted_then_aborted(nav: SimNavigator) -> None:
    nav.send_goal(Goal(1, Pose2D(0.0, 0.0)))  # the centre pillar
    nav.spin(0.05)
    events = nav.poll()
    assert events[0] == GoalAccepted(1)
    assert isinstance(events[1], GoalDone)
    assert events[1].outcome is GoalOutcome.FAILED
    assert events[1].status == "ABORTED"
    assert "obstacle" in events[1].text
    assert len(events) == 2
    assert nav.robot_pose() == START


def test_new_goal_preempts_the_active_one(nav: SimNavigator) -> None:
    nav.send_goal(Goal(1, Pose2D(1.6, -0.5)))
    nav.spin(3.0)
    nav.poll()
    nav.send_goal(Goal(2, Pose2D(-2.0, 0.5)))
    assert nav.poll() == [
        GoalDone.failed(1, "PREEMPTED", "replaced by a new goal"),
        GoalAccepted(2),
    ]
    events = spin_until_done(nav)
    assert all(getattr(e, "goal_id", 2) == 2 for e in events)
    assert events[-1].outcome is GoalOutcome.SUCCEEDED  # type: ignore[attr-defined]


def test_cancel_preempts_and_the_robot_stops(nav: SimNavigator) -> None:
    nav.send_goal(Goal(1, Pose2D(1.6, -0.5)))
    nav.spin(3.0)
    nav.cancel_goal()
    assert nav.poll()[-1] == GoalDone.failed(1, "PREEMPTED", "canceled")
    nav.cancel_goal()  # twice: nothing more
    nav.spin(1.0)  # let it brake
    assert nav.poll() == []
    stopped_at = nav.robot_pose()
    nav.spin(5.0)
    assert nav.robot_pose() == stopped_at
    assert nav.poll() == []


def test_close_cancels_the_active_goal(nav: SimNavigator) -> None:
    nav.send_goal(Goal(3, Pose2D(1.6, -0.5)))
    nav.spin(1.0)
    nav.close()
    assert nav.poll()[-1] == GoalDone.failed(3, "PREEMPTED", "canceled")
    assert nav.world.server.state.value == "CANCELED"


def test_spin_counts_simulated_time_exactly(nav: SimNavigator) -> None:
    for _ in range(10):
        nav.spin(0.01)  # shorter than a step: carried over, not lost
    assert nav.now() == pytest.approx(0.1)
    nav.spin(2.5)
    assert nav.now() == pytest.approx(2.6)


def test_trajectory_records_where_the_robot_drove(nav: SimNavigator) -> None:
    nav.spin(5.0)
    assert nav.trajectory.rows() == [(0.0, START.x, START.y)]  # idle: nothing new
    nav.send_goal(Goal(1, Pose2D(-0.5, -1.8)))
    spin_until_done(nav)
    times = [t for t, _, _ in nav.trajectory]
    assert times == sorted(times)
    _, x, y = nav.trajectory[-1]
    assert math.hypot(x + 0.5, y + 1.8) <= 0.05
    assert len(nav.trajectory) > 100


def test_from_map_default_start_and_bad_start() -> None:
    nav = SimNavigator.from_map(MAP)
    pose = nav.robot_pose()
    assert pose is not None and nav.world.costmap.is_free(pose.x, pose.y)
    with pytest.raises(NavseqError, match="obstacle"):
        SimNavigator.from_map(MAP, Pose2D(1.1, 1.1))
    with pytest.raises(NavseqError):
        SimNavigator.from_map(MAP.with_name("no_such_map.yaml"))
