"""The navseq node against a real rosmaster and the scripted move_base server.

The node gets its mission exactly as the tutorial's launch file gives it (private
``p_seq`` / ``yea_seq`` parameters) and runs as its own process, like under rosrun.
"""

from __future__ import annotations

import math
import signal
import time
from pathlib import Path
from typing import Any

import pytest

from ros_clients import server_log, start_scripted_server
from ros_support import RosMaster, RosProcess, wait_for

pytestmark = pytest.mark.ros

TESTS = Path(__file__).resolve().parent

# The tutorial's launch file contents.
P_SEQ = [-1, -4, 0, 1, -4, 0, 1, -1, 0]
YEA_SEQ = [90, 0, 180]


def events(path: Path, kind: str) -> list[dict[str, Any]]:
    return [r for r in server_log(path) if r["event"] == kind]


def start_server(master: RosMaster, log: Path, script: str = "", then: str = "succeed:0.3"):
    return start_scripted_server(master, "--script", script, "--then", then, "--log", str(log))


def start_node(master: RosMaster, **params: Any) -> RosProcess:
    for key, value in {"p_seq": P_SEQ, "yea_seq": YEA_SEQ, **params}.items():
        master.set_param(f"/navseq/{key}", value)
    return master.start_python("-m", "navseq.ros1.navseq_node", label="navseq_node")


def watch_status(master: RosMaster) -> RosProcess:
    """``rostopic echo`` of the node's status, once it has printed the latched message."""
    status = master.start(["rostopic", "echo", "/navseq/status"])
    status.wait_for_output("data:", timeout=20)
    return status


def test_node_with_only_the_tutorial_params_completes_the_sequence(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log)
    node = start_node(ros_master)
    assert node.wait(timeout=60) == 0, node.output()
    goals = events(log, "goal")
    assert [(g["x"], g["y"]) for g in goals] == [(-1, -4), (1, -4), (1, -1)]
    assert [g["yaw"] for g in goals] == pytest.approx([math.pi / 2, 0.0, math.pi])
    assert all(g["frame"] == "map" for g in goals)
    assert [d["status"] for d in events(log, "done")] == ["SUCCEEDED"] * 3
    assert "Traceback" not in node.output()


def log_lines(output: str, level: str) -> list[str]:
    """The node's own rospy lines of one level, without rospy's ``[LEVEL] [stamps]: ``."""
    return [
        line.split("]: ", 1)[1]
        for line in output.splitlines()
        if line.startswith(f"[{level}]") and "]: navseq: " in line
    ]


def test_node_logs_one_line_per_waypoint_event_as_navseq_run_does_in_a_pipe(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, script="succeed:0.3 abort:0.2", then="succeed:0.3")
    node = start_node(ros_master, retries=1)
    assert node.wait(timeout=60) == 0, node.output()
    info = log_lines(node.output(), "INFO")
    waypoint_lines = [line for line in info if line.startswith("navseq: waypoint")]
    assert waypoint_lines[0] == "navseq: waypoint 1/3: going to (-1.00, -4.00, 90°), attempt 1"
    # No robot in the params: the node looked for move_base's (the scripted server has none).
    assert any("no robot parameters in /move_base parameters" in line for line in info)
    assert waypoint_lines[1].startswith("navseq: waypoint 1/3: reached after ")
    assert "navseq: waypoint 2/3: going to (1.00, -4.00, 0°), attempt 2" in waypoint_lines
    assert waypoint_lines[-1].startswith("navseq: waypoint 3/3: reached after ")
    assert waypoint_lines[-1].endswith(", 1 attempt")
    # Trouble is a warning, in the same words as navseq run's.
    assert log_lines(node.output(), "WARN") == [
        "navseq: waypoint 2/3: attempt 1 failed (ABORTED: scripted abort), will retry"
    ]
    # The end is said once, by the node (not also as "mission finished: ...").
    assert info[-1] == "navseq: mission succeeded (completed)"
    assert not any("mission finished" in line for line in info)


