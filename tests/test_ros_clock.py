"""Which clock, and a clock that runs: navseq, the sim stack and the tutorial's client.

- rospy reads ``/use_sim_time`` once, at ``init_node``: a navseq started before a
  simulator that sets it must still take its time from the simulator's ``/clock``;
- a stack on sim time whose ``/clock`` never comes is a clear error, not a mission timed
  from time 0;
- ``sim.launch`` at speed 1 runs on wall time, so the tutorial's
  ``wait_for_server(rospy.Duration(5))`` (a deadline computed from time 0 before the first
  ``/clock`` under sim time, actionlib #137) finds the server.
"""

from __future__ import annotations

import os
import subprocess
import textwrap
import time
from pathlib import Path

import pytest

from cli_support import NAVSEQ, journal_events, write_mission
from ros_clients import start_scripted_server, start_sim
from ros_support import REPO_ROOT, RosMaster

pytestmark = pytest.mark.ros

SIM_EPOCH_BOUND = 1e5  # s: the sim clock starts at 0; wall time is ~1.7e9


def mission(tmp_path: Path) -> Path:
    return write_mission(
        tmp_path / "clock.yaml",
        "  - {x: -1.6, y: -0.5, yaw: 0}\n  - {x: -1.6, y: -0.9, yaw: -90}\n",
        "defaults: {goal_timeout: 120}\n",
    )


def test_navseq_started_before_a_5x_sim_runs_on_the_sims_clock(
    ros_master: RosMaster, tmp_path: Path
):
    out = tmp_path / "out"
    # No /use_sim_time yet: navseq's rospy comes up on wall time.
    navseq = ros_master.start(
        [NAVSEQ, "run", mission(tmp_path), "--navigator", "ros1", "--out", out],
        cwd=tmp_path,
        label="navseq",
    )
    # Its action client subscribes only once init_node (which reads /use_sim_time) is done.
    ros_master.wait_for_subscriber("/move_base/status", timeout=30)
    start_sim(ros_master, speed=5.0)  # sets /use_sim_time true, drives /clock at 5x
    assert navseq.wait(timeout=120) == 0, navseq.output()[-4000:]
    assert "taking time from /clock" in navseq.output()
    journal = out / "journal.jsonl"
    started = journal_events(journal, "MissionStarted")[0]["t"]
    finished = journal_events(journal, "MissionFinished")[0]["t"]
    assert 0 < started < SIM_EPOCH_BOUND, "mission times must be the sim's, not wall time"
    assert started < finished < SIM_EPOCH_BOUND


def test_sim_time_without_a_clock_is_a_clear_error_naming_clock(
    ros_master: RosMaster, tmp_path: Path
):
    ros_master.set_param("/use_sim_time", True)
    navseq = ros_master.start(
        [NAVSEQ, "run", mission(tmp_path), "--navigator", "ros1", "--out", tmp_path / "out"],
        cwd=tmp_path,
        label="navseq",
    )
    ros_master.wait_for_subscriber("/move_base/status", timeout=30)  # init_node done
    # The server comes up on wall time (no /clock ever): navseq's rospy stays at time 0.
    ros_master.set_param("/use_sim_time", False)
    start_scripted_server(ros_master)
    assert navseq.wait(timeout=60) == 2, navseq.output()[-4000:]
    output = navseq.output()
    assert "/clock" in output and "use_sim_time" in output
    assert "Traceback" not in output
    assert not (tmp_path / "out").exists()


TUTORIAL_WAIT = textwrap.dedent(
    """
    import math
    import actionlib, rospy
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

    rospy.init_node("move_base_seq")
    client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
    if not client.wait_for_server(rospy.Duration(5.0)):
        print("Action server not available!", flush=True)
        raise SystemExit(1)
    print("server available", flush=True)
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = "map"
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose.position.x, goal.target_pose.pose.position.y = -1.7, -0.5
    goal.target_pose.pose.orientation.w = 1.0
    client.send_goal(goal)
    client.wait_for_result(rospy.Duration(60))
    print("state %d" % client.get_state(), flush=True)
    """
)


def test_tutorial_wait_for_server_works_against_sim_launch_at_speed_1(
    ros_master: RosMaster, tmp_path: Path
):
    launched = time.monotonic()
    ros_master.start(["roslaunch", "navseq", "sim.launch"], label="roslaunch")
    ros_master.wait_for_action_server("/move_base", timeout=60)
    assert ros_master.get_param("/use_sim_time") is False
    # Under sim time the tutorial fails once the sim clock has passed 5 s before it starts.
    time.sleep(max(0.0, 6.0 - (time.monotonic() - launched)))
    script = tmp_path / "tutorial_wait.py"
    script.write_text(TUTORIAL_WAIT)
    client = ros_master.start_python(script, label="tutorial")
    assert client.wait(timeout=90) == 0, client.output()
    assert "server available" in client.output()
    assert "state 3" in client.output()  # SUCCEEDED


def test_sim_launch_at_other_speeds_or_when_asked_runs_on_sim_time():
    def use_sim_time(*args: str) -> str:
        result = subprocess.run(
            ["roslaunch", "--dump-params", "navseq", "sim.launch", *args],
            capture_output=True,
            text=True,
            timeout=60,
            env={**os.environ, "ROS_PACKAGE_PATH": str(REPO_ROOT)},
        )
        assert result.returncode == 0, result.stderr
        return next(line for line in result.stdout.splitlines() if "use_sim_time" in line)

    assert use_sim_time().endswith("false")
    assert use_sim_time("speed:=5").endswith("true")
    assert use_sim_time("use_sim_time:=true").endswith("true")
    assert use_sim_time("speed:=5", "use_sim_time:=false").endswith("false")
