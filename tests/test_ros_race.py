"""move_base's SUCCEEDED race (ros-planning/navigation #949) on the simulator's ROS nodes.

On a real move_base a goal sent a few milliseconds after the previous goal's result can
inherit the plan still being computed for the old one and end SUCCEEDED at once, with the
robot metres away. The sim's move_base reproduces it with ``~race_window``; navseq's ros1
navigator stays out of it by waiting ``settle`` seconds (and for the server's status
array) after a result. A separate observer (``RESULT_WATCHER``) checks every SUCCEEDED
against the robot's pose from TF.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cli_support import NAVSEQ, write_mission
from navseq.mission.robot import DEFAULT_PROFILE
from ros_clients import (
    MAP,
    SUCCEEDED,
    goal,
    reports,
    run_client,
    start_result_watcher,
    start_sim,
)
from ros_support import REPO_ROOT, RosMaster, RosProcess

pytestmark = pytest.mark.ros

# Shorter than navseq's default settle (0.05 s), far longer than the 1-3 ms a client
# needs to answer a result with the next goal.
RACE_WINDOW = 0.03
RACE = (f"_race_window:={RACE_WINDOW}", "_race_probability:=1.0")
# Where a test needs the race to happen: on a loaded machine a client answering at once
# can still take more than RACE_WINDOW, and then there is no race to see.
WIDE_RACE = ("_race_window:=0.25", "_race_probability:=1.0")
WAYPOINTS = [(-1.6, -0.5, 90), (-0.55, -1.75, 0), (-1.6, -0.5, 180)]
# The sim's move_base succeeds within its xy tolerance; TF may lag a control step.
REACHED_WITHIN = DEFAULT_PROFILE.goal_tolerance.xy_m + 0.03


def mission(tmp_path: Path) -> Path:
    lines = "".join(f"  - {{x: {x}, y: {y}, yaw: {yaw}}}\n" for x, y, yaw in WAYPOINTS)
    return write_mission(tmp_path / "race.yaml", lines, "defaults: {goal_timeout: 120}\n")


def run_navseq(master: RosMaster, tmp_path: Path, *extra: str) -> tuple[RosProcess, Path]:
    out = tmp_path / "out"
    process = master.start(
        [
            NAVSEQ,
            "run",
            mission(tmp_path),
            "--navigator",
            "ros1",
            "--map",
            MAP,
            "--out",
            out,
            *extra,
        ],
        cwd=tmp_path,
        label="navseq",
    )
    process.wait(timeout=180)
    return process, out


def watched_results(watcher: RosProcess) -> list[dict]:
    return [r for r in reports(watcher) if "status" in r]


def test_the_race_option_gives_a_client_that_sends_at_once_a_far_succeeded(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master, nav_params=RACE)
    first, second = run_client(ros_master, tmp_path, [goal(-1.6, -0.5), goal(-0.55, -1.75)])
    assert first["state"] == SUCCEEDED
    assert second["state"] == SUCCEEDED
    # ...but the robot is still at the first goal, 1.6 m from the second.
    x, y, _ = second["pose"]
    assert abs(x - -1.6) < 0.1 and abs(y - -0.5) < 0.1, second


def test_with_the_settle_every_waypoint_is_truly_reached_despite_the_race(
    ros_master: RosMaster, tmp_path: Path
):
    _robot, nav = start_sim(ros_master, nav_params=RACE)
    watcher = start_result_watcher(ros_master, tmp_path)
    process, out = run_navseq(ros_master, tmp_path)
    assert process.popen.returncode == 0, process.output()[-4000:]
    report = json.loads((out / "report.json").read_text())
    assert [v["outcome"] for v in report["visits"]] == ["reached"] * len(WAYPOINTS)
    results = watched_results(watcher)
    assert [r["status"] for r in results] == [SUCCEEDED] * len(WAYPOINTS), results
    for result, (x, y, _yaw) in zip(results, WAYPOINTS, strict=True):
        assert result["goal"] == pytest.approx([x, y])
        assert result["distance"] < REACHED_WITHIN, result
    assert "race (~race_window)" not in nav.output()


def test_without_the_settle_navseq_runs_into_the_race(ros_master: RosMaster, tmp_path: Path):
    _robot, nav = start_sim(ros_master, nav_params=WIDE_RACE)
    watcher = start_result_watcher(ros_master, tmp_path)
    process, _out = run_navseq(ros_master, tmp_path, "--settle", "0")
    assert "Traceback" not in process.output()
    assert "race (~race_window)" in nav.output()
    far = [
        r
        for r in watched_results(watcher)
        if r["status"] == SUCCEEDED and r["distance"] is not None and r["distance"] > 0.5
    ]
    assert far, watched_results(watcher)


def test_without_the_settle_the_executor_reports_a_far_succeeded(
    ros_master: RosMaster, tmp_path: Path
):
    start_sim(ros_master, nav_params=WIDE_RACE)
    _process, out = run_navseq(ros_master, tmp_path, "--settle", "0")
    report = json.loads((out / "report.json").read_text())
    reasons = [attempt["reason"] for visit in report["visits"] for attempt in visit["attempts"]]
    assert any(reason.startswith("succeeded far from goal") for reason in reasons), reasons


@pytest.mark.parametrize(
    ("param", "complaint"),
    [("_race_window:=-0.1", "race_window"), ("_race_probability:=1.5", "race_probability")],
)
def test_a_bad_race_option_stops_the_node_naming_it(ros_master: RosMaster, param, complaint):
    ros_master.set_param("/use_sim_time", False)
    nav = ros_master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={MAP}", param], label="move_base"
    )
    assert nav.wait(timeout=60) == 2, nav.output()
    assert f"/move_base/{complaint}" in nav.output() and "Traceback" not in nav.output()
