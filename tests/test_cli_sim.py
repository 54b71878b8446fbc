"""``navseq run`` on the embedded simulator, end to end, as a user runs it."""

from __future__ import annotations

import json
import signal

import pytest
from PIL import Image

from cli_support import (
    EXAMPLES,
    TURTLEBOT3_MAP,
    assert_clean_error,
    journal_events,
    navseq,
    start_navseq,
    wait_for,
    write_mission,
)

ARENA = """\
  - {name: south, x: 0.5, y: -1.6, yaw: 0}
  - {name: east, x: 1.6, y: 0.5, yaw: 90}
  - {name: north, x: -0.5, y: 1.6, yaw: 180}
"""


def arena_mission(tmp_path, waypoints: str = ARENA, extra: str = ""):
    header = f"map: {TURTLEBOT3_MAP}\nstart: {{x: -2.0, y: -0.5, yaw: 0}}\n{extra}"
    return write_mission(tmp_path / "arena.yaml", waypoints, header)


def test_example_mission_runs_to_the_end_and_writes_report_and_picture(tmp_path):
    result = navseq(
        "run", EXAMPLES / "turtlebot3_world.yaml", "--out", tmp_path / "out", cwd=tmp_path
    )
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["success"] is True and report["exit_code"] == 0
    assert report["navigator"]["kind"] == "sim"
    assert report["map"]["source"].endswith("turtlebot3_world.yaml")
    assert report["map"]["resolution_m"] == pytest.approx(0.05)
    assert report["start"] is not None
    visits = report["visits"]
    assert len(visits) >= 6 and all(v["outcome"] == "reached" for v in visits)
    assert all(v["distance_m"] > 0.1 and v["duration_s"] > 0 for v in visits)
    assert report["totals"]["distance_m"] == pytest.approx(
        sum(v["distance_m"] for v in visits), abs=0.05
    )
    with Image.open(tmp_path / "out" / "mission.png") as image:
        assert image.format == "PNG" and image.width > 800
    assert journal_events(tmp_path / "out" / "journal.jsonl", "MissionFinished")


def test_json_events_on_the_sim_carry_plans_and_progress(tmp_path):
    result = navseq(
        "run", arena_mission(tmp_path), "--json", "--out", tmp_path / "out", cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr
    records = [json.loads(line) for line in result.stdout.splitlines()]
    kinds = {r["event"] for r in records}
    assert {
        "MissionStarted",
        "WaypointPlan",
        "WaypointProgress",
        "WaypointFinished",
        "MissionFinished",
        "RunFinished",
    } <= kinds
    plan = next(r for r in records if r["event"] == "WaypointPlan")
    assert len(plan["path"]) > 2


def test_waypoints_in_a_pillar_and_off_the_map_stop_the_run_before_it_starts(tmp_path):
    mission = arena_mission(
        tmp_path,
        (
            "  - {name: ok, x: 0.5, y: -1.6, yaw: 0}\n"
            "  - {name: pillar, x: 0.0, y: 0.0, yaw: 0}\n"
            "  - {name: far, x: 40.0, y: 0.0, yaw: 0}\n"
        ),
    )
    result = navseq("run", mission, "--out", tmp_path / "out", cwd=tmp_path)
    assert_clean_error(result)
    assert "waypoint 2 'pillar'" in result.stderr and "waypoint 3 'far'" in result.stderr
    assert "'ok'" not in result.stderr
    assert not (tmp_path / "out").exists()  # nothing moved, nothing written


def test_start_inside_an_obstacle_is_a_preflight_error(tmp_path):
    result = navseq(
        "run", arena_mission(tmp_path), "--start", "0,0,0", "--out", tmp_path / "out", cwd=tmp_path
    )
    assert_clean_error(result)
    assert "start" in result.stderr


def test_unreachable_waypoint_without_preflight_is_skipped_and_marked(tmp_path):
    mission = arena_mission(
        tmp_path,
        (
            "  - {name: ok, x: 0.5, y: -1.6, yaw: 0}\n"
            "  - {name: pillar, x: 0.0, y: 0.0, yaw: 0}\n"
            "  - {name: back, x: -1.6, y: -0.5, yaw: 0}\n"
        ),
        extra="defaults: {on_failure: skip, retries: 0}\n",
    )
    result = navseq("run", mission, "--no-preflight", "--out", tmp_path / "out", cwd=tmp_path)
    assert result.returncode == 1, result.stdout + result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert [v["outcome"] for v in report["visits"]] == ["reached", "skipped", "reached"]
    assert report["visits"][1]["reason"] == "ABORTED"
    assert "skipped" in result.stdout


def test_without_a_start_pose_the_robot_starts_near_the_map_origin(tmp_path):
    mission = write_mission(tmp_path / "m.yaml", ARENA, f"map: {TURTLEBOT3_MAP}\n")
    result = navseq("run", mission, "--out", tmp_path / "out", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "no start pose given" in result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    start = report["start"]
    assert abs(start["x"]) < 1.0 and abs(start["y"]) < 1.0


def test_sigint_ends_a_forever_patrol_with_exit_130_and_an_interrupted_report(tmp_path):
    process = start_navseq(
        "run",
        arena_mission(tmp_path),
        "--loops",
        "forever",
        "--out",
        tmp_path / "out",
        cwd=tmp_path,
    )
    journal = tmp_path / "out" / "journal.jsonl"
    wait_for(
        lambda: len(journal_events(journal, "WaypointFinished")) >= 4,
        120,
        "a lap and a bit of the patrol",
    )
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert "Traceback" not in stdout + stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["interrupted"] == "SIGINT" and report["exit_code"] == 130
    assert report["mission"]["loops"] == "forever"
    assert report["totals"]["reached"] >= 4
    assert "interrupted" in journal_events(journal, "MissionFinished")[-1]["reason"]
    assert (tmp_path / "out" / "mission.png").exists()


def test_a_sim_run_inflates_the_map_once_for_preflight_and_navigation(tmp_path, monkeypatch):
    """Inflating a large map is the slow part of start-up: pre-flight and the simulated
    navigation server share one costmap."""
    from navseq.run import RunRequest, prepare
    from navseq.sim import costmap as costmap_module

    inflated = []
    real_inflate = costmap_module.inflate

    def counting_inflate(grid, params):
        inflated.append(grid)
        return real_inflate(grid, params)

    monkeypatch.setattr(costmap_module, "inflate", counting_inflate)
    setup = prepare(RunRequest(arena_mission(tmp_path)))
    navigator = setup.make_navigator()
    assert len(inflated) == 1
    assert navigator.world.server.costmap.grid is setup.grid
