"""The JSON run report: what a user or a script reads after a run."""

from __future__ import annotations

import json
import math

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult, WaypointResult
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.sinks.report import SCHEMA_VERSION, build_report, report_json, write_report

MISSION = Mission(
    waypoints=(
        Waypoint(1.0, 0.0, yaw_rad=0.0, name="dock"),
        Waypoint(2.0, 0.0, yaw_rad=math.pi / 2),
    ),
    loops=None,
    source="/data/missions/office.yaml",
)


def result(*outcomes: WaypointOutcome, success: bool = False) -> MissionResult:
    visits = [
        WaypointResult(
            index=i % 2,
            loop=i // 2,
            name=MISSION.waypoints[i % 2].name,
            x=MISSION.waypoints[i % 2].x,
            y=0.0,
            yaw_rad=MISSION.waypoints[i % 2].yaw_rad,
            outcome=o,
            attempts=1 if o != WaypointOutcome.NOT_RUN else 0,
            duration=10.0 * (i + 1),
            distance_driven=1.25,
            reason="ABORTED" if o in (WaypointOutcome.SKIPPED, WaypointOutcome.FAILED) else "",
        )
        for i, o in enumerate(outcomes)
    ]
    return MissionResult(
        success=success,
        reason="interrupted: SIGINT",
        visits=visits,
        duration=100.0,
        distance_driven=5.0,
        loops_completed=1,
    )


def test_report_counts_each_outcome_and_records_how_the_run_ended():
    r = result(
        WaypointOutcome.REACHED,
        WaypointOutcome.SKIPPED,
        WaypointOutcome.REACHED,
        WaypointOutcome.NOT_RUN,
    )
    report = build_report(
        MISSION,
        r,
        exit_code=130,
        navigator={"kind": "sim"},
        interrupted="SIGINT",
        mission_digest="ab" * 32,
        start=Pose2D(-2.0, -0.5, math.pi),
        files={"journal": "out/journal.jsonl"},
    )
    assert report["schema_version"] == SCHEMA_VERSION
    assert report["mission"] == {
        "source": "/data/missions/office.yaml",
        "name": "office",
        "digest": "ab" * 32,
        "frame": "map",
        "waypoints": 2,
        "loops": "forever",
    }
    assert report["totals"] == {
        "visits": 4,
        "reached": 2,
        "skipped": 1,
        "failed": 0,
        "not_run": 1,
        "duration_s": 100.0,
        "distance_m": 5.0,
        "loops_completed": 1,
    }
    assert report["success"] is False
    assert report["interrupted"] == "SIGINT" and report["exit_code"] == 130
    assert report["start"] == {"x": -2.0, "y": -0.5, "yaw_deg": 180.0}
    assert report["navigator"] == {"kind": "sim"} and report["map"] is None
    second = report["visits"][1]
    assert second["number"] == 2 and second["index"] == 1 and second["loop"] == 0
    assert second["outcome"] == "skipped" and second["reason"] == "ABORTED"
    assert second["yaw_deg"] == 90.0
    assert report["visits"][2]["loop"] == 1 and report["visits"][0]["name"] == "dock"


def test_report_file_is_valid_json_even_with_non_finite_numbers(tmp_path):
    r = result(WaypointOutcome.REACHED, success=True)
    r.visits[0].distance_driven = math.nan
    report = build_report(MISSION, r, exit_code=0, navigator={"kind": "scripted"})
    path = tmp_path / "run" / "report.json"
    write_report(report, path)
    text = path.read_text()
    assert "NaN" not in text
    loaded = json.loads(text)
    assert loaded["visits"][0]["distance_m"] is None
    assert loaded["success"] is True and loaded["exit_code"] == 0
    # Written atomically: no temporary file is left beside it.
    assert [p.name for p in path.parent.iterdir()] == ["report.json"]


def test_report_text_is_python_json_indented_and_a_name_orjson_refuses_still_writes(tmp_path):
    r = result(WaypointOutcome.REACHED, WaypointOutcome.SKIPPED, WaypointOutcome.REACHED)
    report = build_report(MISSION, r, exit_code=1, navigator={"kind": "sim", "speed": 2.0})
    assert report_json(report) == json.dumps(report, indent=2, ensure_ascii=False) + "\n"
    # A file name holding bytes that are not UTF-8 (os.fsdecode gives lone surrogates).
    report["files"] = {"journal": "run-\udcff/journal.jsonl"}
    path = tmp_path / "report.json"
    write_report(report, path)
    assert json.loads(path.read_text())["files"]["journal"].startswith("run-")
