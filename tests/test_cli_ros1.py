"""``navseq run --navigator ros1`` against a real rosmaster and the simulator's ROS nodes.

The robot node and the move_base stand-in (``nodes/sim_robot_node``,
``nodes/sim_nav_node``) run at several times real time; navseq talks to them only
through actionlib, exactly as it would to a real robot's move_base.
"""

from __future__ import annotations

import json
import signal

import pytest

from cli_support import (
    NAVSEQ,
    assert_clean_error,
    driven_towards,
    navseq,
    wait_for,
    write_mission,
)
from ros_clients import MAP, start_sim

pytestmark = pytest.mark.ros


def mission(tmp_path):
    return write_mission(
        tmp_path / "ros.yaml",
        (
            "  - {name: west, x: -1.6, y: -0.5, yaw: 90}\n"
            "  - {name: south, x: -0.55, y: -1.75, yaw: 0}\n"
        ),
        "defaults: {goal_timeout: 120}\n",
    )


def test_ros1_run_completes_and_reports(ros_master, tmp_path):
    start_sim(ros_master)
    out = tmp_path / "out"
    process = ros_master.start(
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
        ],
        cwd=tmp_path,
        label="navseq",
    )
    assert process.wait(timeout=120) == 0, process.output()
    report = json.loads((out / "report.json").read_text())
    assert report["success"] is True
    navigator = report["navigator"]
    assert {k: navigator[k] for k in ("kind", "action", "frame", "ns")} == {
        "kind": "ros1",
        "action": "move_base",
        "frame": "map",
        "ns": "",
    }
    # The sim's move_base declares the robot it simulates (the burger by default) under
    # move_base's parameter names, and navseq reads it from there.
    assert navigator["robot"] == "navstack:/move_base"
    assert navigator["robot_source"].startswith(
        "robot from /move_base parameters: footprint 4 points, circumscribed 0.15 m"
    ), navigator["robot_source"]
    assert [v["outcome"] for v in report["visits"]] == ["reached", "reached"]
    assert report["visits"][1]["distance_m"] > 0.5
    assert (out / "mission.png").exists()


def test_without_a_map_file_pre_flight_runs_on_the_map_the_stack_latches(ros_master, tmp_path):
    _robot, nav = start_sim(ros_master)
    # (1.0, 0.0): the edge of the east pillar (navseq validate --map: inside an obstacle).
    pillar = write_mission(
        tmp_path / "pillar.yaml",
        "  - {name: west, x: -1.6, y: -0.5, yaw: 90}\n  - {name: pillar, x: 1.0, y: 0.0, yaw: 0}\n",
    )
    refused = ros_master.start(
        [NAVSEQ, "run", pillar, "--navigator", "ros1", "--out", tmp_path / "refused"],
        cwd=tmp_path,
        label="navseq-refused",
    )
    assert refused.wait(timeout=120) == 2, refused.output()
    text = refused.output()
    assert "pre-flight on the map on /map: 384 x 384 cells at 0.050 m" in text, text
    assert "waypoint 2 'pillar'" in text and "inside an obstacle" in text, text
    assert "Traceback" not in text
    assert not (tmp_path / "refused").exists()
    assert "new goal" not in nav.output()  # nothing was sent: the robot never moved

    out = tmp_path / "out"
    done = ros_master.start(
        [NAVSEQ, "run", mission(tmp_path), "--navigator", "ros1", "--out", out],
        cwd=tmp_path,
        label="navseq",
    )
    assert done.wait(timeout=120) == 0, done.output()
    assert "navseq run: pre-flight on the map on /map: 384 x 384 cells at 0.050 m" in (
        done.output()
    )
    report = json.loads((out / "report.json").read_text())
    assert report["navigator"]["map_source"] == "the map on /map: 384 x 384 cells at 0.050 m"
    assert [v["outcome"] for v in report["visits"]] == ["reached", "reached"]
    assert (out / "mission.png").exists()


def test_ros1_sigint_cancels_the_goal(ros_master, tmp_path):
    _robot, nav = start_sim(ros_master)
    out = tmp_path / "out"
    process = ros_master.start(
        [NAVSEQ, "run", mission(tmp_path), "--navigator", "ros1", "--json", "--out", out],
        cwd=tmp_path,
        label="navseq",
    )
    wait_for(lambda: driven_towards(process.output(), 0), 60, "the robot moving")
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=60) == 130, process.output()
    report = json.loads((out / "report.json").read_text())
    assert report["interrupted"] == "SIGINT" and report["exit_code"] == 130
    assert "Traceback" not in process.output()
    nav.wait_for_output("goal canceled", timeout=10)  # the robot was not left driving


def test_a_negative_settle_is_a_clean_error(tmp_path):
    result = navseq(
        "run",
        mission(tmp_path),
        "--navigator",
        "ros1",
        "--settle",
        "-1",
        "--out",
        tmp_path / "out",
        cwd=tmp_path,
        timeout=60,
    )
    assert_clean_error(result)
    assert "settle" in result.stderr and ">= 0" in result.stderr
    assert not (tmp_path / "out").exists()
