"""Fault tests: ``navseq run --navigator ros1`` against the simulator's real ROS nodes.

Each test starts its own rosmaster, the sim robot node and the move_base stand-in
(``nodes/sim_robot_node``, ``nodes/sim_nav_node``) on the TurtleBot3 world at several
times real time, runs navseq as a subprocess, and then breaks something the way it
breaks on a real robot: the navigation server dies and comes back, the operator presses
Ctrl-C, a waypoint lies inside a pillar, another client takes move_base over. What is
checked is what a user sees: the exit status, the report's per-waypoint outcomes, the
goal statuses on ``move_base/result`` and whether the robot keeps moving.
"""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any

import pytest

from cli_support import NAVSEQ, driven_towards, journal_events, write_mission
from ros_clients import MAP, PREEMPTED, SUCCEEDED, goal, reports, start_client, start_sim
from ros_support import REPO_ROOT, RosMaster, RosProcess, wait_for

pytestmark = [pytest.mark.ros, pytest.mark.slow]

PILLAR = (0.0, 0.0)  # the centre pillar of the arena: the sim aborts any goal there

# Bounds on wall-clock waits: generous, because ~7 engineers share two CPU cores.
MISSION_TIMEOUT = 90.0
EVENT_TIMEOUT = 60.0


# -- helpers ---------------------------------------------------------------------------------


def mission_file(tmp_path: Path, waypoints: list[tuple[str, float, float]], **policy: Any) -> Path:
    """A navseq mission with these (name, x, y) waypoints and these default policy keys."""
    defaults = {"goal_timeout": 120, **policy}
    header = "defaults: {" + ", ".join(f"{k}: {v}" for k, v in defaults.items()) + "}\n"
    lines = "".join(f"  - {{name: {name}, x: {x}, y: {y}, yaw: 0}}\n" for name, x, y in waypoints)
    return write_mission(tmp_path / "mission.yaml", lines, header)


def start_navseq(master: RosMaster, tmp_path: Path, mission: Path) -> tuple[RosProcess, Path]:
    """``navseq run --navigator ros1 --json`` without map pre-flight; it and its out folder.

    ``--json`` prints every event, progress included: the journal thins progress to the
    corners of the driven path, so a straight leg shows there only when it ends.
    """
    out = tmp_path / "out"
    process = master.start(
        [NAVSEQ, "run", mission, "--navigator", "ros1", "--no-preflight", "--json", "--out", out],
        cwd=tmp_path,
        label="navseq",
    )
    return process, out


def report_of(out: Path) -> dict[str, Any]:
    return json.loads((out / "report.json").read_text())


def outcomes(out: Path) -> list[str]:
    return [visit["outcome"] for visit in report_of(out)["visits"]]


def wait_driving_to(process: RosProcess, index: int) -> None:
    """Block until navseq reports progress towards waypoint ``index`` (the robot moving)."""

    def driving() -> bool:
        if not process.running():
            raise AssertionError(f"navseq exited early:\n{process.output()[-4000:]}")
        return driven_towards(process.output(), index)

    wait_for(driving, EVENT_TIMEOUT, f"the robot driving to waypoint {index}")


def start_result_monitor(master: RosMaster, tmp_path: Path, count: int) -> RosProcess:
    """A bystander that prints the first ``count`` statuses the server publishes on result."""
    monitor = start_client(
        master,
        tmp_path / "monitor",
        [{"op": "watch_results", "count": count, "timeout": 120}],
        label="monitor",
    )
    monitor.wait_for_output('"op": "watching"', timeout=EVENT_TIMEOUT)
    return monitor


def intruder_listening(master: RosMaster) -> bool:
    """Whether a ``SIM_CLIENT`` (anonymous node ``/sim_client_*``) subscribes to /odom."""
    _, subscribers, _ = master.system_state()
    return any(node.startswith("/sim_client") for node in subscribers.get("/odom", []))


def start_nav_node(master: RosMaster) -> RosProcess:
    """Another navigation node, as ``start_sim`` starts it (the robot node keeps running)."""
    return master.start(
        [REPO_ROOT / "nodes" / "sim_nav_node", f"_map:={MAP}"], label="move_base_again"
    )


# -- the navigation server dies mid-goal ------------------------------------------------------


def test_navigation_node_killed_mid_goal_and_restarted_mission_completes(
    ros_master: RosMaster, tmp_path: Path
):
    _, nav = start_sim(ros_master)
    # The leg to waypoint 1 crosses the arena: long enough to be cut in the middle.
    waypoints = [("west", -1.6, -0.5), ("east", 1.75, -0.55), ("north-east", 1.6, 0.5)]
    navseq, out = start_navseq(ros_master, tmp_path, mission_file(tmp_path, waypoints))
    journal = out / "journal.jsonl"
    wait_driving_to(navseq, 1)
    nav.stop(signal.SIGKILL)  # a crash: no goodbye to the master or to navseq
    # navseq notices (no status from move_base) before the server comes back.
    wait_for(lambda: journal_events(journal, "ServerStatusChanged"), EVENT_TIMEOUT, "server lost")
    restarted = start_nav_node(ros_master)
    assert navseq.wait(timeout=MISSION_TIMEOUT) == 0, navseq.output() + restarted.output()
    assert outcomes(out) == ["reached", "reached", "reached"], navseq.output()
    changes = [event["available"] for event in journal_events(journal, "ServerStatusChanged")]
    assert changes == [False, True], changes
    # The goal that was underway went to the new server, then the last one did.
    assert restarted.output().count("goal reached") == 2, restarted.output()
    assert "Traceback" not in navseq.output()


