"""A retry's recoveries: run in order after the back-off, then the goal again; each
timed out, reported, and stopped by a pause, a skip or a cancel."""

from __future__ import annotations

from helpers_executor import Harness, line_mission
from navseq.executor.events import RecoveryFinished, RecoveryStarted
from navseq.mission.recovery import RECOVERY_TIMEOUT_S, Recovery

SPIN, BACKUP, CLEAR = Recovery("spin", 90.0), Recovery("backup", 0.15), Recovery("clear_costmaps")


def failed_once(*recoveries: Recovery, retries: int = 1) -> Harness:
    h = Harness(line_mission(2, retries=retries, recoveries=recoveries))
    h.start(0.0)
    h.done("ABORTED", 2.0)
    return h


def test_recoveries_run_in_order_after_the_back_off_then_the_retry() -> None:
    h = failed_once(SPIN, BACKUP, CLEAR)
    assert h.recoveries_run() == []  # the back-off first: the stack is not hammered
    h.tick(3.0)
    h.recovery_done(5.0)
    h.recovery_done(6.0)
    assert len(h.goals()) == 1  # no goal while the robot recovers
    h.recovery_done(6.1)
    assert [c.recovery for c in h.recoveries_run()] == [SPIN, BACKUP, CLEAR]
    assert len(h.goals()) == 2
    started = h.of_type(RecoveryStarted)
    assert [(e.recovery, e.recovery_kind, e.attempt) for e in started] == [
        (1, "spin", 2),
        (2, "backup", 2),
        (3, "clear_costmaps", 2),
    ]
    visit = h.executor.result.visits[0]
    assert [(r.kind, r.outcome, r.attempt) for r in visit.recoveries] == [
        ("spin", "succeeded", 2),
        ("backup", "succeeded", 2),
        ("clear_costmaps", "succeeded", 2),
    ]


def test_a_failed_recovery_is_recorded_and_the_next_goes_ahead() -> None:
    h = failed_once(SPIN, BACKUP)
    h.tick(3.0)
    h.recovery_done(4.0, succeeded=False, detail="COLLISION_AHEAD")
    assert [c.recovery for c in h.recoveries_run()] == [SPIN, BACKUP]
    finished = h.of_type(RecoveryFinished)
    assert (finished[0].outcome, finished[0].detail) == ("failed", "COLLISION_AHEAD")


def test_a_recovery_without_end_times_out_and_is_stopped() -> None:
    h = failed_once(SPIN)
    h.tick(3.0)
    h.tick(3.0 + RECOVERY_TIMEOUT_S - 0.5)
    assert h.recoveries_cancelled() == []
    h.tick(3.0 + RECOVERY_TIMEOUT_S)
    assert len(h.recoveries_cancelled()) == 1
    assert h.of_type(RecoveryFinished)[-1].outcome == "timed_out"
    assert len(h.goals()) == 2  # the retry goes ahead


def test_no_recovery_runs_when_no_retry_follows() -> None:
    h = failed_once(SPIN, retries=0)
    h.tick(10.0)
    assert h.recoveries_run() == []


def test_recoveries_run_before_every_retry() -> None:
    h = failed_once(SPIN, retries=2)
    h.tick(3.0)
    h.recovery_done(4.0)
    h.done("ABORTED", 6.0)
    h.tick(7.5)
    assert len(h.recoveries_run()) == 2
    assert h.of_type(RecoveryStarted)[-1].attempt == 3


def test_a_late_end_of_a_stopped_recovery_is_ignored() -> None:
    h = failed_once(SPIN, BACKUP)
    h.tick(3.0)
    h.pause(4.0)
    assert len(h.recoveries_cancelled()) == 1  # the robot stops
    h.recovery_done(4.5)  # the cancelled spin's end arrives late
    assert len(h.recoveries_run()) == 1 and len(h.goals()) == 1
    h.resume(6.0)
    assert [c.recovery for c in h.recoveries_run()] == [SPIN, SPIN]  # again from its start


def test_skip_during_a_recovery_stops_it_and_goes_on() -> None:
    h = failed_once(SPIN)
    h.tick(3.0)
    h.skip(4.0)
    assert len(h.recoveries_cancelled()) == 1
    assert h.goals()[-1].goal.pose.x == 2.0
    assert h.of_type(RecoveryFinished)[-1].outcome == "cancelled"


def test_cancel_during_a_recovery_stops_the_robot() -> None:
    h = failed_once(SPIN)
    h.tick(3.0)
    commands = h.executor.cancel(4.0, "cancelled by operator")
    assert {type(c).__name__ for c in commands} == {"CancelGoal", "CancelRecovery"}
    assert h.executor.finished
    assert h.of_type(RecoveryFinished)[-1].outcome == "cancelled"
