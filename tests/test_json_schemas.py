"""The ``--json`` events and the report of a real simulator run match their JSON Schemas.

The schemas in docs/schemas are what programs reading navseq's output rely on; they
are strict (no unknown fields), so a renamed or added field fails here until the
schema, its version and docs/cli.md say so.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from cli_support import REPO, TURTLEBOT3_MAP, navseq, write_mission
from navseq.executor.events import ServerStatusChanged
from navseq.sinks import json_events, report

SCHEMAS = REPO / "docs" / "schemas"

# A lap of the arena that emits every kind of event the simulator can: two loops, a
# dwell, and a waypoint whose 1 s timeout fails twice (one retry) and is then skipped.
MISSION = """\
  - {name: south, x: 0.5, y: -1.6, yaw: 0, dwell: 1.0}
  - {name: far, x: 1.6, y: 0.5, yaw: 90, goal_timeout: 1.0, retries: 1, on_failure: skip}
"""
HEADER = f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\nloops: 2\n"


def validator(name: str) -> Draft202012Validator:
    schema = json.loads((SCHEMAS / f"{name}.schema.json").read_text())
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema, format_checker=Draft202012Validator.FORMAT_CHECKER)


def problems(check: Draft202012Validator, record: Any) -> list[str]:
    return [
        f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in check.iter_errors(record)
    ]


@pytest.fixture(scope="module")
def run(
    tmp_path_factory: pytest.TempPathFactory,
) -> tuple[list[dict[str, Any]], dict[str, Any], Path]:
    folder = tmp_path_factory.mktemp("schema_run")
    mission = write_mission(folder / "lap.yaml", MISSION, HEADER)
    done = navseq("run", mission, "--json", "--out", folder / "out", cwd=folder)
    assert done.returncode == 1, done.stderr  # "far" is skipped: not every visit reached
    records = [json.loads(line) for line in done.stdout.splitlines()]
    return records, json.loads((folder / "out" / "report.json").read_text()), folder


def test_every_event_record_of_a_real_run_matches_the_events_schema(run):
    records, _, _ = run
    check = validator("events")
    kinds = {record["event"] for record in records}
    # Every kind a simulator run can emit (the server never vanishes in process).
    assert kinds == {
        "MissionStarted",
        "LoopStarted",
        "WaypointStarted",
        "WaypointPlan",
        "WaypointProgress",
        "AttemptFailed",
        "WaypointDwelling",
        "WaypointFinished",
        "MissionFinished",
        "RunFinished",
    }
    for record in records:
        assert problems(check, record) == [], record


def test_server_status_records_match_the_schema_too():
    check = validator("events")
    for event in (ServerStatusChanged(3.0, False, "no heartbeat"), ServerStatusChanged(4.0, True)):
        assert problems(check, json_events.event_record(event)) == []


def test_the_report_of_a_real_run_matches_the_report_schema(run):
    _, written, _ = run
    assert problems(validator("report"), written) == []


def test_events_and_report_use_the_same_names_and_units_for_the_same_things(run):
    records, written, _ = run
    started = next(r for r in records if r["event"] == "WaypointStarted" and r["index"] == 1)
    visit = written["visits"][1]
    assert started["yaw_deg"] == visit["yaw_deg"] == 90.0  # degrees in both, not radians
    assert started["number"] == visit["number"] == 2  # the number messages say
    finished = [r for r in records if r["event"] == "WaypointFinished"]
    for record, visit in zip(finished, written["visits"], strict=True):
        assert record["outcome"] == visit["outcome"]
        assert record["attempt_count"] == len(visit["attempts"])
        assert record["duration_s"] == pytest.approx(visit["duration_s"], abs=0.01)
        assert record["distance_m"] == pytest.approx(visit["distance_m"], abs=0.001)
    failed = next(r for r in records if r["event"] == "AttemptFailed")
    attempt = written["visits"][1]["attempts"][0]
    assert failed["reason"] == attempt["reason"] == "timeout"
    assert failed["duration_s"] == pytest.approx(attempt["duration_s"], abs=0.01)
    assert records[-1]["files"] == written["files"]
    # How fast the simulator ran, said the same way in both, its ratio the factor.
    clock = written["clock"]
    assert records[-1]["clock"] == clock
    assert clock["navigator_s"] == pytest.approx(written["totals"]["duration_s"], abs=0.5)
    assert clock["real_time_factor"] == pytest.approx(
        clock["navigator_s"] / clock["wall_s"], rel=0.01
    )
    assert written["map"]["origin"] == {"x": -10.0, "y": -10.0, "yaw_deg": 0.0}


def test_the_schemas_say_the_versions_the_code_writes():
    events_schema = json.loads((SCHEMAS / "events.schema.json").read_text())
    report_schema = json.loads((SCHEMAS / "report.schema.json").read_text())
    assert events_schema["$defs"]["schema_version"]["const"] == json_events.SCHEMA_VERSION
    assert report_schema["properties"]["schema_version"]["const"] == report.SCHEMA_VERSION


def test_the_schemas_catch_drift(run):
    records, written, _ = run
    renamed = {**records[2], "duration": 1.0}  # an old, unit-less name
    assert problems(validator("events"), renamed)
    visit = {**written["visits"][0], "yaw": math.pi / 2}
    assert problems(validator("report"), {**written, "visits": [visit]})
    assert problems(validator("report"), {**written, "schema_version": 3})
    assert problems(validator("report"), {**written, "clock": {"real_time_factor": 2.0}})
    finished = {**records[-1]}
    del finished["clock"]
    assert problems(validator("events"), finished)


def test_a_report_rebuilt_from_the_journal_matches_the_schema(run, tmp_path):
    _, _, folder = run
    copy = shutil.copytree(folder / "out", tmp_path / "out")
    (copy / "report.json").unlink()
    done = navseq("report", copy, cwd=tmp_path)
    assert done.returncode in (0, 1), done.stderr
    rebuilt = json.loads((copy / "report.json").read_text())
    assert problems(validator("report"), rebuilt) == []


def test_navseq_plan_json_matches_its_schema(tmp_path: Path) -> None:
    from navseq.commands import plan

    check = validator("plan")
    schema = json.loads((SCHEMAS / "plan.schema.json").read_text())
    assert schema["properties"]["schema_version"]["const"] == plan.SCHEMA_VERSION
    patrol = write_mission(tmp_path / "patrol.yaml", MISSION, f"map: {TURTLEBOT3_MAP}\nloops: 2\n")
    no_map = write_mission(tmp_path / "line.yaml", "  - {x: 0, y: 0}\n  - {x: 2, y: 0}\n")
    example = REPO / "examples" / "turtlebot3_world.yaml"
    for args in [
        (example, "--order", "shortest", "--out", tmp_path / "ordered.yaml"),
        (patrol,),
        (no_map, "--order", "shortest"),
    ]:
        done = navseq("plan", *args, "--json", cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        route = json.loads(done.stdout)
        assert problems(check, route) == [], args
    assert problems(check, {**route, "length": 1.0})  # an unknown, unit-less name
