"""The table at the end of ``navseq run``: like a person's notes for a short mission,
a few dozen rows at most for a patrol or a mission of thousands of waypoints."""

from __future__ import annotations

import io
import math

from rich.console import Console

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import AttemptResult, MissionResult, WaypointResult
from navseq.mission.model import Mission, Waypoint
from navseq.sinks.summary import MAX_PROBLEM_ROWS, MAX_ROWS, print_table, summary_table

REACHED, FAILED, SKIPPED, NOT_RUN = (
    WaypointOutcome.REACHED,
    WaypointOutcome.FAILED,
    WaypointOutcome.SKIPPED,
    WaypointOutcome.NOT_RUN,
)

MISSION = Mission(
    waypoints=(
        Waypoint(1.0, 0.0, yaw_rad=0.0, name="dock"),
        Waypoint(2.0, 0.0, yaw_rad=math.pi / 2),
        Waypoint(2.0, 2.0, yaw_rad=math.pi, name="desk"),
    ),
    loops=2,
    source="office.yaml",
)


def mission_of(count: int, loops: int | None = 1) -> Mission:
    waypoints = tuple(Waypoint(float(i), 0.0, name=f"wp{i + 1}") for i in range(count))
    return Mission(waypoints=waypoints, loops=loops, source="big.yaml")


def visit(index: int, outcome: WaypointOutcome, loop: int = 0, **kw) -> WaypointResult:
    ran = outcome is not NOT_RUN
    return WaypointResult(
        index,
        loop,
        kw.pop("name", None),
        float(index),
        0.0,
        0.0,
        outcome,
        attempts=1 if ran else 0,
        duration=10.0 if ran else 0.0,
        distance_driven=2.0 if ran else 0.0,
        **kw,
    )


def text_of(table, width: int = 200) -> str:
    console = Console(file=io.StringIO(), width=width, record=True)
    console.print(table)
    return console.export_text()


def data_rows(text: str) -> list[str]:
    """The table's body rows (between the header rule and the footer rule)."""
    lines = text.splitlines()
    rules = [n for n, line in enumerate(lines) if set(line.strip()) <= set("┡━╇┩╞═╪╡├─┼┤") and line]
    return [line.strip("│ ") for line in lines[rules[0] + 1 : rules[1]] if line.strip()]


def test_summary_table_lists_every_visit_with_totals():
    result = MissionResult(
        success=False,
        reason="stopped: waypoint 2 failed",
        visits=[
            WaypointResult(0, 0, "dock", 1.0, 0.0, 0.0, REACHED, 1, 13.0, 1.0),
            WaypointResult(1, 0, None, 2.0, 0.0, 1.57, FAILED, 3, 40.0, 0.4, reason="ABORTED"),
            WaypointResult(2, 0, "desk", 2.0, 2.0, 3.14, NOT_RUN),
        ],
        duration=53.0,
        distance_driven=1.4,
    )
    text = text_of(summary_table(MISSION, result), width=120)
    assert "stopped: waypoint 2 failed" in text
    for expected in (
        "dock",
        "reached",
        "failed",
        "ABORTED",
        "not run",
        "53.0",
        "1.40",
        "time [s]",
        "distance [m]",
    ):
        assert expected in text
    assert "loop" not in text and "visits" not in text  # a single loop: one row a visit
    assert len(data_rows(text)) == 3


def test_a_patrol_is_one_row_per_waypoint_with_counts_and_mean_time():
    mission = mission_of(5, loops=None)
    visits = [visit(i, REACHED, loop) for loop in range(1445) for i in range(5)]
    failure = AttemptResult(1, status="ABORTED", reason="aborted", text="no valid plan")
    visits[7] = visit(2, FAILED, 1, attempt_results=[failure], reason="aborted")
    visits.append(visit(0, NOT_RUN, 1445))
    result = MissionResult(False, "interrupted: SIGINT", visits, duration=72250.0)
    text = text_of(summary_table(mission, result))
    rows = data_rows(text)
    assert len(rows) == 5, text
    wp3 = next(row for row in rows if "wp3" in row)
    assert "1445" in wp3 and "1444" in wp3  # visits, reached
    assert "aborted: no valid plan" in wp3  # why the one visit was not reached
    assert "10.0" in wp3 and "14450.0" in wp3  # mean and total time
    assert "7224" in text  # 7225 visits ran, one of them failed: totals in the footer


