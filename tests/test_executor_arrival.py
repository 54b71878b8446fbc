"""The executor believes the robot: a SUCCEEDED with the robot elsewhere is a failure.

move_base can end a fresh goal SUCCEEDED within milliseconds with the robot metres
away (ros-planning/navigation #949). The executor checks such a result against the
robot's pose and hands a miss to the waypoint's policy like any failed attempt.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from cli_support import navseq, write_mission
from helpers_executor import Harness, line_mission
from navseq.executor import SendGoal, run_mission
from navseq.executor.arrival import ARRIVAL_SLACK_M, ARRIVAL_SLACK_RAD
from navseq.executor.events import AttemptFailed, WaypointFinished, WaypointOutcome
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction, Mission, Policy, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE, GoalTolerance
from navseq.navigators.scripted import FalseSuccess, ScriptedNavigator

GOAL = Pose2D(1.0, 0.0, 0.0)  # line_mission's first waypoint


def test_succeeded_far_from_the_goal_is_a_failed_attempt_and_the_retry_resends() -> None:
    h = Harness(line_mission(2, retries=1))
    h.start(0.0)
    first = h.goal_id
    h.done("SUCCEEDED", 0.05, pose=Pose2D(-1.38, 0.0, 0.0), text="Goal reached.")
    [failure] = h.of_type(AttemptFailed)
    assert failure.reason == "succeeded far from goal (2.38 m)"
    assert failure.status == "SUCCEEDED" and failure.text == "Goal reached."
    assert failure.will_retry and not h.of_type(WaypointFinished)
    h.tick(1.1)  # back-off over: the same waypoint again, as a new goal
    assert h.goal_id != first and h.goals()[-1].goal.pose == GOAL
    h.succeed(5.0, pose=GOAL)
    visit = h.executor.result.visits[0]
    assert visit.outcome is WaypointOutcome.REACHED and visit.attempts == 2
    assert [(a.reached, a.status, a.reason) for a in visit.attempt_results] == [
        (False, "SUCCEEDED", "succeeded far from goal (2.38 m)"),
        (True, "SUCCEEDED", ""),
    ]


def test_succeeded_off_the_goal_yaw_says_by_how_many_degrees() -> None:
    h = Harness(line_mission(1, on_failure=FailureAction.SKIP))
    h.start(0.0)
    h.succeed(3.0, pose=Pose2D(1.0, 0.0, math.radians(35.0)))
    visit = h.executor.result.visits[0]
    assert visit.outcome is WaypointOutcome.SKIPPED
    assert visit.reason == "succeeded 35° off the goal yaw"


def test_far_success_with_stop_policy_stops_the_mission_saying_why() -> None:
    h = Harness(line_mission(3))
    h.start(0.0)
    h.succeed(1.0, pose=Pose2D(0.0, 0.0, 0.0))
    result = h.executor.result
    assert h.executor.finished and not result.success
    assert result.reason == "stopped: waypoint 1 'p1' failed (succeeded far from goal (1.00 m))"
    assert len(h.goals()) == 1


def test_succeeded_within_tolerance_and_slack_is_reached() -> None:
    h = Harness(line_mission(1))
    h.start(0.0)
    h.succeed(4.0, pose=Pose2D(1.12, 0.0, 0.2))  # 0.12 m and 0.2 rad off: inside
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED
    assert not h.of_type(AttemptFailed)


def test_without_a_pose_in_the_event_the_latest_pose_seen_is_used() -> None:
    h = Harness(line_mission(1, on_failure=FailureAction.SKIP))
    h.start(0.0)
    h.feedback(0.5, Pose2D(0.5, 0.0, 0.0), 0.5)
    h.succeed(0.6)
    assert h.executor.result.visits[0].reason == "succeeded far from goal (0.50 m)"


def test_with_no_pose_at_all_the_success_is_believed() -> None:
    h = Harness(line_mission(1))
    h.start(0.0)
    h.succeed(0.1)
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED


def _one_waypoint(**overrides: float) -> Mission:
    return Mission(
        waypoints=(Waypoint(1.0, 0.0, yaw_rad=0.0, overrides=overrides),), defaults=Policy()
    )


def test_the_robot_profiles_tolerance_applies_where_the_waypoint_sets_none() -> None:
    loose = replace(DEFAULT_PROFILE, goal_tolerance=GoalTolerance(0.5, 0.17))
    h = Harness(_one_waypoint(), robot=loose)
    h.start(0.0)
    h.succeed(1.0, pose=Pose2D(0.5, 0.0, 0.0))  # 0.5 m off: within 0.5 + slack
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED


def test_the_waypoints_tolerance_wins_over_the_robot_profiles() -> None:
    loose = replace(DEFAULT_PROFILE, goal_tolerance=GoalTolerance(0.5, 1.0))
    h = Harness(_one_waypoint(xy_tolerance_m=0.05), robot=loose)
    h.start(0.0)
    h.succeed(1.0, pose=Pose2D(0.5, 0.0, 0.0))
    assert h.executor.result.visits[0].reason == "succeeded far from goal (0.50 m)"

    lenient = Harness(_one_waypoint(xy_tolerance_m=1.0, yaw_tolerance_rad=math.pi))
    lenient.start(0.0)
    lenient.succeed(1.0, pose=Pose2D(0.2, 0.0, 3.0))
    assert lenient.executor.result.visits[0].outcome is WaypointOutcome.REACHED


def test_a_mission_robot_section_gives_the_tolerance_when_no_robot_is_passed() -> None:
    mission = replace(
        _one_waypoint(), robot=replace(DEFAULT_PROFILE, goal_tolerance=GoalTolerance(2.0, 0.17))
    )
    h = Harness(mission)
    h.start(0.0)
    h.succeed(1.0, pose=Pose2D(-0.5, 0.0, 0.0))
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED


@given(
    off=st.floats(min_value=0.0, max_value=5.0),
    bearing=st.floats(min_value=-math.pi, max_value=math.pi),
)
def test_a_success_is_believed_exactly_within_tolerance_plus_slack(
    off: float, bearing: float
) -> None:
    h = Harness(line_mission(1, on_failure=FailureAction.SKIP))
    h.start(0.0)
    pose = Pose2D(GOAL.x + off * math.cos(bearing), GOAL.y + off * math.sin(bearing), 0.0)
    h.succeed(1.0, pose=pose)
    outcome = h.executor.result.visits[0].outcome
    limit = DEFAULT_PROFILE.goal_tolerance.xy_m + ARRIVAL_SLACK_M
    distance = pose.distance_to(GOAL)
    if distance < limit - 1e-9:
        assert outcome is WaypointOutcome.REACHED
    elif distance > limit + 1e-9:
        assert outcome is WaypointOutcome.SKIPPED


def test_the_yaw_limit_is_the_tolerance_plus_slack() -> None:
    limit = DEFAULT_PROFILE.goal_tolerance.yaw_rad + ARRIVAL_SLACK_RAD
    for yaw, expected in ((limit - 0.01, WaypointOutcome.REACHED), (limit + 0.01, None)):
        h = Harness(line_mission(1, on_failure=FailureAction.SKIP))
        h.start(0.0)
        h.succeed(1.0, pose=Pose2D(GOAL.x, GOAL.y, yaw))
        outcome = h.executor.result.visits[0].outcome
        assert outcome is (expected or WaypointOutcome.SKIPPED)


def test_a_pass_through_success_far_from_its_point_is_a_failed_attempt() -> None:
    # Nav2 ends a goal that preempted another SUCCEEDED with the robot where the old
    # one ended (issue 16: 1.84 m away): passing through is no excuse.
    h = Harness(line_mission(2, pass_through_m=0.3, retries=1))
    h.start(0.0)
    h.succeed(0.1, pose=Pose2D(0.0, 0.0, 0.0))  # 1 m from p1 (1, 0), radius 0.3
    [failure] = h.of_type(AttemptFailed)
    assert failure.reason == "succeeded far from goal (1.00 m)" and failure.will_retry
    assert not h.of_type(WaypointFinished)
    h.tick(1.2)
    assert h.goals()[-1].goal.pose == GOAL  # p1 again, not p2


def test_a_pass_through_success_within_radius_plus_slack_is_reached_whatever_the_yaw() -> None:
    h = Harness(line_mission(2, pass_through_m=0.3))
    h.start(0.0)
    # 0.38 m off (radius 0.3 + slack 0.1) and facing backwards: passing through.
    h.succeed(0.1, pose=Pose2D(1.0, 0.38, math.pi))
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED
    assert isinstance(h.commands[-1], SendGoal) and h.goals()[-1].goal.pose.x == 2.0


def test_a_pass_through_radius_smaller_than_the_stacks_tolerance_allows_the_tolerance() -> None:
    # The stack may end the goal within its own tolerance before the robot is ever
    # within a small radius: that is a true success.
    tolerance = DEFAULT_PROFILE.goal_tolerance.xy_m
    h = Harness(line_mission(2, pass_through_m=0.01, xy_tolerance_m=0.25))
    h.start(0.0)
    h.succeed(0.1, pose=Pose2D(1.0 - 0.3, 0.0, 0.0))
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED
    assert tolerance < 0.25  # the waypoint's own tolerance was the one applied
    h2 = Harness(line_mission(2, pass_through_m=0.01, xy_tolerance_m=0.25))
    h2.start(0.0)
    h2.succeed(0.1, pose=Pose2D(1.0 - 0.4, 0.0, 0.0))
    assert h2.executor.result.visits[0].outcome is not WaypointOutcome.REACHED


def test_runner_with_the_plan_race_retries_and_reaches() -> None:
    navigator = ScriptedNavigator([FalseSuccess()], speed=1.0)
    result = run_mission(line_mission(2, retries=1), navigator)
    assert result.success
    first = result.visits[0]
    assert first.attempts == 2
    assert first.attempt_results[0].reason == "succeeded far from goal (1.00 m)"
    assert len(navigator.sent_goals) == 3


def test_cli_report_shows_the_second_attempt_and_why(tmp_path: Path) -> None:
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {name: a, x: 2.0, y: 0.0, yaw: 0}\n  - {name: b, x: 2.0, y: 1.0, yaw: 90}\n",
        header="defaults:\n  retries: 1\n",
    )
    run = navseq(
        "run", mission, "--navigator", "scripted", "--scripted-script", "falsesuccess",
        "--scripted-speed", "2", "--out", tmp_path / "out", cwd=tmp_path,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    first = report["visits"][0]
    assert first["outcome"] == "reached" and len(first["attempts"]) == 2
    failed, reached = first["attempts"]
    assert failed["status"] == "SUCCEEDED" and not failed["reached"]
    assert failed["reason"] == "succeeded far from goal (2.00 m)"
    assert reached["reached"] and reached["reason"] == ""
    assert "attempt 1 failed (succeeded far from goal (2.00 m)), will retry" in run.stdout
