"""The executor's transition table is the rule: every entry is taken, nothing else is.

Each entry of ``TRANSITIONS`` has a scenario below that drives a real executor (by
hand, as a navigator would) through that very (state, trigger) pair; the spy records
every state change the executor makes, so a state changed behind the table's back, or
an entry no run can reach, fails here.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from helpers_executor import Harness, line_mission
from navseq.executor import machine
from navseq.executor.events import MissionFinished, WaypointOutcome
from navseq.executor.states import (
    TRANSITIONS,
    ExecutorState,
    InvalidTransition,
    Trigger,
    next_state,
)
from navseq.geometry import Pose2D
from navseq.mission.model import FailureAction
from navseq.mission.recovery import Recovery
from navseq.mission.tasks import InputTask, WaitTask

S, T = ExecutorState, Trigger
AT_P1 = Pose2D(1.0, 0.0, 0.0)  # line_mission's first waypoint


def reached_p1(h: Harness, t: float = 5.0) -> None:
    h.succeed(t, pose=AT_P1)


def dwelling(dwell: float = 5.0, count: int = 2) -> Harness:
    h = Harness(line_mission(count, dwell_s=dwell))
    h.start(0.0)
    reached_p1(h)
    assert h.executor.state is S.DWELLING
    return h


def backing_off(count: int = 2) -> Harness:
    h = Harness(line_mission(count, retries=1))
    h.start(0.0)
    h.done("ABORTED", 2.0)
    assert h.executor.state is S.WAITING_RETRY
    return h


def waiting_for_server(count: int = 2, server_timeout: float = 30.0) -> Harness:
    h = Harness(line_mission(count, server_timeout=server_timeout))
    h.start(0.0)
    h.server_lost(1.0)
    assert h.executor.state is S.WAITING_SERVER
    return h


def paused(h: Harness, t: float = 3.0) -> Harness:
    h.pause(t)
    assert h.executor.state is S.PAUSED
    return h


def started(count: int = 2) -> Harness:
    h = Harness(line_mission(count))
    h.start(0.0)
    return h


def start_while_server_is_away() -> Harness:
    h = Harness(line_mission(2))
    h.server_lost(0.0)
    h.start(0.0)
    assert h.goals() == []  # nothing is sent to a server that is not there
    return h


def interrupt_before_start() -> Harness:
    h = Harness(line_mission(2))
    h.interrupt(0.0, "interrupted: SIGINT")
    return h


def reach_first_of_two() -> Harness:
    h = started()
    reached_p1(h)
    assert h.goals()[-1].goal.pose == Pose2D(2.0, 0.0, 0.0)
    return h


def reach_the_only_waypoint() -> Harness:
    h = started(1)
    reached_p1(h)
    assert h.executor.result.success
    return h


def dwell_then_next() -> Harness:
    h = dwelling()
    h.tick(10.0)
    assert len(h.goals()) == 2
    return h


def dwell_then_server_gone() -> Harness:
    h = dwelling()
    h.server_lost(6.0)
    h.tick(10.0)
    assert len(h.goals()) == 1
    return h


def interrupt_dwell() -> Harness:
    h = dwelling()
    h.interrupt(6.0, "interrupted: SIGTERM")
    return h


def backoff_then_retry() -> Harness:
    h = backing_off()
    h.tick(3.0)
    assert len(h.goals()) == 2 and h.executor.result.visits[0].attempts == 2
    return h


def backoff_then_server_gone() -> Harness:
    h = backing_off()
    h.server_lost(2.5)
    h.tick(3.0)
    assert len(h.goals()) == 1
    return h


def interrupt_backoff() -> Harness:
    h = backing_off()
    h.interrupt(2.5, "interrupted: SIGINT")
    return h


def server_back() -> Harness:
    h = waiting_for_server()
    h.server_back(2.0)
    assert len(h.goals()) == 2 and h.executor.result.visits[0].attempts == 1
    return h


def skip_while_server_is_away() -> Harness:
    h = waiting_for_server()
    h.skip(2.0)
    assert h.executor.result.visits[0].outcome is WaypointOutcome.SKIPPED
    return h


def server_never_back() -> Harness:
    h = waiting_for_server(server_timeout=5.0)
    h.tick(6.0)
    assert h.of_type(MissionFinished)[-1].reason == "navigation server lost"
    return h


def resume_active() -> Harness:
    h = paused(started())
    h.resume(10.0)
    assert len(h.goals()) == 2
    return h


def resume_while_server_is_away() -> Harness:
    h = paused(started())
    h.server_lost(4.0)
    h.resume(10.0)
    assert len(h.goals()) == 1
    return h


def resume_dwell() -> Harness:
    h = paused(dwelling(), t=6.0)
    h.resume(20.0)
    return h


def resume_backoff() -> Harness:
    h = paused(backing_off(), t=2.5)
    h.resume(20.0)
    return h


def interrupt_pause() -> Harness:
    h = paused(started())
    h.interrupt(4.0, "interrupted: SIGINT")
    return h


def stop_on_failure() -> Harness:
    h = Harness(line_mission(2, on_failure=FailureAction.STOP))
    h.start(0.0)
    h.done("ABORTED", 1.0)
    return h


TWO_TASKS = (WaitTask(1.0), InputTask("go on?"))


def running_task(count: int = 2) -> Harness:
    h = Harness(line_mission(count, tasks=TWO_TASKS))
    h.start(0.0)
    reached_p1(h)
    assert h.executor.state is S.RUNNING_TASK
    return h


def dwell_then_task() -> Harness:
    h = Harness(line_mission(2, dwell_s=2.0, tasks=TWO_TASKS))
    h.start(0.0)
    reached_p1(h)
    h.tick(8.0)
    assert len(h.started_tasks()) == 1
    return h


def next_task() -> Harness:
    h = running_task()
    h.task_done(6.0)
    assert [c.number for c in h.started_tasks()] == [1, 2]
    return h


def tasks_done_then_next() -> Harness:
    h = next_task()
    h.task_done(7.0)
    assert len(h.goals()) == 2
    return h


def tasks_done_then_server_gone() -> Harness:
    h = next_task()
    h.server_lost(6.5)
    h.task_done(7.0)
    assert len(h.goals()) == 1 and h.executor.state is S.WAITING_SERVER
    return h


def interrupt_task() -> Harness:
    h = running_task()
    h.interrupt(6.0, "interrupted: SIGINT")
    assert len(h.cancelled_tasks()) == 1
    return h


def resume_task() -> Harness:
    h = paused(running_task(), t=6.0)
    h.resume(9.0)
    assert [c.number for c in h.started_tasks()] == [1, 1]
    return h


TWO_RECOVERIES = (Recovery("spin", 90.0), Recovery("backup", 0.15))


def recovering() -> Harness:
    h = Harness(line_mission(2, retries=1, recoveries=TWO_RECOVERIES))
    h.start(0.0)
    h.done("ABORTED", 2.0)
    h.tick(3.0)  # the back-off is over: the first recovery runs
    assert h.executor.state is S.RECOVERING and len(h.recoveries_run()) == 1
    return h


def next_recovery() -> Harness:
    h = recovering()
    h.recovery_done(5.0)
    assert [c.recovery.kind for c in h.recoveries_run()] == ["spin", "backup"]
    return h


def recoveries_done_then_retry() -> Harness:
    h = next_recovery()
    h.recovery_done(7.0)
    assert len(h.goals()) == 2 and h.executor.result.visits[0].attempts == 2
    return h


def recoveries_done_then_server_gone() -> Harness:
    h = next_recovery()
    h.server_lost(6.0)
    h.recovery_done(7.0)
    assert len(h.goals()) == 1 and h.executor.state is S.WAITING_SERVER
    return h


def interrupt_recovery() -> Harness:
    h = recovering()
    h.interrupt(4.0, "interrupted: SIGINT")
    assert len(h.recoveries_cancelled()) == 1 and len(h.cancels()) == 1
    return h


def resume_recovery() -> Harness:
    h = paused(recovering(), t=4.0)
    h.resume(9.0)
    assert [c.recovery.kind for c in h.recoveries_run()] == ["spin", "spin"]
    return h


#: One scenario per table entry; each must take its entry at least once.
SCENARIOS: dict[tuple[ExecutorState, Trigger], Callable[[], Harness]] = {
    (S.IDLE, T.GOAL_SENT): started,
    (S.IDLE, T.SERVER_AWAY): start_while_server_is_away,
    (S.IDLE, T.END): interrupt_before_start,
    (S.ACTIVE, T.GOAL_SENT): reach_first_of_two,
    (S.ACTIVE, T.SERVER_AWAY): waiting_for_server,
    (S.ACTIVE, T.DWELL): dwelling,
    (S.ACTIVE, T.TASK): running_task,
    (S.ACTIVE, T.RETRY_LATER): backing_off,
    (S.ACTIVE, T.PAUSE): lambda: paused(started()),
    (S.ACTIVE, T.END): stop_on_failure,
    (S.DWELLING, T.GOAL_SENT): dwell_then_next,
    (S.DWELLING, T.SERVER_AWAY): dwell_then_server_gone,
    (S.DWELLING, T.PAUSE): lambda: paused(dwelling(), t=6.0),
    (S.DWELLING, T.END): interrupt_dwell,
    (S.DWELLING, T.TASK): dwell_then_task,
    (S.RUNNING_TASK, T.TASK): next_task,
    (S.RUNNING_TASK, T.GOAL_SENT): tasks_done_then_next,
    (S.RUNNING_TASK, T.SERVER_AWAY): tasks_done_then_server_gone,
    (S.RUNNING_TASK, T.PAUSE): lambda: paused(running_task(), t=6.0),
    (S.RUNNING_TASK, T.END): interrupt_task,
    (S.WAITING_RETRY, T.GOAL_SENT): backoff_then_retry,
    (S.WAITING_RETRY, T.SERVER_AWAY): backoff_then_server_gone,
    (S.WAITING_RETRY, T.PAUSE): lambda: paused(backing_off(), t=2.5),
    (S.WAITING_RETRY, T.END): interrupt_backoff,
    (S.WAITING_SERVER, T.GOAL_SENT): server_back,
    (S.WAITING_SERVER, T.SERVER_AWAY): skip_while_server_is_away,
    (S.WAITING_SERVER, T.PAUSE): lambda: paused(waiting_for_server()),
    (S.WAITING_SERVER, T.END): server_never_back,
    (S.PAUSED, T.GOAL_SENT): resume_active,
    (S.PAUSED, T.SERVER_AWAY): resume_while_server_is_away,
    (S.PAUSED, T.DWELL_GOES_ON): resume_dwell,
    (S.PAUSED, T.BACKOFF_GOES_ON): resume_backoff,
    (S.PAUSED, T.END): interrupt_pause,
    (S.PAUSED, T.TASK): resume_task,
    (S.WAITING_RETRY, T.RECOVER): recovering,
    (S.RECOVERING, T.RECOVER): next_recovery,
    (S.RECOVERING, T.GOAL_SENT): recoveries_done_then_retry,
    (S.RECOVERING, T.SERVER_AWAY): recoveries_done_then_server_gone,
    (S.RECOVERING, T.PAUSE): lambda: paused(recovering(), t=4.0),
    (S.RECOVERING, T.END): interrupt_recovery,
    (S.PAUSED, T.RECOVER): resume_recovery,
}

Taken = list[tuple[ExecutorState, Trigger, ExecutorState]]


@pytest.fixture
def taken(monkeypatch: pytest.MonkeyPatch) -> Taken:
    """Every state change the executor makes from now on, in order."""
    changes: Taken = []

    def spy(state: ExecutorState, trigger: Trigger) -> ExecutorState:
        after = next_state(state, trigger)
        changes.append((state, trigger, after))
        return after

    monkeypatch.setattr(machine, "next_state", spy)
    return changes


@pytest.mark.parametrize(
    "entry", list(TRANSITIONS), ids=[f"{s.name}-{t.name}" for s, t in TRANSITIONS]
)
def test_every_table_entry_is_taken_by_a_real_run(
    entry: tuple[ExecutorState, Trigger], taken: Taken
) -> None:
    assert entry in SCENARIOS, f"no scenario reaches {entry}"
    h = SCENARIOS[entry]()
    assert entry in [(before, trigger) for before, trigger, _ in taken]
    # The state the executor reports is the one the table led to: no change bypassed it.
    assert h.executor.state is taken[-1][2]


def test_no_scenario_names_a_transition_the_table_lacks() -> None:
    assert set(SCENARIOS) == set(TRANSITIONS)


def test_a_whole_mission_changes_state_only_through_the_table(taken: Taken) -> None:
    h = Harness(line_mission(3, retries=1, dwell_s=1.0, server_timeout=60.0))
    seen = [h.executor.state]
    h.start(0.0)
    h.done("ABORTED", 1.0)
    h.tick(2.5)
    h.server_lost(3.0)
    h.server_back(4.0)
    h.pause(5.0)
    h.resume(6.0)
    reached_p1(h, 7.0)
    h.tick(8.5)
    h.skip(9.0)
    h.succeed(10.0, pose=Pose2D(3.0, 0.0, 0.0))
    h.tick(11.5)
    assert h.executor.finished
    seen.extend(after for _, _, after in taken)
    for (before, trigger, after), previous in zip(taken, seen, strict=False):
        assert before is previous and TRANSITIONS[before, trigger] is after


INVALID = [
    (state, trigger)
    for state in ExecutorState
    for trigger in Trigger
    if (state, trigger) not in TRANSITIONS
]


@pytest.mark.parametrize("state, trigger", INVALID, ids=[f"{s.name}-{t.name}" for s, t in INVALID])
def test_an_invalid_trigger_raises_naming_it_and_the_state(
    state: ExecutorState, trigger: Trigger
) -> None:
    with pytest.raises(InvalidTransition) as caught:
        next_state(state, trigger)
    assert trigger.name in str(caught.value) and state.name in str(caught.value)
    assert (caught.value.state, caught.value.trigger) == (state, trigger)


def test_a_finished_run_goes_nowhere_and_every_other_state_can_end() -> None:
    assert not [key for key in TRANSITIONS if key[0] is S.FINISHED]
    for state in ExecutorState:
        if state is not S.FINISHED:
            assert next_state(state, T.END) is S.FINISHED


def test_an_executor_bug_that_takes_an_invalid_trigger_says_which(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # A table that forgot how a dwell begins: reaching a dwelling waypoint is refused
    # with the pair named, not a silent jump to some state.
    broken = {key: after for key, after in TRANSITIONS.items() if key != (S.ACTIVE, T.DWELL)}
    monkeypatch.setattr("navseq.executor.states.TRANSITIONS", broken)
    h = Harness(line_mission(2, dwell_s=5.0))
    h.start(0.0)
    with pytest.raises(InvalidTransition, match=r"DWELL .*in state ACTIVE"):
        reached_p1(h)
