"""The mission state machine, driven by hand: every status path and every policy."""

from __future__ import annotations

import math

import pytest

from helpers_executor import Harness, line_mission
from navseq.errors import NavseqError
from navseq.executor import CancelGoal, ClearCostmaps, ExecutorState, ResumePoint, SendGoal
from navseq.executor.events import (
    AttemptFailed,
    LoopStarted,
    MissionFinished,
    MissionStarted,
    ServerStatusChanged,
    WaypointDwelling,
    WaypointFinished,
    WaypointOutcome,
    WaypointProgress,
    WaypointStarted,
)
from navseq.executor.result import WaypointResult
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction
from navseq.navigators.base import GoalDone

REACHED = WaypointOutcome.REACHED
FAILED_STATUSES = [
    "ABORTED",
    "REJECTED",
    "PREEMPTED",
    "RECALLED",
]


def outcomes(h: Harness) -> list[WaypointOutcome]:
    return [v.outcome for v in h.executor.result.visits]


# ---------------------------------------------------------------- status paths


def test_succeeded_goes_through_every_waypoint_in_order() -> None:
    h = Harness(line_mission(3))
    first = h.start(0.0)
    assert first == [SendGoal(h.goals()[0].goal)]
    assert first[0].goal.pose == Pose2D(1.0, 0.0, 0.0)
    for step in range(3):
        h.succeed(10.0 * (step + 1))
    assert [g.goal.pose.x for g in h.goals()] == [1.0, 2.0, 3.0]
    ids = [g.goal.goal_id for g in h.goals()]
    assert ids == sorted(set(ids))
    assert h.executor.finished and h.executor.state is ExecutorState.FINISHED
    result = h.executor.result
    assert result.success and result.exit_code == 0 and result.reason == "completed"
    assert outcomes(h) == [REACHED] * 3
    assert [v.duration for v in result.visits] == [10.0, 10.0, 10.0]
    assert h.of_type(MissionFinished) == [MissionFinished(t=30.0, success=True, reason="completed")]
    assert not h.cancels()


@pytest.mark.parametrize("status", FAILED_STATUSES)
def test_failed_status_with_stop_policy_ends_the_mission(status: str) -> None:
    h = Harness(line_mission(3, on_failure=FailureAction.STOP))
    h.start(0.0)
    h.succeed(5.0)
    h.done(status, 7.0)
    failure = h.of_type(AttemptFailed)
    assert failure == [
        AttemptFailed(
            t=7.0,
            index=1,
            attempt=1,
            reason=status,
            will_retry=False,
            status=status,
            duration=2.0,
        )
    ]
    assert h.executor.finished
    assert outcomes(h) == [REACHED, WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN]
    result = h.executor.result
    assert not result.success and result.exit_code == 1
    assert result.reason == f"stopped: waypoint 2 'p2' failed ({status})"
    assert result.visits[1].reason == status
    assert len(h.goals()) == 2


def test_outcomes_are_the_stacks_and_its_status_names_reach_the_record() -> None:
    """A stack with other status names (Nav2's) needs no executor change: the outcome
    decides what happens, the stack's own name is what the result records."""
    h = Harness(line_mission(2, on_failure=FailureAction.SKIP))
    h.start(0.0)
    h._keep(h.executor.on_event(GoalDone.failed(h.goal_id, "CANCELED", "by a client"), 2.0))
    h._keep(h.executor.on_event(GoalDone.succeeded(h.goal_id, status="STATUS_SUCCEEDED"), 4.0))
    first, second = h.executor.result.visits
    assert first.outcome is WaypointOutcome.SKIPPED and first.reason == "CANCELED"
    attempt = first.attempt_results[0]
    assert (attempt.status, attempt.reason, attempt.text) == (
        "CANCELED",
        "CANCELED",
        "by a client",
    )
    assert second.outcome is REACHED
    assert second.attempt_results[0].status == "STATUS_SUCCEEDED"
    # LOST, whatever the stack calls it, waits for the server instead of failing.
    h = Harness(line_mission(1))
    h.start(0.0)
    h.executor.on_event(GoalDone.lost(h.goal_id, status="UNKNOWN"), 1.0)
    assert h.executor.state is ExecutorState.WAITING_SERVER
    assert h.of_type(ServerStatusChanged)[0].reason == "goal UNKNOWN"


