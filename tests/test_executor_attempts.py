"""Say why: every attempt keeps the stack's status and text, its time and distance.

move_base's result text ("Failed to find a valid plan. Even after executing recovery
behaviors.") used to be dropped; the output said only ABORTED.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import pytest
from rich.console import Console

from helpers_executor import Harness, line_mission
from navseq.executor.events import AttemptFailed, MissionEvent, WaypointOutcome
from navseq.executor.result import AttemptResult
from navseq.executor.runner import run_mission
from navseq.geometry import Pose2D
from navseq.journal.reader import journal_events
from navseq.journal.writer import JournalWriter, read_journal, resume_point
from navseq.mission.model import FailureAction
from navseq.navigators.scripted import Finish, ScriptedNavigator, Stall, Succeed
from navseq.sinks.json_events import JsonProgress
from navseq.sinks.progress import LogProgress
from navseq.sinks.report import build_report
from navseq.sinks.summary import summary_table

NO_PLAN = "Failed to find a valid plan. Even after executing recovery behaviors."


def run_with_a_failing_first_attempt(listeners: list = ()):  # type: ignore[no-untyped-def,type-arg]
    navigator = ScriptedNavigator(
        [Finish("ABORTED", after=2.0, text=NO_PLAN), Succeed(), Stall(), Stall()],
        speed=0.25,
        step=0.05,
    )
    mission = line_mission(3, retries=1, stall_timeout_s=3.0, on_failure=FailureAction.SKIP)
    return mission, run_mission(mission, navigator, listeners)


def test_attempts_keep_status_reason_text_duration_and_distance() -> None:
    _, result = run_with_a_failing_first_attempt()
    first, second = result.visits[0], result.visits[1]
    assert first.outcome is WaypointOutcome.REACHED and first.attempts == 2
    aborted, reached = first.attempt_results
    assert (aborted.number, aborted.status, aborted.reason, aborted.text) == (
        1, "ABORTED", "ABORTED", NO_PLAN,
    )  # fmt: skip
    assert aborted.duration == pytest.approx(2.0, abs=0.11)
    assert aborted.distance_driven == pytest.approx(0.5, abs=0.03)  # 2 s at 0.25 m/s
    assert reached.reached and reached.status == "SUCCEEDED" and reached.reason == ""
    # Distance is sampled every tick: what the robot rolled in the tick that ended an
    # attempt counts for the visit, not for either attempt.
    unattributed = first.distance_driven - (aborted.distance_driven + reached.distance_driven)
    assert 0.0 <= unattributed <= 0.03
    # The second waypoint stalls twice: navseq gave up on both goals, no stack status.
    assert second.outcome is WaypointOutcome.SKIPPED
    assert [(a.status, a.reason) for a in second.attempt_results] == [
        (None, "stalled"),
        (None, "stalled"),
    ]


def test_report_lists_every_attempt_of_every_visit() -> None:
    mission, result = run_with_a_failing_first_attempt()
    report = build_report(mission, result, exit_code=result.exit_code, navigator={})
    attempts = report["visits"][0]["attempts"]
    assert [a["number"] for a in attempts] == [1, 2]
    assert attempts[0]["status"] == "ABORTED" and attempts[0]["text"] == NO_PLAN
    assert set(attempts[0]) == {
        "number", "reached", "status", "reason", "text", "duration_s", "distance_m", "recoveries",
        "held_s",
    }  # fmt: skip
    assert report["visits"][1]["attempts"][1]["status"] is None
    assert [a["reached"] for a in report["visits"][2]["attempts"]] == [True]


def test_summary_table_says_why_a_visit_was_not_reached() -> None:
    mission = line_mission(2, on_failure=FailureAction.SKIP)
    h = Harness(mission)
    h.start(0.0)
    h.done("ABORTED", 3.0, text=NO_PLAN)
    h.succeed(6.0)
    console = Console(file=io.StringIO(), width=250)
    console.print(summary_table(mission, h.executor.result))
    text = console.file.getvalue()  # type: ignore[attr-defined]
    assert f"ABORTED: {NO_PLAN}" in text


def test_progress_lines_and_json_carry_the_stacks_text() -> None:
    log, lines = io.StringIO(), io.StringIO()
    mission = line_mission(3, retries=1, stall_timeout_s=3.0, on_failure=FailureAction.SKIP)
    plain = LogProgress(mission, log)
    as_json = JsonProgress(lines)
    run_with_a_failing_first_attempt([plain, as_json])
    assert f"attempt 1 failed (ABORTED: {NO_PLAN}), will retry" in log.getvalue()
    failed = [
        record
        for record in map(json.loads, lines.getvalue().splitlines())
        if record["event"] == "AttemptFailed"
    ]
    assert failed[0]["text"] == NO_PLAN and failed[0]["status"] == "ABORTED"
    assert failed[0]["duration_s"] == pytest.approx(2.0, abs=0.11)


# ---------------------------------------------------------------- journal


def journal_of(tmp_path: Path) -> tuple[Path, list[MissionEvent]]:
    path = tmp_path / "run.journal"
    events: list[MissionEvent] = []
    with JournalWriter(path, "mission.yaml", "d" * 64) as journal:
        run_with_a_failing_first_attempt([journal, events.append])
    return path, events


def test_journal_keeps_the_new_fields_and_rebuilds_each_visits_attempts(tmp_path: Path) -> None:
    path, events = journal_of(tmp_path)
    state = read_journal(path)
    written = [e for e in events if isinstance(e, AttemptFailed)]
    assert [e for e in journal_events(path) if isinstance(e, AttemptFailed)] == written
    _, result = run_with_a_failing_first_attempt()
    held = {(v.loop, v.index): v for v in state.visits.held()}
    for visit in result.visits:
        replayed = held[(visit.loop, visit.index)].attempt_results
        assert [(a.number, a.reached, a.status, a.reason, a.text) for a in replayed] == [
            (a.number, a.reached, a.status, a.reason, a.text) for a in visit.attempt_results
        ]
        for mine, theirs in zip(replayed, visit.attempt_results, strict=True):
            assert mine.duration == pytest.approx(theirs.duration, abs=1e-6)
            # The journal knows the last attempt only as the visit's rest.
            assert mine.distance_driven == pytest.approx(theirs.distance_driven, abs=0.03)


def test_a_journal_written_before_the_new_fields_still_reads_and_resumes(
    tmp_path: Path,
) -> None:
    old = tmp_path / "old.journal"
    header = {
        "kind": "header", "format": "navseq-journal", "version": 1,
        "mission_source": "m.yaml", "mission_digest": "e" * 64, "started": "then",
    }  # fmt: skip
    records = [
        header,
        {"type": "MissionStarted", "t": 0.0, "waypoint_count": 3, "loops": 1},
        {"type": "LoopStarted", "t": 0.0, "loop": 0},
        {"type": "WaypointStarted", "t": 0.0, "index": 0, "loop": 0, "attempt": 1,
         "goal_id": 1, "x": 1.0, "y": 0.0, "yaw": 0.0},
        {"type": "AttemptFailed", "t": 2.0, "index": 0, "attempt": 1, "reason": "ABORTED",
         "will_retry": True},
        {"type": "WaypointStarted", "t": 3.0, "index": 0, "loop": 0, "attempt": 2,
         "goal_id": 2, "x": 1.0, "y": 0.0, "yaw": 0.0},
        {"type": "WaypointFinished", "t": 5.0, "index": 0, "loop": 0, "outcome": "reached",
         "attempts": 2, "duration": 5.0, "distance_driven": 1.5},
        {"type": "WaypointStarted", "t": 5.0, "index": 1, "loop": 0, "attempt": 1,
         "goal_id": 3, "x": 2.0, "y": 0.0, "yaw": 0.0},
    ]  # fmt: skip
    old.write_text(
        "".join(json.dumps(r if r is header else {"kind": "event", **r}) + "\n" for r in records)
    )
    state = read_journal(old)
    failed = next(e for e in journal_events(old) if isinstance(e, AttemptFailed))
    assert failed.text == "" and failed.status is None and failed.duration == 0.0
    point = resume_point(state)
    assert (point.loop, point.index) == (0, 1)
    assert point.earlier is not None
    [done] = point.earlier.held()
    assert done.attempt_results == [
        AttemptResult(number=1, reason="ABORTED"),
        AttemptResult(number=2, reached=True, status="SUCCEEDED", duration=2.0,
                      distance_driven=1.5),
    ]  # fmt: skip


def test_interrupt_and_operator_skip_close_the_open_attempt() -> None:
    h = Harness(line_mission(3))
    h.start(0.0)
    h.tick(1.0, Pose2D(0.5, 0.0, 0.0))
    h.skip(2.0, "skipped by operator")
    h.interrupt(4.0, "interrupted: SIGINT")
    first, second, third = h.executor.result.visits
    assert first.attempt_results == [
        AttemptResult(number=1, reason="skipped by operator", duration=2.0)
    ]
    assert [(a.status, a.reason) for a in second.attempt_results] == [(None, "interrupted: SIGINT")]
    assert third.attempt_results == []
    assert math.isclose(second.attempt_results[0].duration, 2.0)
