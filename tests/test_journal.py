"""The journal file: what is written, what the reader tolerates, where a run resumes."""

from __future__ import annotations

import contextlib
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers_executor import line_mission
from helpers_subprocess import journal_records
from navseq.errors import NavseqError
from navseq.executor import MissionExecutor, run_mission
from navseq.executor.events import (
    MissionFinished,
    MissionStarted,
    WaypointFinished,
    WaypointOutcome,
    WaypointPlan,
    WaypointProgress,
    WaypointStarted,
)
from navseq.executor.resume import ResumePoint
from navseq.journal.reader import journal_events
from navseq.journal.writer import (
    HEARTBEAT,
    PATH_TOLERANCE,
    JournalWriter,
    mission_digest,
    read_journal,
    resume_point,
)
from navseq.mission.model import FailureAction
from navseq.navigators.scripted import Finish, ScriptedNavigator, Succeed


@pytest.fixture
def mission_file(tmp_path: Path) -> Path:
    path = tmp_path / "mission.yaml"
    path.write_text("waypoints: [...]\n")
    return path


def journal_of_run(tmp_path: Path, mission_file: Path, **policy) -> Path:  # type: ignore[no-untyped-def]
    path = tmp_path / "run.journal"
    with JournalWriter(path, str(mission_file), mission_digest(mission_file)) as journal:
        run_mission(line_mission(4, **policy), ScriptedNavigator(speed=0.5), [journal])
    return path


def records(path: Path) -> list[dict]:  # type: ignore[type-arg]
    return [json.loads(line) for line in path.read_text().splitlines()]