def test_node_publishes_latched_status_and_markers(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, then="hang")
    node = start_node(ros_master)
    wait_for(lambda: events(log, "goal"), 20, "the first goal")
    status = ros_master.start(["rostopic", "echo", "-n", "1", "/navseq/status"])
    assert status.wait(timeout=20) == 0, status.output()
    assert '\\"state\\": \\"running\\"' in status.output()
    markers = ros_master.start(
        ["rostopic", "echo", "-n", "1", "/navseq/waypoints/markers[0]/color"]
    )
    assert markers.wait(timeout=20) == 0, markers.output()
    # Waypoint 1 is the active goal: blue.
    assert "b: 1.0" in markers.output()
    node.stop(signal.SIGINT)


@pytest.mark.parametrize(
    ("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"]
)
def test_signal_to_the_node_cancels_the_active_goal(
    ros_master: RosMaster, tmp_path: Path, sig: int, code: int
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, then="hang")
    node = start_node(ros_master)
    wait_for(lambda: events(log, "accepted"), 20, "the first goal to be accepted")
    status = watch_status(ros_master)
    node.send_signal(sig)
    assert node.wait(timeout=20) == code, node.output()
    cancels = events(log, "cancel")
    assert [c["id"] for c in cancels] == [events(log, "goal")[0]["id"]]
    assert [d["status"] for d in events(log, "done")] == ["PREEMPTED"]
    assert f"interrupted ({signal.Signals(sig).name})" in node.output()
    wait_for(lambda: '\\"state\\": \\"interrupted\\"' in status.output(), 10, "status")
    assert "Traceback" not in node.output()


def test_rosnode_kill_cancels_the_active_goal(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, then="hang")
    node = start_node(ros_master)
    wait_for(lambda: events(log, "accepted"), 20, "the first goal to be accepted")
    ros_master.kill_node("/navseq")
    assert node.wait(timeout=20) == 1, node.output()
    assert [d["status"] for d in events(log, "done")] == ["PREEMPTED"], node.output()
    # Said as an interruption with rospy's reason, not as a waypoint that failed.
    output = node.output()
    assert "interrupted (external shutdown request" in output, output
    assert "killed by the test" in output and "PREEMPTED" not in output, output
    assert "Traceback" not in output


def test_skip_service_skips_a_hanging_goal_and_the_mission_goes_on(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, script="hang", then="succeed:0.3")
    node = start_node(ros_master)
    wait_for(lambda: events(log, "accepted"), 20, "the first goal to be accepted")
    status = watch_status(ros_master)
    response = ros_master.call_service("/navseq/skip")
    assert response["success"], response
    assert "waypoint 1" in response["message"]
    # Mission goes on, but not every waypoint was reached: exit status 1.
    assert node.wait(timeout=60) == 1, node.output()
    goals = [(g["x"], g["y"]) for g in events(log, "goal")]
    assert goals == [(-1, -4), (1, -4), (1, -1)]
    assert [d["status"] for d in events(log, "done")] == ["PREEMPTED", "SUCCEEDED", "SUCCEEDED"]
    warnings = log_lines(node.output(), "WARN")
    assert any(
        line.startswith("navseq: waypoint 1/3: skipped (skipped by the operator (~skip)) after")
        for line in warnings
    ), node.output()
    wait_for(lambda: '\\"outcome\\": \\"skipped\\"' in status.output(), 10, "status")
    assert "Traceback" not in node.output()


def test_skip_service_refuses_when_no_waypoint_is_underway(ros_master: RosMaster):
    # No action server: the node waits for one, so no waypoint is underway yet.
    node = start_node(ros_master, server_wait=30)
    ros_master.wait_for_service("/navseq/skip")
    response = ros_master.call_service("/navseq/skip")
    assert not response["success"] and "no waypoint" in response["message"], response
    assert node.stop(signal.SIGINT) == 130
    assert "interrupted (SIGINT)" in node.output() and "Traceback" not in node.output()


def test_server_killed_mid_goal_and_restarted_mission_completes(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, script="succeed:0.3 die:0.8")
    node = start_node(ros_master)
    wait_for(lambda: events(log, "die"), 20, "the server to die on goal 2")
    time.sleep(1.0)  # the node notices after its status timeout (2 s)
    start_server(ros_master, log)
    assert node.wait(timeout=60) == 0, node.output()
    goals = [(g["x"], g["y"]) for g in events(log, "goal")]
    assert goals == [(-1, -4), (1, -4), (1, -4), (1, -1)]


