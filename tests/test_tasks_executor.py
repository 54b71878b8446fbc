"""The executor runs a reached waypoint's tasks in order, times them out, and lets the
waypoint's on_failure, the operator's pause / skip / cancel act on them (no I/O: it
returns StartTask / CancelTask and takes TaskDone)."""

from __future__ import annotations

from helpers_executor import Harness, line_mission
from navseq.executor.events import TaskFinished, TaskStarted, WaypointOutcome
from navseq.executor.states import ExecutorState
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction
from navseq.mission.tasks import InputTask, RunTask, WaitTask

AT_P1 = Pose2D(1.0, 0.0, 0.0)
TASKS = (WaitTask(1.0), RunTask(("true",), timeout_s=10.0))


def at_first_task(**policy: object) -> Harness:
    h = Harness(line_mission(2, tasks=TASKS, **policy))  # type: ignore[arg-type]
    h.start(0.0)
    h.succeed(5.0, pose=AT_P1)
    return h


def test_tasks_run_in_order_after_arrival_then_the_next_goal_goes() -> None:
    h = at_first_task()
    assert [c.task for c in h.started_tasks()] == [TASKS[0]]
    assert len(h.goals()) == 1  # the robot stays while its tasks run
    h.task_done(6.0)
    assert [c.task for c in h.started_tasks()] == list(TASKS)
    h.task_done(7.5, detail="exit status 0")
    assert len(h.goals()) == 2
    visit = h.executor.result.visits[0]
    assert visit.outcome is WaypointOutcome.REACHED
    assert [(t.kind, t.outcome, t.duration, t.detail) for t in visit.tasks] == [
        ("wait", "succeeded", 1.0, ""),
        ("run", "succeeded", 1.5, "exit status 0"),
    ]
    assert [e.task for e in h.of_type(TaskStarted)] == [1, 2]


def test_dwell_is_a_leading_wait() -> None:
    h = Harness(line_mission(1, dwell_s=3.0, tasks=(InputTask("ok?"),)))
    h.start(0.0)
    h.succeed(5.0, pose=AT_P1)
    h.tick(7.0)
    assert h.started_tasks() == []
    h.tick(8.0)
    assert len(h.started_tasks()) == 1


def test_a_task_over_its_timeout_is_cancelled_and_stops_the_mission() -> None:
    h = at_first_task()
    h.task_done(6.0)
    h.tick(15.0)
    assert h.cancelled_tasks() == []
    h.tick(16.0)  # 10 s after the run task started
    assert [c.task_id for c in h.cancelled_tasks()] == [h.started_tasks()[-1].task_id]
    result = h.executor.result
    assert result.visits[0].outcome is WaypointOutcome.FAILED
    assert result.visits[0].tasks[-1].outcome == "timed_out"
    assert result.reason.startswith("stopped: waypoint 1 'p1' failed (task 2 (run) timed out")
    assert h.executor.finished and len(h.goals()) == 1


def test_a_failed_task_under_skip_skips_the_visit_and_goes_on() -> None:
    h = at_first_task(on_failure=FailureAction.SKIP)
    h.task_done(6.0, succeeded=False, detail="exit status 3")
    visit = h.executor.result.visits[0]
    assert visit.outcome is WaypointOutcome.SKIPPED
    assert visit.reason == "task 1 (wait) failed: exit status 3"
    assert len(h.goals()) == 2 and len(h.started_tasks()) == 1  # task 2 never ran


def test_retries_run_the_failed_task_again_without_driving() -> None:
    h = at_first_task(retries=1)
    h.task_done(6.0, succeeded=False, detail="no")
    assert h.of_type(TaskFinished)[-1].will_retry
    h.tick(6.5)
    assert len(h.started_tasks()) == 1  # a back-off first
    h.tick(7.0)
    assert [(c.number, c.task_id) for c in h.started_tasks()] == [(1, 1), (1, 2)]
    assert h.of_type(TaskStarted)[-1].attempt == 2
    h.task_done(8.0, succeeded=False, detail="no again")
    assert h.executor.finished  # retries used up; on_failure stop
    assert len(h.goals()) == 1


def test_on_failure_retry_runs_the_task_again_until_it_succeeds() -> None:
    h = at_first_task(on_failure=FailureAction.RETRY)
    for attempt in range(4):
        h.task_done(6.0 + 2 * attempt, succeeded=False)
        h.tick(7.0 + 2 * attempt)
    assert len(h.started_tasks()) == 5
    h.task_done(20.0)
    assert [t.outcome for t in h.executor.result.visits[0].tasks] == [
        *["failed"] * 4,
        "succeeded",
    ]


def test_a_late_report_of_a_cancelled_task_is_ignored() -> None:
    h = at_first_task()
    old = h.started_tasks()[-1].task_id
    h.pause(5.5)
    h.resume(6.0)
    h.task_done(6.1, task_id=old)
    assert len(h.started_tasks()) == 2 and h.executor.state is ExecutorState.RUNNING_TASK


def test_pause_cancels_the_task_and_resume_runs_it_again() -> None:
    h = at_first_task()
    h.task_done(6.0)
    running = h.started_tasks()[-1]
    h.pause(9.0)
    assert [c.task_id for c in h.cancelled_tasks()] == [running.task_id]
    h.tick(100.0)  # no timeout runs while paused
    assert not h.executor.finished
    h.resume(200.0)
    again = h.started_tasks()[-1]
    assert again.task == running.task and again.task_id != running.task_id
    h.tick(205.0)
    assert not h.executor.finished  # the timeout counts from the new start
    h.task_done(206.0)
    assert h.executor.result.visits[0].outcome is WaypointOutcome.REACHED


def test_skip_cancels_the_running_task_and_goes_on() -> None:
    h = at_first_task()
    h.skip(5.5)
    assert len(h.cancelled_tasks()) == 1 and len(h.goals()) == 2
    visit = h.executor.result.visits[0]
    assert visit.outcome is WaypointOutcome.SKIPPED
    assert visit.tasks[0].outcome == "cancelled"


def test_cancel_cancels_the_running_task() -> None:
    h = at_first_task()
    commands = h.executor.cancel(5.5)
    assert any(c.__class__.__name__ == "CancelTask" for c in commands)
    assert h.executor.result.visits[0].outcome is WaypointOutcome.FAILED


def test_passing_through_never_skips_tasks() -> None:
    """Built by hand (files refuse it): a pass-through waypoint with tasks stops there."""
    h = Harness(line_mission(2, pass_through_m=0.5, tasks=(WaitTask(1.0),)))
    h.start(0.0)
    h.tick(1.0, pose=Pose2D(0.8, 0.0, 0.0))
    assert len(h.goals()) == 1
    h.succeed(3.0, pose=AT_P1)
    assert len(h.started_tasks()) == 1