@pytest.mark.parametrize("status", FAILED_STATUSES)
def test_failed_status_with_skip_policy_goes_on(status: str) -> None:
    h = Harness(line_mission(3, on_failure=FailureAction.SKIP))
    h.start(0.0)
    h.done(status, 2.0)
    assert h.goals()[-1].goal.pose.x == 2.0  # next waypoint sent at once
    h.succeed(4.0)
    h.succeed(6.0)
    assert outcomes(h) == [WaypointOutcome.SKIPPED, REACHED, REACHED]
    result = h.executor.result
    assert not result.success and result.exit_code == 1
    assert result.reason.startswith("completed: 1 ")


def test_results_for_stale_goal_ids_are_ignored() -> None:
    h = Harness(line_mission(2, retries=1))
    h.start(0.0)
    old = h.goal_id
    h.done("ABORTED", 1.0)
    h.tick(2.0)
    assert h.goal_id != old
    h.done("SUCCEEDED", 3.0, goal_id=old)  # late news about the first attempt
    h.feedback(3.0, Pose2D(1.0, 0.0, 0.0), 0.0, goal_id=old)
    assert h.of_type(WaypointFinished) == []
    assert h.executor.state is ExecutorState.ACTIVE
    h.succeed(4.0)
    assert h.of_type(WaypointFinished)[0].attempts == 2


# ---------------------------------------------------------------- server lost


@pytest.mark.parametrize("how", ["lost_status", "server_lost"])
def test_lost_server_back_in_time_resends_without_using_a_retry(how: str) -> None:
    h = Harness(line_mission(2, retries=0, server_timeout=30.0))
    h.start(0.0)
    first = h.goal_id
    if how == "lost_status":
        h.done("LOST", 5.0)
    else:
        h.server_lost(5.0)
    assert h.executor.state is ExecutorState.WAITING_SERVER
    assert h.of_type(ServerStatusChanged)[0].available is False
    h.tick(20.0)
    assert len(h.goals()) == 1  # nothing sent while the server is away
    h.server_back(34.0)  # 29 s after the loss: in time
    resent = h.goals()[-1].goal
    assert resent.goal_id > first and resent.pose == h.goals()[0].goal.pose
    assert h.of_type(AttemptFailed) == []
    h.succeed(40.0)
    h.succeed(45.0)
    result = h.executor.result
    assert result.success
    assert [v.attempts for v in result.visits] == [1, 1]


def test_server_not_back_in_time_stops_the_mission() -> None:
    h = Harness(line_mission(3, retries=5, on_failure=FailureAction.RETRY, server_timeout=30.0))
    h.start(0.0)
    h.succeed(3.0)
    h.server_lost(5.0)
    h.tick(34.9)
    assert not h.executor.finished
    commands = h.tick(35.0)
    assert CancelGoal() in commands
    assert h.executor.finished
    result = h.executor.result
    assert not result.success and result.reason == "navigation server lost"
    assert outcomes(h) == [REACHED, WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN]
    assert result.visits[1].reason == "navigation server lost"


def test_server_timeout_none_waits_forever() -> None:
    h = Harness(line_mission(1, server_timeout=None))
    h.start(0.0)
    h.done("LOST", 1.0)
    h.tick(1e6)
    assert h.executor.state is ExecutorState.WAITING_SERVER
    h.server_back(1e6 + 1)
    h.succeed(1e6 + 2)
    assert h.executor.result.success


def test_server_lost_during_back_off_waits_before_the_retry() -> None:
    h = Harness(line_mission(1, retries=1, server_timeout=10.0))
    h.start(0.0)
    h.done("ABORTED", 1.0)
    h.server_lost(1.5)
    h.tick(2.0)  # back-off over, but no server
    assert h.executor.state is ExecutorState.WAITING_SERVER and len(h.goals()) == 1
    h.server_back(3.0)
    assert len(h.goals()) == 2
    h.succeed(4.0)
    assert h.executor.result.visits[0].attempts == 2


