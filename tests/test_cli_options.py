"""``navseq run``'s part-of-mission, pacing and picture options, and the messages of
the CLI: each names the thing, the problem and the fix, once.

Run as a user runs the command (a subprocess, output not a terminal), on the hidden
``scripted`` navigator where the plumbing is what is tested, on the simulator where
pacing is.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path
from typing import Any

import pytest

from cli_support import (
    EXAMPLES,
    REPO,
    TURTLEBOT3_MAP,
    assert_clean_error,
    journal_events,
    journal_records,
    kill_9_when,
    navseq,
    start_scripted_run,
    write_mission,
)
from navseq.cli import build_parser
from navseq.navigators.sim import SimNavigator

SIX = "".join(
    f"  - {{name: {name}, x: {x}, y: {y}, yaw: 0}}\n"
    for name, x, y in (
        ("a", 1.0, 0.0),
        ("b", 2.0, 0.0),
        ("c", 3.0, 0.0),
        ("d", 3.0, 1.0),
        ("e", 2.0, 1.0),
        ("f", 1.0, 1.0),
    )
)
MAP_IMAGE = REPO / "maps" / "turtlebot3_world.pgm"


def scripted(tmp_path: Path, *extra: Any, mission: Path | None = None):
    mission = mission or write_mission(tmp_path / "six.yaml", SIX)
    return navseq(
        "run", mission, "--navigator", "scripted", "--out", tmp_path / "out", *extra, cwd=tmp_path
    )


def table_numbers(stdout: str) -> list[str]:
    """The # column of the summary table's body rows."""
    return re.findall(r"^│\s+(\d+(?:-\d+)?) │", stdout, flags=re.MULTILINE)


def report_of(tmp_path: Path) -> dict[str, Any]:
    return json.loads((tmp_path / "out" / "report.json").read_text())


# ---------------------------------------------------------------- part of a mission


def test_from_and_to_run_that_part_numbered_as_in_the_file(tmp_path):
    result = scripted(tmp_path, "--from", "3", "--to", "5")
    assert result.returncode == 0, result.stderr
    assert table_numbers(result.stdout) == ["3", "4", "5"]
    assert "waypoint 3 'c' (1/3): going to" in result.stdout
    assert "waypoints 3-5 of 6, --from 3 --to 5" in result.stdout
    report = report_of(tmp_path)
    assert report["part"]["numbers"] == [3, 4, 5] and report["part"]["from"] == 3
    assert [visit["number"] for visit in report["visits"]] == [3, 4, 5]
    assert [visit["name"] for visit in report["visits"]] == ["c", "d", "e"]


def test_a_part_that_stops_says_the_files_number_everywhere(tmp_path):
    """Waypoint 4 (the part's second) fails: every message says 4, as the table does."""
    result = scripted(tmp_path, "--from", "3", "--to", "5", "--scripted-script", "succeed,aborted")
    assert result.returncode == 1, result.stderr
    reason = "stopped: waypoint 4 'd' failed (ABORTED)"
    assert f"mission finished: {reason}" in result.stdout  # the progress line
    assert f"six.yaml (waypoints 3-5 of 6, --from 3 --to 5): {reason}" in result.stdout
    assert "waypoint 2 " not in result.stdout and "waypoint 1 " not in result.stdout
    report = report_of(tmp_path)
    assert report["reason"] == reason
    assert [visit["number"] for visit in report["visits"]] == [3, 4, 5]
    # --json: index is the position in the part, number the file's, as in the report.
    as_json = scripted(
        tmp_path, "--from", "3", "--to", "5", "--scripted-script", "succeed,aborted", "--json"
    )
    records = [json.loads(line) for line in as_json.stdout.splitlines()]
    finished = [r for r in records if r["event"] == "WaypointFinished"]
    assert [(r["index"], r["number"]) for r in finished] == [(0, 3), (1, 4)]
    assert records[-1]["event"] == "RunFinished" and records[-1]["reason"] == reason


def test_only_takes_names_and_numbers_in_the_missions_order(tmp_path):
    result = scripted(tmp_path, "--only", "e,2")
    assert result.returncode == 0, result.stderr
    assert table_numbers(result.stdout) == ["2", "5"]
    assert report_of(tmp_path)["part"]["only"] == "e,2"


def test_a_whole_run_reports_no_part(tmp_path):
    result = scripted(tmp_path)
    assert result.returncode == 0, result.stderr
    assert table_numbers(result.stdout) == ["1", "2", "3", "4", "5", "6"]
    assert report_of(tmp_path)["part"] is None