# -- Ctrl-C -----------------------------------------------------------------------------------


def test_sigint_to_navseq_cancels_the_goal_and_the_robot_stops(
    ros_master: RosMaster, tmp_path: Path
):
    _, nav = start_sim(ros_master)
    monitor = start_result_monitor(ros_master, tmp_path, count=1)
    waypoints = [("east", 1.6, 0.5), ("home", -2.0, -0.5)]
    navseq, out = start_navseq(ros_master, tmp_path, mission_file(tmp_path, waypoints))
    wait_driving_to(navseq, 0)
    navseq.send_signal(signal.SIGINT)
    assert navseq.wait(timeout=EVENT_TIMEOUT) == 130, navseq.output()
    # The server heard the cancel: the goal ended PREEMPTED, not SUCCEEDED or hanging.
    assert monitor.wait(timeout=EVENT_TIMEOUT) == 0, monitor.output()
    assert reports(monitor)[-1]["results"] == [PREEMPTED], monitor.output()
    assert "goal canceled" in nav.output(), nav.output()
    # ... and the robot stands still: odometry says zero, the pose does not change.
    observer = start_client(ros_master, tmp_path / "observer", [{"op": "settle"}])
    assert observer.wait(timeout=EVENT_TIMEOUT) == 0, observer.output()
    (settled,) = reports(observer)
    assert settled["v"] == 0.0 and settled["w"] == 0.0, settled
    assert settled["moved"] < 0.005 and settled["turned"] < 0.01, settled
    report = report_of(out)
    assert report["interrupted"] == "SIGINT", report
    # The waypoint the robot was driving to is not claimed as reached.
    assert report["visits"][0]["outcome"] != "reached", report["visits"]


# -- a waypoint inside a pillar ---------------------------------------------------------------


@pytest.mark.parametrize(
    ("on_failure", "expected"),
    [("skip", ["reached", "skipped", "reached"]), ("stop", ["reached", "failed", "not_run"])],
)
def test_waypoint_in_a_wall_is_aborted_and_the_policy_decides(
    ros_master: RosMaster, tmp_path: Path, on_failure: str, expected: list[str]
):
    _, nav = start_sim(ros_master)
    waypoints = [("west", -1.6, -0.5), ("pillar", *PILLAR), ("south", -0.55, -1.75)]
    mission = mission_file(tmp_path, waypoints, on_failure=on_failure)
    navseq, out = start_navseq(ros_master, tmp_path, mission)
    # Not every waypoint was reached: exit status 1 either way.
    assert navseq.wait(timeout=MISSION_TIMEOUT) == 1, navseq.output()
    assert outcomes(out) == expected, navseq.output()
    pillar = report_of(out)["visits"][1]
    assert "ABORTED" in pillar["reason"], pillar
    assert "goal aborted" in nav.output(), nav.output()
    # With stop, the last waypoint was never sent: the server saw two goals only.
    goals_sent = 3 if on_failure == "skip" else 2
    assert nav.output().count("new goal") == goals_sent, nav.output()
    assert "Traceback" not in navseq.output()


# -- another client preempts navseq's goal ----------------------------------------------------


@pytest.mark.parametrize(
    ("policy", "exit_code", "expected"),
    [
        ({"retries": 1}, 0, ["reached", "reached"]),
        ({"on_failure": "retry"}, 0, ["reached", "reached"]),
        ({"on_failure": "stop"}, 1, ["failed", "not_run"]),
    ],
    ids=["retries-1", "on_failure-retry", "on_failure-stop"],
)
def test_goal_preempted_by_another_client_is_handled_per_policy(
    ros_master: RosMaster,
    tmp_path: Path,
    policy: dict[str, Any],
    exit_code: int,
    expected: list[str],
):
    start_sim(ros_master)
    # The intruder is ready before navseq starts, and sends its goal as soon as the robot
    # moves: navseq's first goal is surely still underway then.
    intruder = start_client(
        ros_master,
        tmp_path / "intruder",
        [{"op": "wait_moving"}, goal(-1.5, -1.0)],
        label="intruder",
    )
    wait_for(lambda: intruder_listening(ros_master), EVENT_TIMEOUT, "the intruder on /odom")
    waypoints = [("east", 1.6, 0.5), ("home", -2.0, -0.5)]
    navseq, out = start_navseq(ros_master, tmp_path, mission_file(tmp_path, waypoints, **policy))
    journal = out / "journal.jsonl"
    assert navseq.wait(timeout=MISSION_TIMEOUT) == exit_code, navseq.output()
    assert outcomes(out) == expected, navseq.output()
    failed = journal_events(journal, "AttemptFailed")
    assert [(f["index"], f["reason"]) for f in failed] == [(0, "PREEMPTED")], failed
    assert intruder.wait(timeout=EVENT_TIMEOUT) == 0, intruder.output()
    _, intruder_result = reports(intruder)
    if exit_code == 0:
        # navseq's resent goal took move_base back from the intruder.
        assert intruder_result["state"] == PREEMPTED, intruder_result
    else:
        # navseq stopped cleanly and left move_base to the intruder.
        assert intruder_result["state"] == SUCCEEDED, intruder_result
    assert "Traceback" not in navseq.output()