# ---------------------------------------------------------------- timeouts


def test_goal_timeout_cancels_and_counts_from_each_attempts_send() -> None:
    h = Harness(line_mission(1, goal_timeout_s=10.0, retries=1))
    h.start(0.0)
    assert h.tick(9.9) == []
    commands = h.tick(10.0)
    assert commands == [CancelGoal()]
    assert h.of_type(AttemptFailed)[0].reason == "timeout"
    assert h.of_type(AttemptFailed)[0].will_retry
    h.tick(11.0)  # back-off over: attempt 2 sent at t=11
    assert len(h.goals()) == 2
    assert h.tick(20.9) == []
    h.tick(21.0)
    assert [f.reason for f in h.of_type(AttemptFailed)] == ["timeout", "timeout"]
    assert h.executor.finished and not h.executor.result.success


def test_stall_timeout_fires_only_without_progress() -> None:
    h = Harness(line_mission(1, stall_timeout_s=5.0))
    h.start(0.0)
    h.feedback(1.0, Pose2D(-3.0, 0.0), remaining=4.0)
    # Steady progress keeps it alive well past the stall timeout.
    for step in range(1, 10):
        h.feedback(1.0 + 3.0 * step, Pose2D(-3.0 + 0.3 * step, 0.0), remaining=4.0 - 0.3 * step)
        h.tick(1.0 + 3.0 * step)
    assert not h.of_type(AttemptFailed)
    last_progress = 28.0
    # Crawling by less than 5 cm at a time is not progress.
    for step in range(1, 6):
        h.feedback(last_progress + step, Pose2D(0.0, 0.0), remaining=1.3 - 0.008 * step)
        h.tick(last_progress + step - 0.01)
    assert not h.of_type(AttemptFailed)
    commands = h.tick(last_progress + 5.0)
    assert commands == [CancelGoal()]
    assert h.of_type(AttemptFailed)[0].reason == "stalled"


def test_turning_in_place_at_the_goal_is_progress_but_not_far_away() -> None:
    h = Harness(line_mission(1, stall_timeout_s=3.0))
    h.start(0.0)
    # At the goal position, turning towards the goal yaw (0) from pi/2.
    for step in range(8):
        yaw = math.pi / 2 - 0.2 * step
        h.feedback(2.0 * step, Pose2D(1.0, 0.05, yaw), remaining=0.05)
        h.tick(2.0 * step)
    assert not h.of_type(AttemptFailed)

    far = Harness(line_mission(1, stall_timeout_s=3.0))
    far.start(0.0)
    for step in range(3):
        yaw = math.pi / 2 - 0.2 * step
        far.feedback(1.5 * step, Pose2D(0.0, 0.0, yaw), remaining=1.0)
        far.tick(1.5 * step)
    assert far.of_type(AttemptFailed)[0].reason == "stalled"


def test_straight_line_progress_from_tick_poses_without_feedback() -> None:
    h = Harness(line_mission(1, stall_timeout_s=2.0))
    h.start(0.0)
    for step in range(10):
        h.tick(1.0 * step, Pose2D(-5.0 + 0.5 * step, 0.0))
    assert not h.of_type(AttemptFailed)
    progress = h.of_type(WaypointProgress)
    assert progress and progress[-1].distance_remaining == pytest.approx(1.5)
    h.tick(11.0, Pose2D(-0.5, 0.0))
    assert h.of_type(AttemptFailed)[0].reason == "stalled"


# ---------------------------------------------------------------- retries


