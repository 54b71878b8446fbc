"""The stand-in-beside-Nav2 benchmark: its reading of a run's folder, and its small run.

The benchmark's numbers are only as good as ``benchmarks/mission_runs.py``'s reading of
the journals, so that is tested on journals written here (no ROS). The ``--quick`` run
(one short mission, once, on the stand-in only; the real Nav2 is the full run's, too slow
for CI) shows the script still drives navseq end to end and checks issue 16's bar.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from bench_support import BENCHMARKS, load_benchmark

runs = load_benchmark("mission_runs")


def event(kind: str, t: float, **fields: Any) -> dict[str, Any]:
    return {"kind": "event", "type": kind, "t": t, **fields}


def write_run(folder: Path, events: list[dict[str, Any]], robot_source: str) -> Path:
    folder.mkdir()
    lines = [{"kind": "header", "format": "navseq-journal"}, *events]
    (folder / "journal.jsonl").write_text("".join(json.dumps(e) + "\n" for e in lines))
    report = {
        "navigator": {"robot_source": robot_source},
        "visits": [{"attempts": [{"recoveries": 2}, {"recoveries": 1}]}],
    }
    (folder / "report.json").write_text(json.dumps(report))
    return folder


NAV2_ROBOT = "robot from Nav2's parameters under /: robot_radius 0.22 m, tolerance 0.25 m / 14°"


def two_visit_run() -> list[dict[str, Any]]:
    """a passed through 0.38 m off; b: a false success, then reached 0.30 m off."""
    return [
        event("MissionStarted", 100.0),
        event("WaypointStarted", 100.0, index=0, attempt=1, x=0.0, y=0.0),
        event("WaypointProgress", 104.0, index=0, x=0.38, y=0.0),
        event("WaypointFinished", 104.1, index=0, outcome="reached", passed_through=True),
        event("WaypointStarted", 104.1, index=1, attempt=1, x=2.0, y=0.0),
        event("WaypointProgress", 104.1, index=1, x=0.39, y=0.0),  # nearest to a's end
        event(
            "AttemptFailed",
            104.8,
            index=1,
            attempt=1,
            status="SUCCEEDED",
            reason="succeeded far from goal (1.61 m)",
            text="",
        ),
        event("WaypointStarted", 105.8, index=1, attempt=2, x=2.0, y=0.0),
        event("WaypointProgress", 110.0, index=1, x=1.7, y=0.0),
        event("WaypointFinished", 110.0, index=1, outcome="reached", passed_through=False),
        event("MissionFinished", 110.0, success=True),
    ]


def test_a_run_folder_gives_time_failures_and_the_bar_on_the_nearest_pose(
    tmp_path: Path,
) -> None:
    folder = write_run(tmp_path / "run", two_visit_run(), NAV2_ROBOT)
    record = runs.read_run(folder, runs.RunRecord("nav2", "pass", 0, 0, 12.0), 0.4, ["a", "b"])
    assert record.mission_s == pytest.approx(10.0)
    assert record.tolerance_m == 0.25 and record.recoveries == 3
    assert [f.false_success for f in record.failures] == [True]
    assert record.after_false_success == ["reached"]
    a, b = record.arrivals
    # a: judged on the pose at its end's very time (b's first progress), not on its own
    # last one 0.1 s earlier.
    assert a.waypoint == "a" and a.passed_through and a.pose_dt_s == pytest.approx(0.0)
    assert a.distance_m == pytest.approx(0.39) and a.bound_m == pytest.approx(0.5)
    assert not a.over
    assert b.distance_m == pytest.approx(0.30) and b.bound_m == pytest.approx(0.35)
    assert not b.over


def test_a_visit_recorded_reached_beyond_its_tolerance_breaks_the_bar(tmp_path: Path) -> None:
    events = two_visit_run()
    events[-3]["x"] = 1.6  # b stopped 0.40 m off: over 0.25 + 0.1
    folder = write_run(tmp_path / "run", events, NAV2_ROBOT)
    record = runs.read_run(folder, runs.RunRecord("nav2", "stop", 0, 0, 12.0), None, ["a", "b"])
    assert [check.over for check in record.arrivals] == [True, True]  # a: 0.39 > 0.35 too


def test_without_the_robot_note_the_bar_is_not_checked(tmp_path: Path) -> None:
    folder = write_run(tmp_path / "run", two_visit_run(), "turtlebot3_burger")
    record = runs.read_run(folder, runs.RunRecord("nav2", "pass", 0, 0, 1.0), 0.4, ["a", "b"])
    assert record.tolerance_m is None and record.arrivals == []


def test_an_edge_case_gives_its_first_result_and_the_time_to_it(tmp_path: Path) -> None:
    events = [
        event("MissionStarted", 5.0),
        event("WaypointStarted", 5.0, index=0, attempt=1, x=1.1, y=0.1),
        event(
            "AttemptFailed",
            5.4,
            index=0,
            attempt=1,
            status="ABORTED",
            reason="ABORTED",
            text="ComputePathToPose GOAL_OCCUPIED (error_code 206)",
        ),
        event("WaypointFinished", 5.4, index=0, outcome="failed", passed_through=False),
        event("MissionFinished", 5.4, success=False),
    ]
    folder = write_run(tmp_path / "run", events, NAV2_ROBOT)
    record = runs.read_run(folder, runs.RunRecord("nav2", "wall", 0, 1, 3.0), None, ["wall"])
    assert record.first == runs.FirstResult(
        "failed", "ABORTED", "ComputePathToPose GOAL_OCCUPIED (error_code 206)", pytest.approx(0.4)
    )
    assert record.failures[0].kind() == "ABORTED: ComputePathToPose GOAL_OCCUPIED (error_code 206)"


def test_reasons_without_text_group_with_their_numbers_folded() -> None:
    one = runs.Failure("SUCCEEDED", "succeeded 21° off the goal yaw", "")
    other = runs.Failure("SUCCEEDED", "succeeded 104° off the goal yaw", "")
    assert one.kind() == other.kind() == "SUCCEEDED: succeeded N° off the goal yaw"


@pytest.mark.ros2
def test_quick_run_on_the_stand_in_completes_and_holds_the_bar(tmp_path: Path) -> None:
    out = tmp_path / "records.json"
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / "bench_nav2_real.py"), "--quick", "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "COLUMNS": "250"},
    )
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "Issue 16's bar: held." in done.stdout
    (record,) = json.loads(out.read_text())
    assert record["stack"] == "stand-in" and record["exit_code"] == 0, record
    assert record["tolerance_m"] is not None and len(record["arrivals"]) == 2, record
    assert not any(check["distance_m"] > check["bound_m"] for check in record["arrivals"])