def test_bad_part_options_name_the_option_and_what_is_valid(tmp_path):
    cases = {
        ("--from", "9"): ["--from", "numbered 1 to 6"],
        ("--from", "0"): ["--from", "numbered 1 to 6"],
        ("--from", "4", "--to", "2"): ["--to", "at least --from"],
        ("--only", "x,7"): ["--only", "'x', '7'", "a, b, c, d, e, f", "1 to 6"],
        ("--only", "a", "--from", "2"): ["--only", "either --only or --from/--to"],
        ("--from", "two"): ["--from", "expected a waypoint number"],
    }
    for args, expected in cases.items():
        result = scripted(tmp_path, *args)
        assert_clean_error(result)
        for text in expected:
            assert text in result.stderr, (args, result.stderr)
        assert not (tmp_path / "out" / "journal.jsonl").exists()


def test_a_resume_continues_the_same_part(tmp_path):
    mission = write_mission(tmp_path / "six.yaml", SIX)
    log = tmp_path / "nav.log"
    out = tmp_path / "out"
    process = start_scripted_run(
        mission, out, "--from", "2", "--to", "5", "--scripted-log", log, realtime=4, cwd=tmp_path
    )
    journal = out / "journal.jsonl"
    kill_9_when(
        process,
        lambda: len(journal_events(journal, "WaypointFinished")) >= 1,
        60,
        "one waypoint reached",
    )
    header = journal_records(journal)[0]
    assert header["run"]["from_waypoint"] == 2
    assert header["run"]["to_waypoint"] == 5

    other_part = navseq("run", "--resume", journal, "--only", "a", cwd=tmp_path)
    assert_clean_error(other_part)
    assert "--from 2 --to 5" in other_part.stderr

    resumed_log = tmp_path / "resumed.log"
    result = navseq(
        "run", "--resume", journal, "--navigator", "scripted", "--scripted-log", resumed_log,
        cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    sent = [
        round(json.loads(line)["x"], 3)
        for line in resumed_log.read_text().splitlines()
        if json.loads(line)["call"] == "send_goal"
    ]
    done = len(journal_events(journal, "WaypointFinished"))
    # Waypoints 2-5 are x = 2, 3, 3, 2; the resume sends only those not yet reached.
    assert done == 4 and sent == [2.0, 3.0, 3.0, 2.0][-len(sent) :] and len(sent) < 4
    assert table_numbers(result.stdout) == ["2", "3", "4", "5"]
    rebuilt = navseq("report", out, cwd=tmp_path)  # complete: nothing to do, no error
    assert rebuilt.returncode == 0, rebuilt.stderr


# --------------------------------------------------------------- picture and pacing


def test_no_picture_writes_none_and_the_report_names_none(tmp_path):
    result = scripted(tmp_path, "--no-picture")
    assert result.returncode == 0, result.stderr
    assert not list((tmp_path / "out").glob("*.png"))
    assert "picture" not in report_of(tmp_path)["files"]
    assert "picture:" not in result.stdout
    # Nor does rebuilding the report draw one: the run said no picture.
    (tmp_path / "out" / "report.json").unlink()
    rebuilt = navseq("report", tmp_path / "out", cwd=tmp_path)
    assert rebuilt.returncode == 0, rebuilt.stderr
    assert not list((tmp_path / "out").glob("*.png"))
    assert "picture" not in report_of(tmp_path)["files"]


def real_time_factor(stdout: str) -> tuple[float, float, float]:
    found = re.search(r"simulated ([\d.]+) s in ([\d.]+) s: ([\d.]+)x real time", stdout)
    assert found, stdout
    simulated, wall, factor = map(float, found.groups())
    return simulated, wall, factor


def test_the_simulator_says_how_fast_it_ran_and_realtime_paces_it(tmp_path):
    patrol = EXAMPLES / "patrol.yaml"
    common = ("run", patrol, "--loops", "1", "--only", "south", "--no-picture")
    fast = navseq(*common, "--out", tmp_path / "fast", cwd=tmp_path)
    assert fast.returncode == 0, fast.stderr
    simulated, fast_wall, fast_factor = real_time_factor(fast.stdout)
    assert simulated > 5.0
    # However short the wall time, the figures printed agree with each other.
    assert fast_wall > 0 and simulated / fast_wall == pytest.approx(fast_factor, rel=0.25)
    paced = navseq(*common, "--realtime", "20", "--out", tmp_path / "paced", cwd=tmp_path)
    assert paced.returncode == 0, paced.stderr
    _, wall, factor = real_time_factor(paced.stdout)
    # Pacing only ever waits: never faster than asked (rounding of the printed figure aside).
    assert factor <= 21 and wall >= simulated / 21


def test_pacing_sleeps_until_the_wall_clock_catches_up_with_simulated_time():
    from navseq.sim.occupancy import load_map
    from navseq.sim.world import SimWorld, default_start

    grid = load_map(TURTLEBOT3_MAP)
    wall = [100.0]
    slept: list[float] = []

    def sleep(seconds: float) -> None:
        slept.append(seconds)
        wall[0] += seconds

    world = SimWorld(grid, default_start(grid))
    navigator = SimNavigator(world, realtime=2.0, wall_clock=lambda: wall[0], sleep=sleep)
    start = world.time
    navigator.spin(3.0)
    # Half as much wall time as simulated time (the first step sets the origin).
    assert abs((wall[0] - 100.0) - (world.time - start - world.dt) / 2.0) < 1e-9
    assert slept and all(seconds > 0 for seconds in slept)
    unpaced = SimNavigator(SimWorld(grid, default_start(grid)), sleep=sleep)
    before = len(slept)
    unpaced.spin(3.0)
    assert len(slept) == before  # without realtime: as fast as it can


# ----------------------------------------------------------------------- messages


def test_run_without_a_mission_says_so_once(tmp_path):
    result = navseq("run", cwd=tmp_path)
    assert_clean_error(result)
    assert result.stderr.count("navseq run") == 2  # the prefix, and the example command
    assert result.stderr.startswith("navseq run: no mission given")
    assert "--resume JOURNAL" in result.stderr


def test_a_map_image_given_for_the_map_yaml_says_to_give_the_yaml(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 0.5, y: 0.5, yaw: 0}\n")
    for command in ("run", "validate"):
        result = navseq(command, mission, "--map", MAP_IMAGE, cwd=tmp_path)
        assert_clean_error(result)
        assert "is a map image" in result.stderr and "YAML" in result.stderr
        assert "turtlebot3_world.yaml?" in result.stderr  # the YAML beside it
        assert "codec" not in result.stderr and "NUL" not in result.stderr


def test_validate_reports_a_missing_mission_and_a_missing_map_together(tmp_path):
    result = navseq("validate", "nonexist.yaml", "--map", "/nope.yaml", cwd=tmp_path)
    assert_clean_error(result)
    assert "2 problems found" in result.stderr
    assert "nonexist.yaml: no such file" in result.stderr
    assert "--map: no such file: /nope.yaml" in result.stderr


def test_start_and_realtime_are_refused_with_ros1(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 0.5, y: 0.5, yaw: 0}\n")
    start = navseq("run", mission, "--navigator", "ros1", "--start", "0,0,0", cwd=tmp_path)
    assert_clean_error(start)
    assert start.stderr.startswith("navseq run: --start:") and "/initialpose" in start.stderr
    paced = navseq("run", mission, "--navigator", "ros1", "--realtime", cwd=tmp_path)
    assert_clean_error(paced)
    assert paced.stderr.startswith("navseq run: --realtime:")


def test_a_realtime_factor_that_is_not_one_says_why(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 0.5, y: 0.5, yaw: 0}\n")
    swallowed = navseq("run", "--realtime", mission, cwd=tmp_path)
    assert_clean_error(swallowed)
    assert "put MISSION before --realtime" in swallowed.stderr
    assert_clean_error(navseq("run", mission, "--realtime", "0", cwd=tmp_path))


def test_every_option_of_every_command_has_help():
    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = [
        f"navseq {name} {action.option_strings or action.dest}"
        for name, sub in commands.choices.items()
        for action in sub._actions
        if not action.help
    ]
    assert missing == []


def test_no_message_of_the_cli_repeats_its_prefix(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 0.5, y: 0.5, yaw: 0}\n")
    for args in (
        ("run",),
        ("run", "nope.yaml"),
        ("run", mission, "--map", "/nope.yaml"),
        ("validate", "nope.yaml"),
        ("report", tmp_path),
        ("convert", "nope.yaml", tmp_path / "x.yaml"),
    ):
        result = navseq(*args, cwd=tmp_path)
        assert result.returncode != 0
        prefix = f"navseq {args[0]}: "
        assert f"{prefix}{prefix}" not in result.stderr
        assert f"{prefix}navseq " not in result.stderr, result.stderr


def test_summary_in_a_pipe_keeps_long_names_whole(tmp_path):
    name = "north-most-corner-of-the-loading-bay-beside-the-red-door-" * 2
    mission = write_mission(tmp_path / "long.yaml", f"  - {{name: {name}, x: 1, y: 0, yaw: 0}}\n")
    result = scripted(tmp_path, "--scripted-script", "aborted", mission=mission)
    assert result.returncode == 1
    assert name in result.stdout
    assert "…" not in result.stdout
    assert "mission finished: stopped" in result.stdout


def test_report_of_a_folder_that_is_no_run_says_what_to_give(tmp_path):
    result = navseq("report", tmp_path, cwd=tmp_path)
    assert_clean_error(result)
    assert "is not a run's output folder (it has no journal.jsonl)" in result.stderr
    assert "navseq-out/" in result.stderr


def test_a_file_that_is_no_robot_is_quoted_short_and_the_robots_listed_once(tmp_path):
    not_a_robot = tmp_path / "notes.yaml"
    not_a_robot.write_text("x" * 5000 + "\n")
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 0.5, y: 0.5, yaw: 0}\n")
    result = navseq("validate", mission, "--robot", not_a_robot, cwd=tmp_path)
    assert_clean_error(result)
    assert len(result.stderr) < 400
    assert result.stderr.count("turtlebot3_waffle_pi") == 1