@pytest.mark.parametrize("clear", [True, False])
def test_retries_back_off_one_second_and_clear_costmaps_when_asked(clear: bool) -> None:
    h = Harness(line_mission(1, retries=2, clear_costmaps_on_retry=clear))
    h.start(0.0)
    for attempt in (1, 2):
        t = 10.0 * attempt
        assert h.done("ABORTED", t) == []
        assert h.executor.state is ExecutorState.WAITING_RETRY
        assert h.tick(t + 0.99) == []
        commands = h.tick(t + 1.0)
        expected = ([ClearCostmaps()] if clear else []) + [SendGoal(h.goals()[-1].goal)]
        assert commands == expected
    h.done("ABORTED", 30.0)  # third attempt: retries used up
    assert [f.will_retry for f in h.of_type(AttemptFailed)] == [True, True, False]
    assert len(h.goals()) == 3 and len(h.clears()) == (2 if clear else 0)
    assert [s.attempt for s in h.of_type(WaypointStarted)] == [1, 2, 3]
    assert h.executor.result.visits[0].outcome is WaypointOutcome.FAILED
    assert h.executor.result.visits[0].attempts == 3


def test_on_failure_retry_retries_without_limit() -> None:
    h = Harness(line_mission(1, retries=0, on_failure=FailureAction.RETRY))
    h.start(0.0)
    for attempt in range(25):
        h.done("ABORTED", 2.0 * attempt)
        h.tick(2.0 * attempt + 1.0)
    assert len(h.goals()) == 26
    h.succeed(100.0)
    result = h.executor.result
    assert result.success and result.visits[0].attempts == 26


def waits_between_goals(h: Harness, statuses: list[str]) -> list[float]:
    """End each goal with the next status and tick until the retry goes out; the waits."""
    waits = []
    t = 0.0
    for status in statuses:
        h.done(status, t)
        if h.executor.finished:
            break
        sent = len(h.goals())
        failed_at = t
        while len(h.goals()) == sent:
            t += 0.5
            h.tick(t)
        waits.append(t - failed_at)
    return waits


def test_rejected_goals_back_off_longer_each_time_and_end_the_retry_mission() -> None:
    # A stack that refuses every goal (bt_navigator inactive) must not be asked once a
    # second for ever: the waits grow, and after five refusals in a row the mission ends.
    h = Harness(line_mission(2, retries=0, on_failure=FailureAction.RETRY))
    h.start(0.0)
    waits = waits_between_goals(h, ["REJECTED"] * 10)
    assert waits == [1.0, 2.0, 4.0, 8.0, 16.0]
    assert h.executor.finished and len(h.goals()) == 6
    assert [f.will_retry for f in h.of_type(AttemptFailed)] == [True] * 5 + [False]
    result = h.executor.result
    assert outcomes(h) == [WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN]
    assert result.exit_code == 1
    assert result.reason == "stopped: waypoint 1 'p1' failed (REJECTED 6 times in a row)"


def test_rejections_honour_retries_and_the_back_off_stops_growing_at_30_s() -> None:
    h = Harness(line_mission(1, retries=7, on_failure=FailureAction.RETRY))
    h.start(0.0)
    waits = waits_between_goals(h, ["REJECTED"] * 10)
    assert waits == [1.0, 2.0, 4.0, 8.0, 16.0, 30.0, 30.0]
    assert h.executor.finished and len(h.goals()) == 8


def test_an_attempt_that_is_not_rejected_starts_the_count_again() -> None:
    # Between refusals the stack took a goal and aborted it: the stack works again, so
    # the wait is back to one second and the count of refusals starts anew.
    h = Harness(line_mission(1, retries=0, on_failure=FailureAction.RETRY))
    h.start(0.0)
    statuses = ["REJECTED"] * 4 + ["ABORTED"] + ["REJECTED"] * 5
    waits = waits_between_goals(h, statuses)
    assert waits == [1.0, 2.0, 4.0, 8.0, 1.0, 1.0, 2.0, 4.0, 8.0, 16.0]
    assert not h.executor.finished
    h.succeed(200.0)
    assert h.executor.result.success