def test_not_run_waypoints_are_one_row():
    mission = mission_of(5000)
    visits = [visit(i, REACHED) for i in range(1200)]
    visits.append(visit(1200, FAILED, reason="stalled"))
    visits += [visit(i, NOT_RUN) for i in range(1201, 5000)]
    result = MissionResult(False, "stopped: waypoint 1201 failed", visits)
    rows = data_rows(text_of(summary_table(mission, result)))
    assert len(rows) <= MAX_ROWS
    assert any("1202-5000" in row and "not run (3799)" in row for row in rows)
    assert any(row.strip().startswith("1201") and "stalled" in row for row in rows)
    assert any("1-1200" in row and "reached (1200)" in row for row in rows)


def test_a_short_stopped_mission_keeps_its_reached_rows_and_merges_what_did_not_run():
    mission = mission_of(8)
    visits = [visit(0, REACHED), visit(1, REACHED), visit(2, FAILED, reason="timeout")]
    visits += [visit(i, NOT_RUN) for i in range(3, 8)]
    rows = data_rows(text_of(summary_table(mission, MissionResult(False, "stopped", visits))))
    assert len(rows) == 4
    assert "wp1" in rows[0] and "wp2" in rows[1] and "timeout" in rows[2]
    assert "4-8" in rows[3] and "not run (5)" in rows[3]


def test_failures_are_always_listed_up_to_a_cap_then_counted():
    mission = mission_of(500)
    visits = [
        visit(i, FAILED if i % 5 == 0 else REACHED, reason="stalled" if i % 5 == 0 else "")
        for i in range(500)
    ]
    text = text_of(summary_table(mission, MissionResult(False, "completed", visits)))
    rows = data_rows(text)
    assert len(rows) <= 2 * MAX_PROBLEM_ROWS + 2
    listed = [row for row in rows if row.split("│")[2].strip() == "✗ failed"]
    assert len(listed) == MAX_PROBLEM_ROWS
    assert f"and {100 - MAX_PROBLEM_ROWS} more waypoints not reached, see report.json" in text


def test_part_of_a_mission_is_numbered_as_in_the_file():
    mission = mission_of(2)
    visits = [visit(0, REACHED), visit(1, REACHED)]
    table = summary_table(
        mission, MissionResult(True, "completed", visits), numbers=[4, 6], part="--only 5,7"
    )
    text = text_of(table)
    rows = data_rows(text)
    assert rows[0].split()[0] == "5" and rows[1].split()[0] == "7"
    assert "(--only 5,7)" in text  # the part, as the caller describes it


def test_in_a_pipe_names_are_never_cut():
    long_name = "north-most-corner-of-the-loading-bay-beside-the-red-door"
    mission = Mission(waypoints=(Waypoint(1.0, 0.0, name=long_name),), source="m.yaml")
    result = MissionResult(
        False,
        "stopped",
        [visit(0, FAILED, name=long_name, reason="the navigation stack gave up after 3 plans")],
    )
    stream = io.StringIO()  # not a terminal: rich would assume 80 columns
    print_table(summary_table(mission, result), Console(file=stream))
    text = stream.getvalue()
    assert long_name in text
    assert "the navigation stack gave up after 3 plans" in text
    assert "…" not in text


def test_a_patrol_longer_than_the_report_lists_is_counted_from_the_totals():
    """A patrol keeps only its last visits in full: the table still counts every one."""
    from navseq.executor.result import VisitLog

    mission = mission_of(5, loops=None)
    log = VisitLog(mission.waypoints, None)
    failure = AttemptResult(1, status="ABORTED", reason="aborted", text="no valid plan")
    for loop in range(1445):
        for i in range(5):
            if (loop, i) == (1, 2):
                log.add(visit(2, FAILED, 1, attempt_results=[failure], reason="aborted"))
            else:
                log.add(visit(i, REACHED, loop))
    result = log.result(
        success=False, reason="interrupted: SIGINT", duration=72250.0, loops_completed=1445
    )
    assert result.omitted_visits > 0  # the premise: not every visit is listed
    text = text_of(summary_table(mission, result))
    wp3 = next(row for row in data_rows(text) if "wp3" in row)
    assert "1445" in wp3 and "1444" in wp3  # visits, reached: counted, not just listed
    assert "aborted: no valid plan" in wp3
    assert "14450.0" in wp3
