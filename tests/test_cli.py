"""The ``navseq`` command end to end, run as a subprocess the way a user runs it.

These tests use the hidden ``--navigator scripted`` (a deterministic stand-in for a
navigation stack) to check the command's plumbing: arguments, exit statuses, output
files, signals and resume. ``test_cli_sim.py`` runs the embedded simulator.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from cli_support import (
    EXAMPLES,
    NAVSEQ,
    TURTLEBOT3_MAP,
    assert_clean_error,
    journal_events,
    journal_records,
    kill_9_when,
    navseq,
    start_navseq,
    start_scripted_run,
    wait_for,
    write_mission,
)


def scripted_log(path: Path, call: str) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    return [r for r in map(json.loads, path.read_text().splitlines()) if r["call"] == call]


SQUARE = """\
  - {name: a, x: 1.0, y: 0.0, yaw: 90}
  - {name: b, x: 1.0, y: 1.0, yaw: 180}
  - {name: c, x: 0.0, y: 1.0, yaw: -90}
  - {name: d, x: 0.0, y: 0.0, yaw: 0}
"""


def run_scripted(
    tmp_path: Path,
    *extra: Any,
    mission: Path | None = None,
) -> subprocess.CompletedProcess[str]:
    mission = mission or write_mission(tmp_path / "square.yaml", SQUARE)
    return navseq(
        "run", mission, "--navigator", "scripted", "--out", tmp_path / "out", *extra, cwd=tmp_path
    )


# ----------------------------------------------------------------------- basics


def test_version(tmp_path):
    result = navseq("--version", cwd=tmp_path)
    assert result.returncode == 0
    assert result.stdout.startswith("navseq 0.")


def test_no_command_prints_usage_and_exits_2(tmp_path):
    result = navseq(cwd=tmp_path)
    assert result.returncode == 2
    assert "run" in result.stderr and "validate" in result.stderr and "convert" in result.stderr


def test_python_dash_m_navseq_is_the_same_command(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "navseq", "--version"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0 and result.stdout.startswith("navseq ")


def test_bad_argument_value_is_a_usage_error(tmp_path):
    result = navseq("run", "m.yaml", "--start", "1,two,3", cwd=tmp_path)
    assert_clean_error(result)
    assert "--start" in result.stderr and "x,y,yaw" in result.stderr


# --------------------------------------------------------------------- validate


def test_validate_accepts_a_good_mission(tmp_path):
    result = navseq("validate", EXAMPLES / "tutorial_move_base_seq.launch", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "OK" in result.stdout and "3 waypoints" in result.stdout


def test_validate_lists_every_problem_with_file_line_and_field(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "navseq: 1\n"
        "loops: 0\n"
        "defaults: {goal_timout: 10}\n"
        "waypoints:\n"
        "  - {name: a, x: 1.0, y: .nan, yaw: 0}\n"
        "  - {name: a, x: 2.0, y: 0.0, yaw: 0}\n"
    )
    result = navseq("validate", bad, cwd=tmp_path)
    assert_clean_error(result)
    problems = [line for line in result.stderr.splitlines() if line.strip().startswith("- ")]
    assert len(problems) >= 4, result.stderr
    assert "bad.yaml:2" in result.stderr and "loops" in result.stderr
    assert "bad.yaml:3" in result.stderr and "goal_timeout" in result.stderr  # suggestion
    assert "bad.yaml:5" in result.stderr and "waypoint 1 'a'" in result.stderr
    assert "bad.yaml:6" in result.stderr  # the duplicate name


def test_validate_tutorial_launch_with_mismatched_counts(tmp_path):
    launch = tmp_path / "seq.launch"
    launch.write_text(
        "<launch>\n"
        '  <node pkg="simple_navigation_goals" type="move_base_seq.py" name="move_base_seq">\n'
        '    <rosparam param="p_seq">[-1,-4,0,1,-4,0,1,-1,0]</rosparam>\n'
        '    <rosparam param="yea_seq">[90,0]</rosparam>\n'
        "  </node>\n"
        "</launch>\n"
    )
    result = navseq("validate", launch, cwd=tmp_path)
    assert_clean_error(result)
    assert "seq.launch:" in result.stderr and "yea_seq" in result.stderr
    assert "2" in result.stderr and "3" in result.stderr


@pytest.mark.parametrize("content", [b"\x00\x01\x02\xff" * 100, b"just some words\n"])
def test_validate_rejects_files_that_are_not_missions(tmp_path, content):
    path = tmp_path / "mission.yaml"
    path.write_bytes(content)
    result = navseq("validate", path, cwd=tmp_path)
    assert_clean_error(result)
    assert "mission.yaml" in result.stderr


def test_validate_missing_file(tmp_path):
    result = navseq("validate", tmp_path / "nope.yaml", cwd=tmp_path)
    assert_clean_error(result)
    assert "nope.yaml" in result.stderr


def test_validate_against_a_map_finds_a_waypoint_in_a_pillar(tmp_path):
    mission = write_mission(
        tmp_path / "m.yaml",
        (
            "  - {name: free, x: 0.5, y: -1.6, yaw: 0}\n"
            "  - {name: pillar, x: 0.0, y: 0.0, yaw: 0}\n"
            "  - {name: outside, x: 30.0, y: 0.0, yaw: 0}\n"
        ),
    )
    result = navseq(
        "validate", mission, "--map", TURTLEBOT3_MAP, "--start", "-2,-0.5,0", cwd=tmp_path
    )
    assert_clean_error(result)
    assert "waypoint 2 'pillar'" in result.stderr
    assert "waypoint 3 'outside'" in result.stderr
    assert "waypoint 1 'free'" not in result.stderr


def test_validate_lists_file_and_map_problems_in_one_run(tmp_path):
    """A typo in one waypoint does not hide that another one sits in a pillar."""
    mission = write_mission(
        tmp_path / "m.yaml",
        (
            "  - {name: free, x: 0.5, y: -1.6, yaw: 0}\n"
            "  - {name: typo, x: 1.0, y: oops}\n"
            "  - {name: pillar, x: 0.0, y: 0.0, yaw: 0}\n"
            "  - {name: far, x: 1.6, y: 0.5, yaw: 90, goal_timeout: -1}\n"
        ),
        header=f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n",
    )
    result = navseq("validate", mission, cwd=tmp_path)
    assert_clean_error(result)
    lines = [line for line in result.stderr.splitlines() if line.startswith("  - ")]
    assert len(lines) == 3, result.stderr
    assert "m.yaml:6, waypoint 2 'typo', field y" in lines[0]
    assert "m.yaml:8, waypoint 4 'far', field goal_timeout" in lines[1]
    # numbered as in the file, though waypoint 2 could not be read
    assert "m.yaml:7, waypoint 3 'pillar'" in lines[2] and "nearest free spot" in lines[2]


def test_validate_names_an_unreadable_map_next_to_the_file_problems(tmp_path):
    mission = write_mission(
        tmp_path / "m.yaml",
        "  - {x: 1.0, y: oops}\n  - {x: 0.5, y: 0.5}\n",
        header="map: missing_map.yaml\n",
    )
    result = navseq("validate", mission, cwd=tmp_path)
    assert_clean_error(result)
    assert "field y" in result.stderr and "missing_map.yaml" in result.stderr


# ---------------------------------------------------------------------- convert


def test_convert_writes_navseq_yaml_and_never_overwrites(tmp_path):
    out = tmp_path / "tutorial.yaml"
    result = navseq("convert", EXAMPLES / "tutorial_move_base_seq.launch", out, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert navseq("validate", out, cwd=tmp_path).returncode == 0
    text = out.read_text()
    assert "yaw: 90" in text and "x: -1" in text

    out.write_text("# my own notes\n")
    again = navseq("convert", EXAMPLES / "recorded.csv", out, cwd=tmp_path)
    assert_clean_error(again)
    assert "--force" in again.stderr
    assert out.read_text() == "# my own notes\n"

    forced = navseq("convert", EXAMPLES / "recorded.csv", out, "--force", cwd=tmp_path)
    assert forced.returncode == 0, forced.stderr
    assert "waypoints:" in out.read_text()


def test_convert_of_a_broken_file_is_a_clean_error(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("1,2,0,0,0,0,1\n3,x,0,0,0,0,1\n")
    result = navseq("convert", bad, tmp_path / "out.yaml", cwd=tmp_path)
    assert_clean_error(result)
    assert "bad.csv:2" in result.stderr
    assert not (tmp_path / "out.yaml").exists()


# ------------------------------------------------------------- run (scripted)


def test_run_writes_report_picture_and_journal(tmp_path):
    result = run_scripted(tmp_path)
    assert result.returncode == 0, result.stderr
    out = tmp_path / "out"
    report = json.loads((out / "report.json").read_text())
    assert report["success"] is True and report["exit_code"] == 0
    assert report["totals"]["reached"] == 4 and report["totals"]["visits"] == 4
    assert [v["name"] for v in report["visits"]] == ["a", "b", "c", "d"]
    assert report["navigator"]["kind"] == "scripted"
    assert report["mission"]["source"].endswith("square.yaml")
    assert (out / "mission.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert journal_events(out / "journal.jsonl", "MissionFinished")[-1]["success"] is True
    # The summary table and the file list end the (plain) output.
    assert "✓ reached" in result.stdout and str(out / "report.json") in result.stdout


def test_plain_log_lines_when_stdout_is_not_a_terminal(tmp_path):
    result = run_scripted(tmp_path)
    assert "\x1b[" not in result.stdout  # no terminal control codes
    lines = result.stdout.splitlines()
    assert any("waypoint 2/4 'b': going to (1.00, 1.00, 180°)" in line for line in lines)
    assert any("mission finished: completed" in line for line in lines)


def test_failed_waypoint_gives_exit_1_and_says_why(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", SQUARE, "defaults: {on_failure: skip}\n")
    result = run_scripted(tmp_path, "--scripted-script", "succeed,aborted@1", mission=mission)
    assert result.returncode == 1, result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["success"] is False and report["exit_code"] == 1
    second = report["visits"][1]
    assert second["outcome"] == "skipped" and second["reason"] == "ABORTED"
    assert report["totals"]["reached"] == 3 and report["totals"]["skipped"] == 1


def test_json_output_is_one_object_per_line(tmp_path):
    result = run_scripted(tmp_path, "--json")
    assert result.returncode == 0, result.stderr
    records = [json.loads(line) for line in result.stdout.splitlines()]
    kinds = [r["event"] for r in records]
    assert kinds[0] == "MissionStarted" and kinds[-2] == "MissionFinished"
    assert kinds.count("WaypointFinished") == 4
    assert records[-1]["event"] == "RunFinished" and records[-1]["exit_code"] == 0
    assert Path(records[-1]["files"]["report"]).exists()


def test_run_never_overwrites_earlier_output(tmp_path):
    assert run_scripted(tmp_path).returncode == 0
    first = (tmp_path / "out" / "report.json").read_text()
    assert run_scripted(tmp_path).returncode == 0
    assert (tmp_path / "out" / "report.json").read_text() == first
    assert (tmp_path / "out" / "report-2.json").exists()
    assert (tmp_path / "out" / "mission-2.png").exists()
    assert (tmp_path / "out" / "journal-2.jsonl").exists()


def test_default_output_folder_is_named_after_mission_and_time(tmp_path):
    mission = write_mission(tmp_path / "square.yaml", SQUARE)
    result = navseq("run", mission, "--navigator", "scripted", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    folders = list((tmp_path / "navseq-out").iterdir())
    assert len(folders) == 1 and folders[0].name.startswith("square-20")
    assert {p.name for p in folders[0].iterdir()} == {"report.json", "mission.png", "journal.jsonl"}


def test_run_with_a_broken_mission_writes_nothing(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", "  - {x: 1.0, y: oops}\n")
    result = run_scripted(tmp_path, mission=mission)
    assert_clean_error(result)
    assert "m.yaml:3" in result.stderr
    assert not (tmp_path / "out").exists()


def test_sim_without_a_map_is_a_clean_error(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    result = navseq("run", mission, "--out", tmp_path / "out", cwd=tmp_path)
    assert_clean_error(result)
    assert "--map" in result.stderr


def test_internal_errors_are_one_line_unless_debug(tmp_path):
    # "bogus" is not a goal status: the test-only script parser fails unexpectedly.
    result = run_scripted(tmp_path, "--scripted-script", "bogus")
    assert result.returncode == 3
    assert "internal error" in result.stderr and "--debug" in result.stderr
    assert "Traceback" not in result.stderr
    debug = run_scripted(tmp_path, "--scripted-script", "bogus", "--debug")
    assert debug.returncode == 3 and "Traceback" in debug.stderr


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_signal_cancels_the_goal_and_reports_interrupted(tmp_path, name):
    signum, status = {"SIGINT": (signal.SIGINT, 130), "SIGTERM": (signal.SIGTERM, 143)}[name]
    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    log = tmp_path / "nav.log"
    process = start_navseq(
        "run",
        mission,
        "--navigator",
        "scripted",
        "--out",
        tmp_path / "out",
        "--scripted-realtime",
        "1",
        "--scripted-log",
        log,
        cwd=tmp_path,
    )
    wait_for(lambda: scripted_log(log, "send_goal"), 30, "the first goal")
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == status, stderr
    assert "Traceback" not in stderr
    cancels = scripted_log(log, "cancel_goal")
    assert cancels and cancels[0]["goal_id"] == scripted_log(log, "send_goal")[-1]["goal_id"]
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["interrupted"] == name and report["exit_code"] == status
    assert report["success"] is False and report["totals"]["not_run"] >= 1
    finished = journal_events(tmp_path / "out" / "journal.jsonl", "MissionFinished")
    assert finished and name in finished[-1]["reason"]
    assert (tmp_path / "out" / "mission.png").exists()


def test_resume_after_kill_runs_only_what_is_left(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    log = tmp_path / "nav.log"
    out = tmp_path / "out"
    process = start_scripted_run(mission, out, "--scripted-log", log, realtime=4, cwd=tmp_path)
    journal = out / "journal.jsonl"
    kill_9_when(
        process,
        lambda: len(journal_events(journal, "WaypointFinished")) >= 2,
        60,
        "two waypoints reached",
    )
    reached = {e["index"] for e in journal_events(journal, "WaypointFinished")}

    resumed_log = tmp_path / "resumed.log"
    # Another directory: the journal names the mission by its absolute path.
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    result = navseq(
        "run",
        "--resume",
        journal,
        "--navigator",
        "scripted",
        "--scripted-log",
        resumed_log,
        cwd=elsewhere,
    )
    assert result.returncode == 0, result.stderr
    sent = [(round(g["x"], 3), round(g["y"], 3)) for g in scripted_log(resumed_log, "send_goal")]
    square = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]
    assert sent == [p for i, p in enumerate(square) if i not in reached]
    # The killed run left no (empty) report behind: the resumed run writes the report.
    assert [p.name for p in out.glob("report*.json")] == ["report.json"]
    report = json.loads((out / "report.json").read_text())
    assert report["success"] is True and report["totals"]["reached"] == 4
    assert any(r.get("kind") == "resumed" for r in journal_records(journal))


def test_resumed_picture_shows_the_path_driven_before_the_crash(tmp_path, monkeypatch):
    from navseq import cli
    from navseq.journal.writer import read_journal
    from navseq.sinks.picture import draw as picture

    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    out = tmp_path / "out"
    process = start_scripted_run(mission, out, realtime=4, cwd=tmp_path)
    journal = out / "journal.jsonl"
    kill_9_when(
        process,
        lambda: len(journal_events(journal, "WaypointFinished")) >= 2,
        60,
        "two waypoints reached",
    )
    before = read_journal(journal)
    driven_before = [(e["x"], e["y"]) for e in journal_events(journal, "WaypointProgress")]
    assert len(driven_before) >= 2  # the scripted robot drove 2 m: corners and visit ends

    drawn: dict[str, Any] = {}
    real_draw = picture.mission_picture_png
    monkeypatch.setattr(
        picture, "mission_picture_png", lambda *a, **kw: drawn.update(kw) or real_draw(*a, **kw)
    )
    assert cli.main(["run", "--resume", str(journal), "--navigator", "scripted"]) == 0

    points = [tuple(p) for p in drawn["trajectory"]]
    finite = [p for p in points if not any(map(math.isnan, p))]
    # Everything driven before the crash is in the picture, then a break, then the rest.
    assert [(x, y) for _, x, y in finite[: len(driven_before)]] == driven_before
    assert math.isnan(points[len(driven_before)][0])
    after = finite[len(driven_before) :]
    assert {(round(x, 3), round(y, 3)) for _, x, y in after} >= {(0.0, 1.0), (0.0, 0.0)}
    # One mission clock: the resumed part is coloured after the part before the crash.
    times = [t for t, _, _ in finite]
    assert times == sorted(times)
    assert after[0][0] >= before.previous_duration > 0


def test_resume_refuses_a_changed_mission(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    assert run_scripted(tmp_path, mission=mission).returncode == 0
    mission.write_text(mission.read_text().replace("x: 1.0, y: 0.0", "x: 1.5, y: 0.0"))
    result = navseq(
        "run",
        "--resume",
        tmp_path / "out" / "journal.jsonl",
        "--navigator",
        "scripted",
        cwd=tmp_path,
    )
    assert_clean_error(result)
    assert "journal.jsonl" in result.stderr and "changed" in result.stderr.lower()


def test_resume_of_something_that_is_not_a_journal(tmp_path):
    bogus = tmp_path / "journal.jsonl"
    bogus.write_text('{"hello": 1}\n')
    result = navseq("run", "--resume", bogus, "--navigator", "scripted", cwd=tmp_path)
    assert_clean_error(result)
    assert "journal.jsonl" in result.stderr


def test_ros1_without_a_server_is_a_clean_error(tmp_path):
    pytest.importorskip("rospy", reason="ROS 1 Python packages are not installed")
    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    env_master = {"ROS_MASTER_URI": "http://127.0.0.1:9"}  # nothing listens on port 9
    result = subprocess.run(
        [NAVSEQ, "run", str(mission), "--navigator", "ros1", "--out", str(tmp_path / "out")],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **env_master, "ROS_HOME": str(tmp_path / "ros")},
    )
    assert_clean_error(result)
    assert "master" in result.stderr.lower() or "move_base" in result.stderr
    assert not (tmp_path / "out").exists()  # no run, no output folder


def test_reader_going_away_does_not_stop_the_mission_or_lose_the_report(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", SQUARE)
    log = tmp_path / "nav.log"
    process = start_navseq(
        "run",
        mission,
        "--navigator",
        "scripted",
        "--json",
        "--out",
        tmp_path / "out",
        "--scripted-realtime",
        "2",
        "--scripted-log",
        log,
        cwd=tmp_path,
    )
    assert json.loads(process.stdout.readline())["event"] == "MissionStarted"
    process.stdout.close()  # like `navseq run --json ... | head -1`
    stderr = process.stderr.read()
    assert process.wait(timeout=60) == 0, stderr  # the mission went on to the end
    assert "Traceback" not in stderr
    assert "standard output was closed" in stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["success"] is True and report["exit_code"] == 0
    assert len(scripted_log(log, "send_goal")) == 4


def test_record_refuses_to_overwrite_a_mission_file(tmp_path):
    existing = tmp_path / "mine.yaml"
    existing.write_text("# my mission\n")
    result = navseq("record", existing, cwd=tmp_path)
    assert_clean_error(result)
    assert "mine.yaml" in result.stderr
    assert existing.read_text() == "# my mission\n"


def test_out_pointing_at_a_file_is_a_clean_error(tmp_path):
    not_a_folder = tmp_path / "notes.txt"
    not_a_folder.write_text("keep me\n")
    result = run_scripted(tmp_path, "--out", not_a_folder)
    assert_clean_error(result)
    assert "notes.txt" in result.stderr and "not a folder" in result.stderr
    assert not_a_folder.read_text() == "keep me\n"