def test_pause_stops_the_robot_and_resume_sends_the_goal_again(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, script="succeed:0.3 hang", then="succeed:0.3")
    node = start_node(ros_master)
    wait_for(lambda: len(events(log, "accepted")) == 2, 20, "goal 2 to be accepted")
    response = ros_master.call_service("/navseq/pause")
    assert response["success"], response
    assert [c["id"] for c in events(log, "cancel")] == [events(log, "goal")[1]["id"]]
    assert node.running()
    assert not ros_master.call_service("/navseq/pause")["success"]  # already paused
    assert ros_master.call_service("/navseq/resume")["success"]
    assert node.wait(timeout=60) == 0, node.output()
    goals = [(g["x"], g["y"]) for g in events(log, "goal")]
    assert goals == [(-1, -4), (1, -4), (1, -4), (1, -1)]


def test_cancel_service_ends_the_mission_and_stops_the_robot(ros_master: RosMaster, tmp_path: Path):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log, then="hang")
    node = start_node(ros_master)
    wait_for(lambda: events(log, "accepted"), 20, "the first goal to be accepted")
    status = watch_status(ros_master)
    assert ros_master.call_service("/navseq/cancel")["success"]
    assert node.wait(timeout=20) == 1, node.output()
    assert [d["status"] for d in events(log, "done")] == ["PREEMPTED"]
    assert len(events(log, "goal")) == 1
    # The status says the operator cancelled it: not a failure, not an interruption.
    wait_for(lambda: '\\"state\\": \\"cancelled\\"' in status.output(), 10, "status")
    assert "mission cancelled by the operator (~cancel)" in node.output(), node.output()


def test_bad_params_are_one_clear_error_and_exit_2(ros_master: RosMaster):
    node = start_node(ros_master, yea_seq=[90, 0])
    assert node.wait(timeout=30) == 2
    output = node.output()
    assert "yea_seq" in output and "3" in output and "2" in output
    assert "Traceback" not in output


def test_missing_action_server_is_a_clear_error(ros_master: RosMaster):
    node = start_node(ros_master, server_wait=0.5)
    assert node.wait(timeout=30) == 2
    assert "/move_base" in node.output() and ros_master.uri in node.output()
    assert "Traceback" not in node.output()


def test_keep_alive_keeps_markers_and_status_up_after_the_mission_until_sigint(
    ros_master: RosMaster, tmp_path: Path
):
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log)
    node = start_node(ros_master, keep_alive=True)
    status = watch_status(ros_master)
    wait_for(lambda: '\\"state\\": \\"succeeded\\"' in status.output(), 60, "mission end")
    assert node.running(), node.output()
    # A subscriber arriving after the mission still gets the final markers: all reached.
    markers = ros_master.start(
        ["rostopic", "echo", "-n", "1", "/navseq/waypoints/markers[0]/color"]
    )
    assert markers.wait(timeout=20) == 0, markers.output()
    assert "g: 0.75" in markers.output(), markers.output()  # green: reached
    late_status = ros_master.start(["rostopic", "echo", "-n", "1", "/navseq/status"])
    assert late_status.wait(timeout=20) == 0, late_status.output()
    assert '\\"state\\": \\"succeeded\\"' in late_status.output()
    for service in ("cancel", "skip", "pause"):
        response = ros_master.call_service(f"/navseq/{service}")
        assert not response["success"] and "mission has ended" in response["message"], response
    assert [d["status"] for d in events(log, "done")] == ["SUCCEEDED"] * 3
    # The mission was over: roslaunch's SIGINT interrupts nothing, the exit says success.
    assert node.stop(signal.SIGINT) == 0
    assert "Traceback" not in node.output()


def test_keep_alive_that_is_not_a_boolean_is_a_bad_param(ros_master: RosMaster):
    node = start_node(ros_master, keep_alive="sometimes")
    assert node.wait(timeout=30) == 2
    assert "keep_alive" in node.output() and "Traceback" not in node.output()