def test_rejections_under_skip_back_off_too_within_the_retries() -> None:
    h = Harness(line_mission(2, retries=3, on_failure=FailureAction.SKIP))
    h.start(0.0)
    waits = waits_between_goals(h, ["REJECTED"] * 3)
    assert waits == [1.0, 2.0, 4.0]
    h.done("REJECTED", 100.0)  # the retries are used up: the next waypoint at once
    assert outcomes(h)[0] is WaypointOutcome.SKIPPED
    assert h.goals()[-1].goal.pose.x == 2.0


# ---------------------------------------------------------------- pass-through, dwell


def test_pass_through_sends_next_goal_without_cancel() -> None:
    h = Harness(line_mission(3, pass_through_m=0.3))
    h.start(0.0)
    h.feedback(1.0, Pose2D(0.6, 0.0), remaining=0.4)
    assert len(h.goals()) == 1
    commands = h.feedback(1.2, Pose2D(0.75, 0.0), remaining=0.25)
    assert commands == [SendGoal(h.goals()[-1].goal)]
    assert h.goals()[-1].goal.pose.x == 2.0
    finished = h.of_type(WaypointFinished)[0]
    assert finished.outcome is REACHED and finished.passed_through
    # The same through tick poses.
    h.tick(2.0, Pose2D(1.8, 0.0))
    assert h.goals()[-1].goal.pose.x == 3.0
    # The last waypoint always stops: being within the radius is not enough.
    h.tick(3.0, Pose2D(2.9, 0.0))
    h.feedback(3.1, Pose2D(2.95, 0.0), remaining=0.05)
    assert not h.executor.finished
    h.succeed(4.0)
    assert not h.cancels()
    assert [v.passed_through for v in h.executor.result.visits] == [True, True, False]
    assert h.executor.result.success


def test_pass_through_is_off_when_the_waypoint_dwells() -> None:
    h = Harness(line_mission(2, pass_through_m=0.5, dwell_s=3.0))
    h.start(0.0)
    h.feedback(1.0, Pose2D(0.9, 0.0), remaining=0.1)
    assert len(h.goals()) == 1
    h.succeed(2.0)
    assert h.of_type(WaypointDwelling) == [WaypointDwelling(t=2.0, index=0, seconds=3.0)]
    assert h.executor.state is ExecutorState.DWELLING
    assert h.tick(4.9) == []
    commands = h.tick(5.0)
    assert [c.goal.pose.x for c in commands if isinstance(c, SendGoal)] == [2.0]
    visit = h.executor.result.visits[0]
    assert visit.outcome is REACHED and not visit.passed_through
    assert visit.duration == 2.0  # time to reach; the dwell is not travel time


# ---------------------------------------------------------------- loops


def test_loops_n_times_and_passes_through_the_end_of_inner_loops_only() -> None:
    h = Harness(line_mission(2, loops=2, pass_through_m=0.3))
    h.start(0.0)
    h.feedback(1.0, Pose2D(0.8, 0.0), remaining=0.2)  # pass p1 (loop 0)
    h.feedback(2.0, Pose2D(1.8, 0.0), remaining=0.2)  # pass p2: not last, loop 1 follows
    assert [e.loop for e in h.of_type(LoopStarted)] == [0, 1]
    h.feedback(3.0, Pose2D(0.8, 0.0), remaining=0.2)  # pass p1 (loop 1)
    h.feedback(4.0, Pose2D(1.8, 0.0), remaining=0.2)  # last of last loop: must stop
    assert not h.executor.finished
    h.succeed(5.0, pose=Pose2D(2.0, 0.0))
    result = h.executor.result
    assert result.success and result.loops_completed == 2
    assert [(v.loop, v.index) for v in result.visits] == [(0, 0), (0, 1), (1, 0), (1, 1)]
    assert [v.passed_through for v in result.visits] == [True, True, True, False]


