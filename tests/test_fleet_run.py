"""``navseq run --fleet``: the robots of a fleet together on the embedded simulator."""

from __future__ import annotations

import json
from pathlib import Path

from cli_support import EXAMPLES, TURTLEBOT3_MAP, assert_clean_error, navseq
from navseq.mission import load_mission

FLEET = EXAMPLES / "fleet.yaml"


def fleet_report(folder: Path) -> dict:
    return json.loads((folder / "fleet-report.json").read_text())


def test_the_example_fleet_reaches_every_waypoint_and_leaves_one_folder(tmp_path: Path) -> None:
    out = tmp_path / "run"
    done = navseq("run", "--fleet", FLEET, "--out", out, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = fleet_report(out)
    assert (report["reached"], report["skipped"], report["failed"]) == (7, 0, 0)
    assert report["robot_overlaps"] == 0
    assert report["makespan_s"] == max(row["mission_time_s"] for row in report["robots"])
    for row in report["robots"]:
        own = out / row["name"]
        assert row["reached"] == row["waypoints"] > 0
        # Each robot's folder is a one-robot run's: its share, journal and report.
        assert len(load_mission(own / "mission.yaml").waypoints) == row["waypoints"]
        robot_report = json.loads((own / "report.json").read_text())
        assert robot_report["totals"]["reached"] == row["waypoints"]
        assert (own / "journal.jsonl").stat().st_size > 0
    assert (out / "fleet.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "fleet: 7 reached, 0 skipped, 0 failed" in done.stdout


def test_two_robots_that_swap_places_both_arrive_without_touching(tmp_path: Path) -> None:
    mission = tmp_path / "swap.yaml"
    mission.write_text(
        "navseq: 1\nwaypoints:\n"
        "  - {name: west, x: -1.6, y: -0.5, yaw: 180}\n"
        "  - {name: east, x: 1.6, y: -0.5, yaw: 0}\n"
    )
    fleet = tmp_path / "fleet.yaml"
    fleet.write_text(
        f"navseq_fleet: 1\nmission: swap.yaml\nmap: {TURTLEBOT3_MAP}\nrobots:\n"
        "  - {name: a, start: {x: -1.6, y: -0.5, yaw: 0}}\n"
        "  - {name: b, start: {x: 1.6, y: -0.5, yaw: 180}}\n"
        "waypoints:\n  west: {robots: [b]}\n  east: {robots: [a]}\n"
    )
    done = navseq("run", "--fleet", fleet, "--out", tmp_path / "run", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = fleet_report(tmp_path / "run")
    assert report["reached"] == 2 and report["robot_overlaps"] == 0


def test_a_robot_with_nothing_to_do_stays_parked_and_the_run_ends(tmp_path: Path) -> None:
    mission = tmp_path / "one.yaml"
    mission.write_text("navseq: 1\nwaypoints:\n  - {name: only, x: -0.55, y: -1.75}\n")
    fleet = tmp_path / "fleet.yaml"
    fleet.write_text(
        f"navseq_fleet: 1\nmission: one.yaml\nmap: {TURTLEBOT3_MAP}\nrobots:\n"
        "  - {name: a, start: {x: -2.0, y: -0.5, yaw: 0}}\n"
        "  - {name: b, start: {x: 2.0, y: 0.5, yaw: 180}}\n"
    )
    done = navseq("run", "--fleet", fleet, "--out", tmp_path / "run", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    rows = {row["name"]: row for row in fleet_report(tmp_path / "run")["robots"]}
    assert rows["a"]["reached"] == 1 and rows["b"]["waypoints"] == 0


def test_a_bad_fleet_file_moves_nothing_and_writes_nothing(tmp_path: Path) -> None:
    fleet = tmp_path / "fleet.yaml"
    fleet.write_text(FLEET.read_text().replace("x: 2.0, y: 0.5", "x: 0.0, y: 0.0"))
    mission = (EXAMPLES / "turtlebot3_world.yaml").read_text()
    (tmp_path / "turtlebot3_world.yaml").write_text(mission)
    out = tmp_path / "run"
    done = navseq("run", "--fleet", fleet, "--map", TURTLEBOT3_MAP, "--out", out, cwd=tmp_path)
    assert_clean_error(done)
    assert "robot 'beta', field start" in done.stderr
    assert not out.exists()


def test_options_a_fleet_run_cannot_honour_are_refused(tmp_path: Path) -> None:
    for extra, named in (
        (("--navigator", "scripted"), "--navigator scripted"),
        (("--navigator", "nav2", "--ns", "robot1"), "--ns"),
        (("--navigator", "ros1", "--realtime", "1"), "--realtime"),
        (("--start", "0,0,0"), "--start"),
        (("--resume", tmp_path / "run", "--out", tmp_path / "other"), "--out"),
        (("--resume", tmp_path / "journal.jsonl"), "is not a folder"),
        (("--record", "--record-topics", "/scan"), "--record-topics"),
    ):
        done = navseq("run", "--fleet", FLEET, *extra, cwd=tmp_path)
        assert_clean_error(done)
        assert named in done.stderr
        assert not (tmp_path / "navseq-out").exists()


def test_ctrl_c_stops_every_robot_and_the_fleet_s_outputs_are_still_written(
    tmp_path: Path,
) -> None:
    import signal
    import time

    from cli_support import start_navseq

    out = tmp_path / "run"
    process = start_navseq("run", "--fleet", FLEET, "--out", out, "--realtime", "1", cwd=tmp_path)
    try:
        deadline = time.monotonic() + 60
        # Under way once every robot's journal has its first waypoint started.
        while time.monotonic() < deadline and not all(
            (out / name / "journal.jsonl").exists()
            and "WaypointStarted" in (out / name / "journal.jsonl").read_text()
            for name in ("alpha", "beta", "gamma")
        ):
            time.sleep(0.1)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 130, stderr
    report = fleet_report(out)
    assert report["interrupted"] == "SIGINT" and report["reached"] < 7
    for name in ("alpha", "beta", "gamma"):
        robot_report = json.loads((out / name / "report.json").read_text())
        assert robot_report["totals"]["reached"] < robot_report["totals"]["visits"]


def test_json_prints_every_robot_s_events_one_record_a_line_each_naming_its_robot(
    tmp_path: Path,
) -> None:
    import jsonschema

    from cli_support import REPO

    out = tmp_path / "run"
    done = navseq("run", "--fleet", FLEET, "--out", out, "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    schema = json.loads((REPO / "docs" / "schemas" / "events.schema.json").read_text())
    records = [json.loads(line) for line in done.stdout.splitlines()]  # nothing but records
    for record in records:
        jsonschema.validate(record, schema)
    report = fleet_report(out)
    for row in report["robots"]:
        own = [r for r in records if r["robot"] == row["name"]]
        # Each robot's records are a one-robot run's: started, its waypoints, finished.
        assert own[0]["event"] == "MissionStarted" and own[-1]["event"] == "RunFinished"
        assert own[-1]["exit_code"] == row["exit_status"] == 0
        finished = [r for r in own if r["event"] == "WaypointFinished"]
        assert [r["outcome"] for r in finished] == ["reached"] * row["waypoints"]
        stamps = [r["t_s"] for r in own if "t_s" in r]
        assert stamps == sorted(stamps)  # on the fleet's one clock, forward
    assert {r["robot"] for r in records} == {"alpha", "beta", "gamma"}
    # The fleet's line goes to stderr: stdout is for programs.
    assert "fleet: 7 reached, 0 skipped, 0 failed" in done.stderr