def test_end_launch_outside_roslaunch_signals_nobody_and_exits_with_the_mission(
    ros_master: RosMaster, tmp_path: Path
):
    """Under rosrun (here: the test's own process as parent) nobody is sent SIGINT."""
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log)
    node = start_node(ros_master, end_launch=True)
    assert node.wait(timeout=60) == 0, node.output()
    assert "~end_launch: the parent process" in node.output(), node.output()
    assert "is not roslaunch; the node just exits" in node.output(), node.output()


def test_confirm_service_confirms_the_input_task_waiting(ros_master: RosMaster, tmp_path: Path):
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "navseq: 1\nwaypoints:\n"
        "  - {x: 1, y: 0, tasks: [{input: {prompt: Load the tray}}]}\n"
        "  - {x: 2, y: 0}\n"
    )
    ros_master.set_param("/navseq/mission", str(mission))
    ros_master.set_param("/navseq/server_wait", 30)
    node = ros_master.start_python("-m", "navseq.ros1.navseq_node", label="navseq_node")
    # No action server yet: nothing waits for a confirmation, and none is kept for later.
    ros_master.wait_for_service("/navseq/confirm")
    early = ros_master.call_service("/navseq/confirm")
    assert early == {"success": False, "message": "no input task is waiting for a confirmation"}
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log)
    node.wait_for_output("Load the tray — call /navseq/confirm to go on", timeout=60)
    assert len(events(log, "goal")) == 1  # the robot waits at the first waypoint
    answer = ros_master.call_service("/navseq/confirm")
    assert answer == {"success": True, "message": "input confirmed; going on"}
    assert node.wait(timeout=60) == 0, node.output()
    assert len(events(log, "goal")) == 2


def test_skip_during_a_wait_for_ends_its_subscription_and_the_mission_goes_on(
    ros_master: RosMaster, tmp_path: Path
):
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "navseq: 1\nwaypoints:\n"
        "  - x: 1\n    y: 0\n    tasks:\n"
        "      - wait_for: {topic: /door/open, type: std_msgs/Bool, field: data, equals: true}\n"
        "        timeout: null\n"
        "  - {x: 2, y: 0}\n"
    )
    ros_master.set_param("/navseq/mission", str(mission))
    ros_master.set_param("/navseq/keep_alive", True)  # still up when the mission is over
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log)
    node = ros_master.start_python("-m", "navseq.ros1.navseq_node", label="navseq_node")
    ros_master.wait_for_subscriber("/door/open", timeout=60)  # the task waits
    answer = ros_master.call_service("/navseq/skip")
    assert answer["success"], answer
    node.wait_for_output("staying up", timeout=60)
    assert len(events(log, "goal")) == 2  # the mission went on
    # The node is still up, and no longer listens to the task's topic.
    wait_for(
        lambda: "/door/open" not in ros_master.system_state()[1], 10, "the subscription to end"
    )
    assert node.stop(signal.SIGINT) == 1, node.output()  # waypoint 1 skipped


def test_snapshots_go_into_the_snapshot_dir_and_without_one_are_refused(
    ros_master: RosMaster, tmp_path: Path
):
    mission = tmp_path / "m.yaml"
    mission.write_text(
        "navseq: 1\nwaypoints:\n"
        "  - name: dock\n    x: 1\n    y: 0\n    tasks:\n"
        "      - snapshot: {topic: /camera/image, type: sensor_msgs/Image}\n"
    )
    ros_master.set_param("/navseq/mission", str(mission))
    log = tmp_path / "server.jsonl"
    start_server(ros_master, log)
    refused = ros_master.start_python("-m", "navseq.ros1.navseq_node", label="navseq_node")
    assert refused.wait(timeout=60) == 2, refused.output()
    assert "m.yaml:7, waypoint 1 'dock', task 1 (snapshot)" in refused.output()
    assert "snapshot_dir" in refused.output()
    assert events(log, "goal") == []  # refused before the robot moved

    ros_master.start_python(TESTS / "ros_task_peer.py", "--log", str(tmp_path / "peer.jsonl"))
    ros_master.set_param("/navseq/snapshot_dir", str(tmp_path / "shots"))
    node = ros_master.start_python("-m", "navseq.ros1.navseq_node", label="navseq_node")
    assert node.wait(timeout=60) == 0, node.output()
    assert [p.name for p in (tmp_path / "shots" / "snapshots").iterdir()] == ["dock-task1.png"]