def test_forever_loops_until_interrupted() -> None:
    h = Harness(line_mission(2, loops=None))
    h.start(0.0)
    assert h.of_type(MissionStarted)[0].loops is None
    for step in range(7):
        h.succeed(float(step + 1))
    assert [e.loop for e in h.of_type(LoopStarted)] == [0, 1, 2, 3]
    assert not h.executor.finished
    commands = h.interrupt(8.0, "interrupted: SIGINT")
    assert commands == [CancelGoal()]
    result = h.executor.result
    assert h.executor.finished and not result.success
    assert result.reason == "interrupted: SIGINT"
    assert len(result.visits) == 8  # seven reached and the interrupted one
    assert result.visits[-1].outcome is WaypointOutcome.FAILED
    assert result.loops_completed == 3
    assert h.of_type(MissionFinished)[-1].reason == "interrupted: SIGINT"


# ---------------------------------------------------------------- bookkeeping


def test_distance_driven_and_duration_per_visit() -> None:
    h = Harness(line_mission(2))
    h.start(0.0)
    for step in range(1, 5):
        h.tick(float(step), Pose2D(0.25 * step, 0.0))
    h.succeed(4.0)
    h.tick(5.0, Pose2D(1.0, 1.0))  # a 1 m detour...
    h.tick(6.0, Pose2D(2.0, 1.0))
    h.tick(7.0, Pose2D(2.0, 0.0))
    h.succeed(7.5)
    first, second = h.executor.result.visits
    assert first.distance_driven == pytest.approx(0.75)  # the first pose is the baseline
    assert second.distance_driven == pytest.approx(3.0)
    assert (first.duration, second.duration) == (4.0, 3.5)
    assert h.executor.result.distance_driven == pytest.approx(3.75)


def test_interrupt_cancels_and_leaves_the_rest_not_run() -> None:
    h = Harness(line_mission(3))
    h.start(0.0)
    h.succeed(1.0)
    assert h.interrupt(1.5, "interrupted: SIGTERM") == [CancelGoal()]
    assert outcomes(h) == [REACHED, WaypointOutcome.FAILED, WaypointOutcome.NOT_RUN]
    assert h.executor.result.visits[1].reason == "interrupted: SIGTERM"
    assert h.interrupt(2.0, "again") == []  # finished: nothing more to do
    assert h.tick(3.0, Pose2D(0, 0)) == [] and h.succeed(3.0) == []


def test_operator_skip_goes_on_without_cancel_but_cancels_the_last_goal() -> None:
    h = Harness(line_mission(3, on_failure=FailureAction.STOP, dwell_s=2.0))
    h.start(0.0)
    commands = h.skip(1.0)
    assert commands == [SendGoal(h.goals()[-1].goal)]
    assert h.goals()[-1].goal.pose.x == 2.0
    h.succeed(2.0)
    h.skip(2.5)  # while dwelling: it was reached, the dwell is cut short
    assert len(h.executor.result.visits) == 3
    assert h.executor.current_goal is not None and h.executor.current_goal.pose.x == 3.0
    assert h.skip(3.0, "operator says no") == [CancelGoal()]
    result = h.executor.result
    assert h.executor.finished and not result.success
    assert outcomes(h) == [WaypointOutcome.SKIPPED, REACHED, WaypointOutcome.SKIPPED]
    assert result.visits[2].reason == "operator says no"


def test_resume_starts_at_the_resume_point_and_keeps_earlier_visits() -> None:
    done = tuple(
        WaypointResult(index=i, loop=0, name=None, x=0, y=0, yaw_rad=0, outcome=REACHED, attempts=1)
        for i in range(2)
    )
    h = Harness(line_mission(3), resume=ResumePoint(loop=0, index=2, done=done))
    h.start(0.0)
    assert [g.goal.pose.x for g in h.goals()] == [3.0]
    assert h.of_type(MissionStarted)[0].resumed_from == 2
    h.succeed(2.0)
    result = h.executor.result
    assert result.success
    assert [v.name for v in result.visits] == ["p1", "p2", "p3"]
    assert [v.x for v in result.visits] == [1.0, 2.0, 3.0]


@pytest.mark.parametrize("point", [ResumePoint(loop=0, index=3), ResumePoint(loop=1, index=0)])
def test_resume_point_outside_the_mission_is_a_user_error(point: ResumePoint) -> None:
    with pytest.raises(NavseqError, match="journal resumes"):
        Harness(line_mission(3), resume=point)