def cut_after(path: Path, predicate, keep_half_of_next: bool = True) -> None:  # type: ignore[no-untyped-def]
    """Simulate a crash: keep lines up to the first matching record, then half a line."""
    lines = path.read_bytes().split(b"\n")
    index = next(i for i, line in enumerate(lines) if predicate(json.loads(line)))
    kept = b"\n".join(lines[: index + 1]) + b"\n"
    if keep_half_of_next:
        kept += lines[index + 1][: len(lines[index + 1]) // 2]
    path.write_bytes(kept)


def test_header_then_one_event_per_line(tmp_path: Path, mission_file: Path) -> None:
    path = journal_of_run(tmp_path, mission_file)
    header, *events = records(path)
    assert header["kind"] == "header" and header["format"] == "navseq-journal"
    assert header["version"] == 2 and header["mission_source"] == str(mission_file)
    assert header["mission_digest"] == mission_digest(mission_file)
    assert len(header["mission_digest"]) == 64
    assert events[0]["type"] == "MissionStarted" and events[-1]["type"] == "MissionFinished"
    assert [e["outcome"] for e in events if e["type"] == "WaypointFinished"] == ["reached"] * 4
    state = read_journal(path)
    assert state.finish_reason == "completed" and state.damaged_lines == []
    assert state.visits.log is not None and state.visits.log.finished == 4


def progress_event(t: float, x: float, y: float = 0.0, index: int = 0) -> WaypointProgress:
    return WaypointProgress(
        t=t, index=index, x=x, y=y, yaw=0.0, distance_remaining=None, distance_driven=x
    )


def test_a_straight_drive_is_journaled_as_its_two_ends(tmp_path: Path) -> None:
    path = tmp_path / "j"
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        journal(MissionStarted(t=0.0, waypoint_count=1, loops=1))
        for step in range(200):  # 20 s at 10 Hz, 0.22 m/s along x
            journal(progress_event(step * 0.1, 0.022 * step))
        journal(WaypointFinished(19.9, 0, 0, WaypointOutcome.REACHED, 1, 19.9, 4.378))
    kept = [r for r in records(path) if r.get("type") == "WaypointProgress"]
    assert [(r["t"], r["x"]) for r in kept] == [(0.0, 0.0), (pytest.approx(19.9), 4.378)]
    # ...and the path a rebuilt picture draws reaches where the robot was at the end.
    assert read_journal(path).recorder.trajectory()[-1][1] == pytest.approx(4.378)


def test_corners_of_the_driven_path_are_journaled_within_the_tolerance(tmp_path: Path) -> None:
    path = tmp_path / "j"
    poses = [(0.02 * i, 0.0) for i in range(100)] + [(2.0, 0.02 * i) for i in range(100)]
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        for step, (x, y) in enumerate(poses):
            journal(progress_event(step * 0.1, x, y))
        journal(MissionFinished(t=20.0, success=True, reason="completed"))
    kept = [(r["x"], r["y"]) for r in records(path) if r.get("type") == "WaypointProgress"]
    assert len(kept) <= 4 and kept[0] == (0.0, 0.0) and kept[-1] == pytest.approx((2.0, 1.98))
    assert max(distance_to_polyline(pose, kept) for pose in poses) <= PATH_TOLERANCE * 1.5


def distance_to_polyline(point: tuple[float, float], line: list[tuple[float, float]]) -> float:
    p = np.asarray(point)
    best = float(np.hypot(*(p - line[0])))
    for a, b in zip(np.asarray(line[:-1]), np.asarray(line[1:]), strict=True):
        span = b - a
        length = float(span @ span)
        along = 0.0 if length == 0 else float(np.clip((p - a) @ span / length, 0.0, 1.0))
        best = min(best, float(np.hypot(*(p - a - along * span))))
    return best


def test_a_robot_standing_still_is_journaled_once_per_heartbeat(tmp_path: Path) -> None:
    path = tmp_path / "j"
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        for step in range(1000):  # 100 s in place (dwelling, paused, waiting for a server)
            journal(progress_event(step * 0.1, 1.0))
    kept = [r["t"] for r in records(path) if r.get("type") == "WaypointProgress"]
    assert kept == pytest.approx([0.0, HEARTBEAT, 2 * HEARTBEAT, 3 * HEARTBEAT])


def test_one_plan_per_attempt_is_journaled_as_corners(tmp_path: Path) -> None:
    path = tmp_path / "j"
    staircase = tuple((0.05 * (i // 2 + i % 2), 0.05 * (i // 2)) for i in range(80))
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        for attempt in (1, 2):
            journal(WaypointStarted(0.0, 0, 0, attempt, attempt, 2.0, 2.0, 0.0))
            for step in range(31):  # a navigation stack that replans every tick
                journal(WaypointPlan(step * 0.1, 0, staircase))
    plans = [r["path"] for r in records(path) if r.get("type") == "WaypointPlan"]
    assert len(plans) == 2  # the first of each attempt
    assert plans[0] == [[0.0, 0.0], [2.0, 1.95]]
    assert read_journal(path).recorder.leg_plans() == [((0.0, 0.0), (2.0, 1.95))]


def test_events_read_back_as_they_were(tmp_path: Path, mission_file: Path) -> None:
    path = journal_of_run(tmp_path, mission_file)
    events = list(journal_events(path))
    finished = [e for e in events if isinstance(e, WaypointFinished)]
    assert finished[0].outcome is WaypointOutcome.REACHED
    assert finished[0].distance_driven == pytest.approx(1.0)
    assert isinstance(events[-1], MissionFinished) and events[-1].success


def test_a_new_journal_never_replaces_an_existing_file(tmp_path: Path) -> None:
    path = tmp_path / "run.journal"
    path.write_text("precious\n")
    with pytest.raises(NavseqError, match="already exists"):
        JournalWriter(path, "m.yaml", "0" * 64)
    assert path.read_text() == "precious\n"


def test_truncated_last_line_is_tolerated_and_resume_starts_at_the_active_waypoint(
    tmp_path: Path, mission_file: Path
) -> None:
    path = journal_of_run(tmp_path, mission_file)
    cut_after(path, lambda r: r.get("type") == "WaypointStarted" and r["index"] == 2)
    state = read_journal(path)
    assert state.damaged_lines == [len(path.read_bytes().split(b"\n"))]
    assert state.finish_reason is None
    point = resume_point(state, mission_digest=mission_digest(mission_file))
    assert (point.loop, point.index) == (0, 2)
    assert point.earlier is not None
    assert [(v.index, v.outcome) for v in point.earlier.held()] == [
        (0, WaypointOutcome.REACHED),
        (1, WaypointOutcome.REACHED),
    ]


def test_resume_appends_to_the_same_journal_after_a_cut_line(
    tmp_path: Path, mission_file: Path
) -> None:
    path = journal_of_run(tmp_path, mission_file)
    cut_after(path, lambda r: r.get("type") == "WaypointFinished" and r["index"] == 0)
    before = path.read_bytes()
    point = resume_point(read_journal(path))
    nav = ScriptedNavigator(speed=0.5)
    with JournalWriter.resume(path, point) as journal:
        result = run_mission(line_mission(4), nav, [journal], resume=point)
    assert path.read_bytes().startswith(before)  # nothing already journaled was touched
    assert [g.pose.x for g in nav.sent_goals] == [2.0, 3.0, 4.0]
    assert result.success and [v.attempts for v in result.visits] == [1, 1, 1, 1]
    state = read_journal(path)
    assert state.segments == 2 and len(state.damaged_lines) == 1
    assert state.finish_reason == "completed"
    assert [r["kind"] for r in journal_records(path)].count("resumed") == 1
    with pytest.raises(NavseqError, match="nothing to resume"):
        resume_point(state)


def test_skipped_visits_are_not_rerun_but_a_failed_stop_is(
    tmp_path: Path, mission_file: Path
) -> None:
    path = tmp_path / "run.journal"
    nav = ScriptedNavigator([Finish("ABORTED"), Finish("ABORTED")])
    with JournalWriter(path, str(mission_file), mission_digest(mission_file)) as journal:
        result = run_mission(line_mission(3, on_failure=FailureAction.SKIP), nav, [journal])
    assert [v.outcome for v in result.visits][:2] == [WaypointOutcome.SKIPPED] * 2
    with pytest.raises(NavseqError, match="nothing to resume"):
        resume_point(read_journal(path))

    stopped = tmp_path / "stopped.journal"
    nav = ScriptedNavigator([Succeed(), Finish("ABORTED")])
    with JournalWriter(stopped, str(mission_file), mission_digest(mission_file)) as journal:
        result = run_mission(line_mission(3), nav, [journal])
    assert result.reason.startswith("stopped")
    point = resume_point(read_journal(stopped))
    assert (point.loop, point.index) == (0, 1)  # the failed one is tried again


def test_resume_point_in_a_later_loop(tmp_path: Path, mission_file: Path) -> None:
    path = tmp_path / "run.journal"
    with JournalWriter(path, str(mission_file), mission_digest(mission_file)) as journal:
        run_mission(line_mission(2, loops=3), ScriptedNavigator(), [journal])
    cut_after(path, lambda r: r.get("type") == "WaypointFinished" and r["loop"] == 1)
    point = resume_point(read_journal(path))
    assert (point.loop, point.index) == (1, 1)
    nav = ScriptedNavigator()
    result = run_mission(line_mission(2, loops=3), nav, resume=point)
    assert [g.pose.x for g in nav.sent_goals] == [2.0, 1.0, 2.0]
    assert result.success and len(result.visits) == 6 and result.loops_completed == 3


def test_changed_mission_is_refused(tmp_path: Path, mission_file: Path) -> None:
    path = journal_of_run(tmp_path, mission_file)
    cut_after(path, lambda r: r.get("type") == "WaypointStarted" and r["index"] == 1)
    mission_file.write_text("waypoints: [something else]\n")
    with pytest.raises(NavseqError, match="mission file changed") as caught:
        resume_point(read_journal(path), mission_digest=mission_digest(mission_file))
    assert caught.value.source == str(path)


def test_damage_in_the_middle_names_the_line(tmp_path: Path, mission_file: Path) -> None:
    path = journal_of_run(tmp_path, mission_file)
    lines = path.read_text().splitlines()
    lines[3] = lines[3][:10]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(NavseqError, match="damaged journal line") as caught:
        read_journal(path)
    assert caught.value.source == f"{path}:4"


@pytest.mark.parametrize(
    "content",
    [
        b"",
        b"waypoints:\n  - {x: 1, y: 2}\n",
        b'{"kind": "header", "format": "something-else", "version": 1}\n',
        b"\x89PNG\r\n\x1a\n\x00\x00binary",
        b'{"kind": "header", "format": "navseq-journal", "version": 99}\n',
    ],
)
def test_not_a_journal_is_a_clear_error(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "not.journal"
    path.write_bytes(content)
    with pytest.raises(NavseqError) as caught:
        read_journal(path)
    assert caught.value.source == f"{path}:1"


def test_malformed_event_names_the_line(tmp_path: Path) -> None:
    path = tmp_path / "j"
    JournalWriter(path, "m", "0" * 64).close()
    with path.open("a") as handle:
        handle.write(json.dumps({"kind": "event", "type": "WaypointFinished", "outcome": "x"}))
        handle.write("\n")
    with pytest.raises(NavseqError, match="WaypointFinished is malformed") as caught:
        read_journal(path)
    assert caught.value.source == f"{path}:2"


def test_journal_of_an_interrupted_run_resumes_at_the_interrupted_visit(
    tmp_path: Path, mission_file: Path
) -> None:
    path = tmp_path / "run.journal"

    def crash_on_third_goal(event: object) -> None:
        if isinstance(event, WaypointStarted) and event.index == 2:
            raise RuntimeError("power cut")

    with (
        JournalWriter(path, str(mission_file), mission_digest(mission_file)) as journal,
        pytest.raises(RuntimeError),
    ):
        run_mission(line_mission(4), ScriptedNavigator(), [journal, crash_on_third_goal])
    state = read_journal(path)
    assert state.finish_reason == "interrupted: RuntimeError: power cut"
    point = resume_point(state)
    assert (point.loop, point.index) == (0, 2)
    assert point.previous_duration == pytest.approx(2.0, abs=0.3)


# ---------------------------------------------------------------- robustness (property-based)

_JOURNAL_SETTINGS = settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def _read_and_resume(path: Path) -> None:
    """What ``navseq run --resume`` does with a journal: only NavseqError may come out."""
    with contextlib.suppress(NavseqError):
        point = resume_point(read_journal(path))
        MissionExecutor(line_mission(3, loops=2), resume=point).start(0.0)


@_JOURNAL_SETTINGS
@given(content=st.binary(max_size=2000))
def test_arbitrary_bytes_raise_only_navseq_errors(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "fuzz.journal"
    path.write_bytes(content)
    _read_and_resume(path)


@pytest.fixture(scope="module")
def valid_journal(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    folder = tmp_path_factory.mktemp("valid")
    path = folder / "run.journal"
    nav = ScriptedNavigator([Finish("ABORTED", after=0.5)])
    with JournalWriter(path, "mission.yaml", "0" * 64) as journal:
        run_mission(line_mission(3, loops=2, retries=1), nav, [journal])
    return path.read_bytes()


@_JOURNAL_SETTINGS
@given(data=st.data())
def test_mutated_journals_raise_only_navseq_errors(
    tmp_path: Path, valid_journal: bytes, data: st.DataObject
) -> None:
    content = bytearray(valid_journal)
    for _ in range(data.draw(st.integers(1, 5), label="mutations")):
        if not content:
            break
        at = data.draw(st.integers(0, len(content) - 1), label="at")
        action = data.draw(st.sampled_from(["flip", "cut", "insert", "drop"]), label="action")
        if action == "flip":
            content[at] = data.draw(st.integers(0, 255), label="byte")
        elif action == "cut":
            del content[at:]
        elif action == "insert":
            content[at:at] = data.draw(st.sampled_from([b'"', b"1", b"-", b"null", b"[]", b"\n"]))
        else:
            del content[at]
    path = tmp_path / "mutated.journal"
    path.write_bytes(bytes(content))
    _read_and_resume(path)


@_JOURNAL_SETTINGS
@given(
    field=st.sampled_from(["index", "loop", "attempts", "outcome", "t", "duration", "reason"]),
    value=st.one_of(
        st.none(),
        st.booleans(),
        st.integers(),
        st.floats(),
        st.text(max_size=5),
        st.lists(st.integers(), max_size=2),
    ),
)
def test_wrongly_typed_event_fields_raise_only_navseq_errors(
    tmp_path: Path, valid_journal: bytes, field: str, value: object
) -> None:
    lines = valid_journal.decode().splitlines()
    for number, line in enumerate(lines):
        record = json.loads(line)
        if record.get("type") == "WaypointFinished":
            record[field] = value
            lines[number] = json.dumps(record)
            break
    path = tmp_path / "typed.journal"
    path.write_text("\n".join(lines) + "\n")
    _read_and_resume(path)


def test_recorder_from_journal_keeps_earlier_segments_on_one_mission_clock(
    tmp_path: Path,
) -> None:
    def progress(t: float, x: float) -> WaypointProgress:
        return WaypointProgress(
            t=t, index=0, x=x, y=0.0, yaw=0.0, distance_remaining=None, distance_driven=x
        )

    path = tmp_path / "run.journal"
    # The first segment runs on a clock that starts at 100 s (ROS time, say)...
    with JournalWriter(path, "m.yaml", "digest") as journal:
        for event in (
            MissionStarted(t=100.0, waypoint_count=2, loops=1),
            WaypointStarted(t=100.0, index=0, loop=0, attempt=1, goal_id=1, x=2.0, y=0.0, yaw=0.0),
            WaypointPlan(t=100.0, index=0, path=((0.0, 0.0), (2.0, 0.0))),
            progress(100.5, 0.5),
            progress(130.5, 1.0),  # a heartbeat later: journaled although straight on
        ):
            journal(event)
    state = read_journal(path)
    recorder = state.recorder
    # ...the resumed one (appended to the same journal) on one that starts at 0.
    with JournalWriter.resume(path, ResumePoint(loop=0, index=0), history=state) as journal:
        for event in (
            MissionStarted(t=0.0, waypoint_count=2, loops=1, resumed_from=0),
            WaypointStarted(t=0.0, index=0, loop=0, attempt=1, goal_id=1, x=2.0, y=0.0, yaw=0.0),
            WaypointPlan(t=0.0, index=0, path=((0.0, 0.0), (3.0, 0.0))),
            progress(1.0, 0.7),
        ):
            journal(event)
            recorder(event)

    assert state.previous_duration == pytest.approx(30.5)
    assert recorder.segments == 2
    t, x, _ = zip(*recorder.trajectory(), strict=True)
    assert x[:2] == (0.5, 1.0) and np.isnan(x[2]) and x[3] == 0.7
    assert t[:2] == (0.5, 30.5) and t[3] == pytest.approx(31.5)  # 30.5 s before + 1 s after
    assert recorder.earlier_trajectory()[:2] == [(0.5, 0.5, 0.0), (30.5, 1.0, 0.0)]
    assert recorder.mission_time(4.0) == pytest.approx(34.5)
    # The resumed visit shows both legs: the one planned before and the one after.
    assert recorder.leg_plans() == [((0.0, 0.0), (2.0, 0.0)), ((0.0, 0.0), (3.0, 0.0))]
    # Replaying the whole journal afterwards gives the same picture data.
    replayed = read_journal(path).recorder
    assert replayed.leg_plans() == recorder.leg_plans()
    assert np.allclose(replayed.trajectory(), recorder.trajectory(), equal_nan=True)


def test_every_change_of_the_stacks_recovery_count_is_journaled(tmp_path: Path) -> None:
    path = tmp_path / "j"
    counts = [0] * 20 + [1] * 20 + [2] * 20  # Nav2 ran two recoveries on a straight drive
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        journal(MissionStarted(t=0.0, waypoint_count=1, loops=1))
        journal(WaypointStarted(0.0, 0, 0, 1, 1, 2.0, 0.0, 0.0))
        for step, count in enumerate(counts):
            event = progress_event(step * 0.1, 0.02 * step)
            journal(dataclasses.replace(event, recoveries=count, navigation_time=step * 0.1))
        journal(WaypointFinished(6.0, 0, 0, WaypointOutcome.REACHED, 1, 6.0, 1.2))
    kept = [r["recoveries"] for r in records(path) if r.get("type") == "WaypointProgress"]
    assert kept == [0, 1, 2, 2]  # the first, each change, the arrival
    [visit] = read_journal(path).visits.held()
    assert [a.recoveries for a in visit.attempt_results] == [2]
