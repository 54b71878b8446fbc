"""A long run's journal is read into bounded memory and still resumes and reports right."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from helpers_executor import line_mission
from navseq.commands.report import result_from_journal
from navseq.errors import NavseqError
from navseq.executor import run_mission
from navseq.executor.events import (
    MissionStarted,
    WaypointFinished,
    WaypointOutcome,
    WaypointPlan,
    WaypointProgress,
)
from navseq.executor.result import KEEP_LAST_VISITS
from navseq.journal.writer import JournalWriter, read_journal, resume_point
from navseq.navigators.scripted import ScriptedNavigator

LOOPS = 300  # 1200 visits: more than a result lists in full
WAYPOINTS = 4


def cut_after_finish(path: Path, finished: int) -> None:
    """What a kill -9 leaves: the lines up to the ``finished``-th WaypointFinished, and
    half of the next line."""
    lines = path.read_bytes().split(b"\n")
    number = [n for n, line in enumerate(lines) if b'"WaypointFinished"' in line][finished - 1]
    path.write_bytes(b"\n".join(lines[: number + 1]) + b"\n" + lines[number + 1][:40])


@pytest.fixture(scope="module")
def long_journal(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("long") / "run.journal"
    with JournalWriter(path, "mission.yaml", "0" * 64) as journal:
        run_mission(line_mission(WAYPOINTS, loops=LOOPS), ScriptedNavigator(speed=5.0), [journal])
    return path


def test_a_long_journal_folds_its_visits_and_resumes_to_a_result_counting_all(
    tmp_path: Path, long_journal: Path
) -> None:
    path = tmp_path / "run.journal"
    path.write_bytes(long_journal.read_bytes())
    cut_after_finish(path, 1101)  # in loop 275, after its first waypoint
    state = read_journal(path)
    assert state.visits.log is not None and state.visits.log.finished == 1101
    assert len(state.visits.held()) == KEEP_LAST_VISITS  # not one per visit
    assert state.damaged_count == 1

    point = resume_point(state)
    assert (point.loop, point.index) == (275, 1)
    mission = line_mission(WAYPOINTS, loops=LOOPS)
    navigator = ScriptedNavigator(speed=5.0)
    with JournalWriter.resume(path, point, history=state) as journal:
        result = run_mission(mission, navigator, [journal], resume=point)
    assert [g.pose.x for g in navigator.sent_goals[:4]] == [2.0, 3.0, 4.0, 1.0]
    assert result.success and result.loops_completed == LOOPS
    assert result.total_visits == LOOPS * WAYPOINTS
    assert len(result.visits) == KEEP_LAST_VISITS
    assert [(t.name, t.reached) for t in result.waypoints] == [
        (f"p{i + 1}", LOOPS) for i in range(WAYPOINTS)
    ]

    # The whole journal, both segments, rebuilds the same counts (navseq report).
    rebuilt = result_from_journal(read_journal(path), mission)
    assert rebuilt.success and rebuilt.loops_completed == LOOPS
    assert rebuilt.total_visits == LOOPS * WAYPOINTS
    assert [t.reached for t in rebuilt.waypoints] == [LOOPS] * WAYPOINTS
    assert [(v.loop, v.index) for v in rebuilt.visits] == [(v.loop, v.index) for v in result.visits]
    assert rebuilt.visits[-1].name == "p4" and rebuilt.visits[-1].x == 4.0


def test_a_resume_reads_the_journal_again_if_it_grew_since(
    tmp_path: Path, long_journal: Path
) -> None:
    path = tmp_path / "run.journal"
    path.write_bytes(long_journal.read_bytes())
    cut_after_finish(path, 10)
    state = read_journal(path)
    point = resume_point(state)
    JournalWriter.resume(path, point).close()  # someone appended since it was read
    JournalWriter.resume(path, point, history=state).close()  # must chain on from that
    assert read_journal(path).segments == 3


def write_events(path: Path, *events: object) -> None:
    with JournalWriter(path, "m.yaml", "0" * 64) as journal:
        for event in events:
            journal(event)  # type: ignore[arg-type]


def finished(index: int, loop: int = 0, outcome: str = "reached") -> WaypointFinished:
    return WaypointFinished(1.0, index, loop, WaypointOutcome(outcome), 1, 1.0, 1.0)


def test_visits_finished_out_of_mission_order_are_refused_with_the_line(tmp_path: Path) -> None:
    # Chained, so not hand-edited: a journal no navseq run writes is still refused.
    path = tmp_path / "j"
    write_events(path, MissionStarted(0.0, 3, 1), finished(0), finished(2))
    with pytest.raises(NavseqError, match="waypoint 3 of loop 1 finished while waypoint 2") as e:
        read_journal(path)
    assert e.value.source == f"{path}:4"


def test_a_waypoint_out_of_the_journaled_mission_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "j"
    write_events(path, MissionStarted(0.0, 3, 1), finished(5))
    with pytest.raises(NavseqError, match=r"records waypoint 6 .* has 3 waypoint") as e:
        read_journal(path)
    assert e.value.source == f"{path}:3"


def test_a_failed_visit_is_run_again_and_then_counted_once(tmp_path: Path) -> None:
    path = tmp_path / "j"
    write_events(
        path,
        MissionStarted(0.0, 2, 1),
        finished(0),
        finished(1, outcome="failed"),  # the mission stopped here...
        MissionStarted(0.0, 2, 1, resumed_from=1),
        finished(1),  # ...and a resumed run reached it
        finished(0),  # a finish of a visit done before changes nothing
    )
    state = read_journal(path)
    assert state.visits.unfinished is None
    assert state.visits.log is not None and state.visits.log.finished == 2
    assert [v.outcome for v in state.visits.held()] == [WaypointOutcome.REACHED] * 2


def test_a_journal_from_before_the_thinning_still_reads_its_path_and_legs(
    tmp_path: Path,
) -> None:
    """Earlier navseq journaled progress once a second, every plan, full floats."""

    class EverySecond(JournalWriter):
        def __call__(self, event: object) -> None:
            record = dataclasses.asdict(event)  # type: ignore[call-overload]
            self._write({"kind": "event", "type": type(event).__name__, **record})

    path = tmp_path / "old.journal"
    with EverySecond(path, "m.yaml", "0" * 64) as journal:
        journal(MissionStarted(0.0, 1, 1))
        for second in range(10):
            journal(WaypointPlan(second, 0, tuple((0.1 * i, 0.0) for i in range(50))))
            journal(WaypointProgress(second + 0.1, 0, 0.1 * second, 0.0, 0.0, None, 0.1))
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    assert sum(r.get("type") == "WaypointPlan" for r in lines) == 10
    state = read_journal(path)
    assert [round(x, 6) for _, x, _ in state.recorder.trajectory()] == [
        round(0.1 * s, 6) for s in range(10)
    ]
    assert len(state.recorder.leg_plans()) == 1 and len(state.recorder.leg_plans()[0]) == 50
