"""A goal the fleet holds back (GoalHeld .. GoalReleased from the navigator): its timeout
and stall clocks stand still while the robot waits or gives way to another robot, the
result keeps the time held, and the sinks hear when the hold began and ended."""

from __future__ import annotations

from pathlib import Path

from helpers_executor import Harness, line_mission
from navseq.executor.events import (
    AttemptFailed,
    WaypointHeld,
    WaypointOutcome,
    WaypointReleased,
)
from navseq.geometry import Pose2D
from navseq.journal.writer import JournalWriter, read_journal
from navseq.mission.model import FailureAction
from navseq.navigators.base import GoalHeld, GoalReleased


def held(h: Harness, t: float, reason: str = "giving way to r1", goal_id: int | None = None):
    gid = h.goal_id if goal_id is None else goal_id
    return h._keep(h.executor.on_event(GoalHeld(gid, reason), t))


def released(h: Harness, t: float, goal_id: int | None = None):
    gid = h.goal_id if goal_id is None else goal_id
    return h._keep(h.executor.on_event(GoalReleased(gid), t))


def test_time_held_does_not_count_against_the_goal_timeout() -> None:
    h = Harness(line_mission(1, goal_timeout_s=10.0))
    h.start(0.0)
    h.tick(4.0)
    held(h, 4.0)
    assert h.tick(40.0) == []  # 36 s of giving way: no timeout
    released(h, 40.0)
    assert h.tick(45.0) == []  # 4 + 5 s of its own
    h.tick(46.0)  # 10 s of its own: out of time
    [failure] = h.of_type(AttemptFailed)
    assert failure.reason == "timeout" and failure.duration == 46.0
    visit = h.executor.result.visits[0]
    assert visit.attempt_results[0].held == 36.0 and visit.held_s == 36.0
    assert h.of_type(WaypointHeld) == [WaypointHeld(4.0, 0, 0, "giving way to r1")]
    assert h.of_type(WaypointReleased) == [WaypointReleased(40.0, 0, 0, 36.0)]


def test_time_held_does_not_count_against_the_stall_timeout() -> None:
    h = Harness(line_mission(1, stall_timeout_s=5.0))
    h.start(0.0)
    h.tick(0.5, Pose2D(0.0, 0.0, 0.0))
    h.tick(3.0, Pose2D(0.5, 0.0, 0.0))  # progress at 3 s
    held(h, 3.5)
    # Sent aside: driving away from the goal is neither progress nor its loss.
    for t in range(4, 30):
        assert h.tick(float(t), Pose2D(0.5, 1.0 + t / 100, 0.0)) == []
    released(h, 30.0)
    # Back on its way from the refuge: progress is judged afresh, the stall clock goes
    # on from where it stood (0.5 s of 5 gone before the hold).
    assert h.tick(30.5, Pose2D(0.5, 1.2, 0.0)) == []
    assert h.tick(34.0, Pose2D(0.5, 1.2, 0.0)) == []
    h.tick(34.5, Pose2D(0.5, 1.2, 0.0))
    assert [f.reason for f in h.of_type(AttemptFailed)] == ["stalled"]


def test_an_attempt_that_ends_while_held_keeps_the_time_held() -> None:
    h = Harness(line_mission(2, on_failure=FailureAction.SKIP))
    h.start(0.0)
    held(h, 2.0)
    h.done("ABORTED", 12.0)
    visit = h.executor.result.visits[0]
    assert visit.outcome is WaypointOutcome.SKIPPED
    assert visit.attempt_results[0].held == 10.0
    assert h.of_type(WaypointReleased) == [WaypointReleased(12.0, 0, 0, 10.0)]
    # The next waypoint's goal starts unheld: its clocks run.
    assert h.executor.result.visits[1].held_s == 0.0


def test_holds_of_other_goals_and_repeated_holds_are_ignored() -> None:
    h = Harness(line_mission(1, goal_timeout_s=10.0))
    h.start(0.0)
    held(h, 1.0, goal_id=h.goal_id + 5)  # not the goal out
    held(h, 2.0)
    held(h, 3.0)  # already held: the hold began at 2 s
    released(h, 6.0, goal_id=h.goal_id + 5)
    released(h, 7.0)
    released(h, 8.0)  # not held: nothing
    assert h.of_type(WaypointHeld) == [WaypointHeld(2.0, 0, 0, "giving way to r1")]
    assert h.of_type(WaypointReleased) == [WaypointReleased(7.0, 0, 0, 5.0)]
    assert h.tick(14.9) == []
    h.tick(15.0)
    assert [f.reason for f in h.of_type(AttemptFailed)] == ["timeout"]


def test_a_pause_while_held_ends_the_hold_and_the_goal_sent_again_runs_its_clocks() -> None:
    h = Harness(line_mission(1, goal_timeout_s=10.0))
    h.start(0.0)
    held(h, 2.0)
    h.pause(5.0)
    assert h.of_type(WaypointReleased) == [WaypointReleased(5.0, 0, 0, 3.0)]
    h.resume(100.0)
    # 2 s of its own before the hold, 95 s paused: 8 s are left from 100 s.
    assert h.tick(107.9) == []
    h.tick(108.0)
    assert [f.reason for f in h.of_type(AttemptFailed)] == ["timeout"]


def test_the_journal_keeps_the_time_held_for_a_rebuilt_report(tmp_path: Path) -> None:
    path = tmp_path / "journal.jsonl"
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        h = Harness(line_mission(2, retries=1))
        h.executor.add_listener(journal)
        h.start(0.0)
        held(h, 1.0)
        released(h, 4.0)
        h.done("ABORTED", 5.0)  # attempt 1: 3 s held
        h.tick(6.0)  # the retry goes out
        held(h, 7.0)
        h.succeed(9.5)  # attempt 2 reached while held: 2.5 s
        held(h, 10.0)
        released(h, 10.5)
        h.succeed(12.0)
    [first, second] = read_journal(path).visits.held()
    assert [a.held for a in first.attempt_results] == [3.0, 2.5]
    assert first.held_s == 5.5 and second.held_s == 0.5
    assert [a.held for a in h.executor.result.visits[0].attempt_results] == [3.0, 2.5]


def test_a_person_reads_when_and_for_whom_the_robot_was_held() -> None:
    from navseq.sinks.progress import RunView, describe

    view = RunView(line_mission(1))
    hold = WaypointHeld(2.0, 0, 0, "giving way to r1")
    release = WaypointReleased(9.5, 0, 0, 7.5)
    assert describe(hold, view) == "waypoint 1/1 'p1': held back by the fleet (giving way to r1)"
    assert describe(release, view) == (
        "waypoint 1/1 'p1': on its way again after 7.5 s held (not counted against its timeouts)"
    )


def test_the_hold_events_as_json_records_follow_the_events_schema() -> None:
    from navseq.sinks.json_events import event_record
    from test_json_schemas import problems, validator

    check = validator("events")
    held_record = event_record(WaypointHeld(2.0, 0, 0, "giving way to r1"))
    released_record = event_record(WaypointReleased(9.5, 0, 0, 7.5))
    assert problems(check, held_record) == [] and problems(check, released_record) == []
    assert released_record["held_s"] == 7.5  # the report's name for it
