"""Ros1Navigator against a real rosmaster and a scripted move_base action server.

rospy allows one node per process, so the navigator runs in a subprocess: this file is
also that subprocess's program (``python tests/test_ros1_navigator.py drive ...``). The
driver sends goals one after the other, prints every navigator event as a JSON line, and
resends the active goal after ``ServerBack`` like the executor does. Two more programs
test ``spin`` under ``use_sim_time``: ``clock`` publishes a simulation clock, and
``spin-sim`` spins on it.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import pytest

THIS = Path(__file__).resolve()


# ---------------------------------------------------------------------------------------
# Driver (runs in the subprocess)
# ---------------------------------------------------------------------------------------


def _emit(record: dict[str, Any]) -> None:
    print("EVENT " + json.dumps(record), flush=True)


def _drive(argv: list[str]) -> int:
    import time

    from navseq.errors import NavseqError
    from navseq.geometry import Pose2D
    from navseq.navigators.base import Goal, GoalDone, ServerBack
    from navseq.ros1.navigator import Ros1Navigator

    parser = argparse.ArgumentParser()
    parser.add_argument("--goals", required=True, help="x,y,yaw_deg;x,y,yaw_deg;...")
    parser.add_argument("--namespace", default="")
    parser.add_argument("--frame", default=None)
    parser.add_argument("--stamp", default="now")
    parser.add_argument("--cancel-after", type=float, default=None)
    parser.add_argument("--replace-after", type=float, default=None)
    parser.add_argument("--clear-costmaps", action="store_true")
    parser.add_argument("--server-wait", type=float, default=10.0)
    parser.add_argument("--goal-timeout", type=float, default=30.0)
    parser.add_argument("--spin", type=float, default=0.02, help="s of ROS time per spin")
    args = parser.parse_args(argv)
    goals = [tuple(float(v) for v in item.split(",")) for item in args.goals.split(";")]

    try:
        navigator = Ros1Navigator(
            frame=args.frame, namespace=args.namespace, stamp=args.stamp, use_tf=False
        )
        navigator.require_server(args.server_wait)
    except NavseqError as error:
        print(f"navseq: {error}", file=sys.stderr, flush=True)
        return 2
    if args.clear_costmaps:
        navigator.clear_costmaps()

    goal_id = 0
    for index, (x, y, yaw_deg) in enumerate(goals):
        goal_id += 1
        goal = Goal(goal_id, Pose2D(x, y, math.radians(yaw_deg)), frame="map")
        navigator.send_goal(goal)
        _emit({"type": "sent", "goal_id": goal_id, "index": index})
        started = time.monotonic()
        acted = False
        done = False
        spun_for: float | None = None  # ROS time the last spin took, until reported
        while not done:
            events = navigator.poll()
            if spun_for is not None:
                _emit({"type": "spun", "ros_seconds": spun_for, "then_polled": len(events)})
            for event in events:
                record = {"type": type(event).__name__, **vars(event)}
                record.pop("pose", None)
                if "outcome" in record:
                    record["outcome"] = event.outcome.value
                _emit(record)
                if isinstance(event, GoalDone) and event.goal_id == goal.goal_id:
                    done = True
                if isinstance(event, ServerBack):
                    goal_id += 1
                    goal = Goal(goal_id, goal.pose, frame="map")
                    navigator.send_goal(goal)
                    _emit({"type": "sent", "goal_id": goal_id, "index": index})
            elapsed = time.monotonic() - started
            if not acted and args.cancel_after is not None and elapsed > args.cancel_after:
                acted = True
                navigator.cancel_goal()
                _emit({"type": "cancel_sent", "goal_id": goal.goal_id})
            if not acted and args.replace_after is not None and elapsed > args.replace_after:
                acted = True
                goal_id += 1
                goal = Goal(goal_id, Pose2D(x + 1.0, y, 0.0), frame="map")
                navigator.send_goal(goal)
                _emit({"type": "sent", "goal_id": goal_id, "index": index})
            if elapsed > args.goal_timeout:
                _emit({"type": "driver_timeout", "goal_id": goal.goal_id})
                return 1
            if not done:
                spin_began = navigator.now()
                navigator.spin(args.spin)
                spun_for = navigator.now() - spin_began
    pose = navigator.robot_pose()
    _emit({"type": "final_pose", "x": pose.x if pose else None, "y": pose.y if pose else None})
    navigator.close()
    return 0


def _publish_clock(argv: list[str]) -> int:
    """Publish /clock from ``--start`` s on, running ``--speed`` times the wall clock."""
    import time

    import rospy
    from rosgraph_msgs.msg import Clock

    parser = argparse.ArgumentParser()
    parser.add_argument("--start", type=float, default=100.0)
    parser.add_argument("--speed", type=float, required=True)
    args = parser.parse_args(argv)
    rospy.init_node("test_clock", disable_signals=True)
    publisher = rospy.Publisher("/clock", Clock, queue_size=1)
    began = time.monotonic()
    while not rospy.core.is_shutdown_requested():
        clock = Clock()
        clock.clock = rospy.Time.from_sec(args.start + args.speed * (time.monotonic() - began))
        publisher.publish(clock)
        time.sleep(0.01)
    return 0


def _spin_on_sim_time(argv: list[str]) -> int:
    """Wait for the simulation clock, spin once with no goal, report both clocks."""
    import time

    from navseq.ros1.navigator import Ros1Navigator

    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, required=True)
    args = parser.parse_args(argv)
    navigator = Ros1Navigator(use_tf=False, plan_topic=None)
    deadline = time.monotonic() + 20.0
    while navigator.now() == 0.0 and time.monotonic() < deadline:
        time.sleep(0.01)
    ros_began, wall_began = navigator.now(), time.monotonic()
    navigator.spin(args.seconds)
    _emit(
        {
            "type": "spun",
            "ros_began": ros_began,
            "ros_seconds": navigator.now() - ros_began,
            "wall_seconds": time.monotonic() - wall_began,
        }
    )
    return 0


PROGRAMS = {"drive": _drive, "clock": _publish_clock, "spin-sim": _spin_on_sim_time}

if __name__ == "__main__":
    program = PROGRAMS.get(sys.argv[1] if len(sys.argv) > 1 else "")
    sys.exit(program(sys.argv[2:]) if program else 64)


# ---------------------------------------------------------------------------------------
# Tests
# ---------------------------------------------------------------------------------------

from cli_support import NAVSEQ, printed_events, write_mission  # noqa: E402
from ros_clients import server_log, start_scripted_server  # noqa: E402
from ros_support import RosMaster, RosProcess  # noqa: E402

pytestmark = pytest.mark.ros


def events_of(process: RosProcess) -> list[dict[str, Any]]:
    return [
        json.loads(line[len("EVENT ") :])
        for line in process.output().splitlines()
        if line.startswith("EVENT ")
    ]


def start_server(master: RosMaster, log: Path, script: str = "", *extra: str) -> RosProcess:
    return start_scripted_server(master, "--script", script, "--log", str(log), *extra)


def drive(master: RosMaster, *args: str, timeout: float = 60.0) -> tuple[int, RosProcess]:
    driver = master.start_python(THIS, "drive", *args, label="driver")
    code = driver.wait(timeout=timeout)
    return code, driver


def done_statuses(events: list[dict[str, Any]]) -> dict[int, str]:
    return {e["goal_id"]: e["status"] for e in events if e["type"] == "GoalDone"}


def test_every_terminal_status_reaches_the_caller(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "succeed:0.4 abort reject preempt recall")
    code, driver = drive(ros_master, "--goals", "1,2,90;3,4,0;5,6,0;7,8,0;9,10,0")
    assert code == 0, driver.output()
    events = events_of(driver)
    assert done_statuses(events) == {
        1: "SUCCEEDED",
        2: "ABORTED",
        3: "REJECTED",
        4: "PREEMPTED",
        5: "RECALLED",
    }
    accepted = {e["goal_id"] for e in events if e["type"] == "GoalAccepted"}
    assert {1, 2, 4} <= accepted and 3 not in accepted
    assert any(e["type"] == "GoalFeedback" and e["goal_id"] == 1 for e in events)
    plans = [e for e in events if e["type"] == "GoalPlan" and e["goal_id"] == 1]
    assert plans and plans[0]["path"][-1] == [1.0, 2.0]
    final = next(e for e in events if e["type"] == "final_pose")
    assert final["x"] == pytest.approx(1.0) and final["y"] == pytest.approx(2.0)

    received = [r for r in server_log(log) if r["event"] == "goal"]
    assert [(r["x"], r["y"]) for r in received] == [(1, 2), (3, 4), (5, 6), (7, 8), (9, 10)]
    assert received[0]["yaw"] == pytest.approx(math.pi / 2)
    assert all(r["frame"] == "map" for r in received)
    # Stamped with ROS time (wall time here, no use_sim_time), not zero.
    assert all(r["stamp"] > 1e9 for r in received)


def test_cancel_reaches_the_server_and_ends_the_goal_preempted(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "hang")
    code, driver = drive(
        ros_master, "--goals", "1,0,0", "--cancel-after", "0.5", "--stamp", "latest"
    )
    assert code == 0, driver.output()
    assert done_statuses(events_of(driver)) == {1: "PREEMPTED"}
    records = server_log(log)
    assert [r["event"] for r in records if r["event"] in ("cancel", "done")] == [
        "cancel",
        "done",
    ]
    assert next(r for r in records if r["event"] == "goal")["stamp"] == 0.0


def test_a_new_goal_replaces_the_active_one_without_a_cancel(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "hang succeed:0.3")
    code, driver = drive(ros_master, "--goals", "1,0,0", "--replace-after", "0.5")
    assert code == 0, driver.output()
    # Only the replacing goal is reported; the replaced one is not the caller's any more.
    assert done_statuses(events_of(driver)) == {2: "SUCCEEDED"}
    records = server_log(log)
    assert not [r for r in records if r["event"] == "cancel"]
    assert [r["status"] for r in records if r["event"] == "done"] == ["PREEMPTED", "SUCCEEDED"]


def test_server_lost_mid_goal_and_back_after_restart(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "die:0.5")
    driver = ros_master.start_python(THIS, "drive", "--goals", "1,1,0;2,2,0", label="driver")
    driver.wait_for_output('"ServerLost"', timeout=20)
    start_server(ros_master, log, "succeed:0.3")
    assert driver.wait(timeout=30) == 0, driver.output()
    kinds = [e["type"] for e in events_of(driver)]
    assert kinds.index("ServerLost") < kinds.index("ServerBack")
    statuses = done_statuses(events_of(driver))
    assert list(statuses.values()) == ["SUCCEEDED", "SUCCEEDED"]
    assert 1 not in statuses  # the goal that died with the server is not reported as done
    goals = [(r["x"], r["y"]) for r in server_log(log) if r["event"] == "goal"]
    assert goals == [(1, 1), (1, 1), (2, 2)]


def test_missing_server_is_a_clear_error_naming_action_and_master(ros_master: RosMaster):
    code, driver = drive(ros_master, "--goals", "1,0,0", "--server-wait", "0.5")
    assert code == 2
    output = driver.output()
    assert "/move_base" in output and ros_master.uri in output
    assert "Traceback" not in output


def test_namespaced_action_and_clear_costmaps(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "", "__ns:=robot1")
    code, driver = drive(
        ros_master, "--goals", "1,0,0", "--namespace", "/robot1", "--clear-costmaps"
    )
    assert code == 0, driver.output()
    assert done_statuses(events_of(driver)) == {1: "SUCCEEDED"}
    assert [r["event"] for r in server_log(log)].count("clear_costmaps") == 1


def test_spin_returns_as_soon_as_the_server_reports(ros_master: RosMaster, tmp_path: Path):
    # Spins of 30 s of ROS time, each cut short by the goal's acceptance, feedback and
    # result: the executor answers a result with the next goal at once, not after its
    # tick. A spin that slept its full time would show here as a 30 s spin.
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "succeed:0.5 succeed:0.5")
    code, driver = drive(
        ros_master,
        "--goals",
        "1,0,0;2,0,0",
        "--spin",
        "30",
        "--goal-timeout",
        "60",
        timeout=150,
    )
    assert code == 0, driver.output()
    events = events_of(driver)
    assert done_statuses(events) == {1: "SUCCEEDED", 2: "SUCCEEDED"}
    spins = [e for e in events if e["type"] == "spun"]
    assert spins, driver.output()
    assert all(spin["ros_seconds"] < 30.0 for spin in spins), spins
    # Each spin ended because there was news, never with nothing to report.
    assert all(spin["then_polled"] >= 1 for spin in spins), spins


def test_spin_waits_on_the_simulation_clock(ros_master: RosMaster):
    # A clock at half the wall clock's speed: one second of ROS time takes two of wall
    # time, and spin must wait for the ROS second, not the wall second.
    ros_master.set_param("/use_sim_time", True)
    ros_master.start_python(THIS, "clock", "--speed", "0.5", label="clock")
    ros_master.wait_for_publisher("/clock", timeout=20)
    spinner = ros_master.start_python(THIS, "spin-sim", "--seconds", "1.0", label="spinner")
    assert spinner.wait(timeout=60) == 0, spinner.output()
    (spun,) = [e for e in events_of(spinner) if e["type"] == "spun"]
    assert spun["ros_began"] >= 100.0  # simulation time, not wall time
    assert spun["ros_seconds"] >= 1.0


# -- navseq run against the scripted server: the policy around rejections and clearing --


def run_navseq(master: RosMaster, tmp_path: Path, waypoints: str, defaults: str) -> RosProcess:
    """``navseq run --navigator ros1 --json`` to its end (a hang fails on the timeout)."""
    mission = write_mission(tmp_path / "m.yaml", waypoints, f"defaults: {{{defaults}}}\n")
    out = tmp_path / "out"
    process = master.start(
        [NAVSEQ, "run", mission, "--navigator", "ros1", "--no-preflight", "--json", "--out", out],
        cwd=tmp_path,
        label="navseq",
    )
    process.wait(timeout=90)
    return process


def visits_of(tmp_path: Path) -> list[dict[str, Any]]:
    return list(json.loads((tmp_path / "out" / "report.json").read_text())["visits"])


def test_rejected_goals_spend_the_retries_then_skip_then_stop(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "reject:0.1 reject:0.1 reject:0.1")
    navseq = run_navseq(
        ros_master,
        tmp_path,
        "  - {name: first, x: 1.0, y: 0.0, yaw: 0, retries: 1, on_failure: skip}\n"
        "  - {name: second, x: 2.0, y: 0.0, yaw: 0}\n",
        "retries: 0, on_failure: stop, goal_timeout: 30",
    )
    assert navseq.popen.returncode == 1, navseq.output()
    assert "Traceback" not in navseq.output()
    first, second = visits_of(tmp_path)
    assert first["outcome"] == "skipped" and second["outcome"] == "failed"
    attempts = first["attempts"] + second["attempts"]
    assert [(a["status"], a["text"]) for a in attempts] == [
        ("REJECTED", "the server rejected the goal: scripted reject")
    ] * 3
    failed = printed_events(navseq.output(), "AttemptFailed")
    assert [(e["index"], e["will_retry"]) for e in failed] == [(0, True), (0, False), (1, False)]
    assert [r["event"] for r in server_log(log)].count("accepted") == 0


@pytest.mark.parametrize("clear", [True, False])
def test_a_retry_clears_the_costmaps_before_its_goal_only_when_asked(
    clear: bool, ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "abort:0.2 succeed:0.2")
    navseq = run_navseq(
        ros_master,
        tmp_path,
        "  - {name: a, x: 1.0, y: 0.0, yaw: 0}\n",
        f"retries: 1, goal_timeout: 30, clear_costmaps_on_retry: {str(clear).lower()}",
    )
    assert navseq.popen.returncode == 0, navseq.output()
    (visit,) = visits_of(tmp_path)
    assert [a["status"] for a in visit["attempts"]] == ["ABORTED", "SUCCEEDED"]
    order = [r["event"] for r in server_log(log) if r["event"] in ("goal", "clear_costmaps")]
    assert order == (["goal", "clear_costmaps", "goal"] if clear else ["goal", "goal"])


def test_a_retrys_wait_and_clear_recoveries_run_on_move_base(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, "abort:0.2 succeed:0.2")
    navseq = run_navseq(
        ros_master,
        tmp_path,
        "  - {name: a, x: 1.0, y: 0.0, yaw: 0}\n",
        "retries: 1, goal_timeout: 30, recovery: [wait: 0.5, clear_costmaps]",
    )
    assert navseq.popen.returncode == 0, navseq.output()
    (visit,) = visits_of(tmp_path)
    assert [a["status"] for a in visit["attempts"]] == ["ABORTED", "SUCCEEDED"]
    runs = [(r["kind"], r["outcome"]) for r in visit["recoveries_run"]]
    assert runs == [("wait", "succeeded"), ("clear_costmaps", "succeeded")]
    assert visit["recoveries_run"][0]["duration_s"] >= 0.5  # on ROS time
    order = [r["event"] for r in server_log(log) if r["event"] in ("goal", "clear_costmaps")]
    assert order == ["goal", "clear_costmaps", "goal"]


@pytest.mark.parametrize(
    ("behaviour", "warning"),
    [
        ("silent", "/move_base/clear_costmaps did not answer within 1 s"),
        ("absent", "/move_base/clear_costmaps unavailable"),
    ],
)
def test_a_silent_or_missing_clear_service_delays_the_retry_but_never_hangs_it(
    behaviour: str, warning: str, ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_scripted_server(
        ros_master, "--then", "abort:0.2", "--log", str(log), "--clear-costmaps", behaviour
    )
    # Before the fix a silent service hung the retry for good: navseq never ended.
    navseq = run_navseq(
        ros_master,
        tmp_path,
        "  - {name: a, x: 1.0, y: 0.0, yaw: 0}\n",
        "retries: 2, on_failure: stop, goal_timeout: 30, clear_costmaps_on_retry: true",
    )
    assert navseq.popen.returncode == 1, navseq.output()
    (visit,) = visits_of(tmp_path)
    assert [a["status"] for a in visit["attempts"]] == ["ABORTED"] * 3
    events = [r["event"] for r in server_log(log) if r["event"] in ("goal", "clear_costmaps")]
    calls = ["clear_costmaps"] if behaviour == "silent" else []
    assert events == ["goal", *calls, "goal", *calls, "goal"]
    assert navseq.output().count(warning) == 1, navseq.output()  # said once, not per retry
