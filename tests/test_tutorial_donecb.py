"""Why navseq never sends goals from an actionlib callback (ros/actionlib issue 193).

The classic ``move_base_seq.py`` tutorial sends the next goal from inside
``SimpleActionClient``'s ``done_cb``. Noetic's actionlib sets the simple state to DONE
*after* ``done_cb`` returns, so the goal sent inside it is tracked in the DONE state and
its result never reaches ``done_cb``: the tutorial reaches its second goal and then
waits forever. A plain sequence client (send, ``wait_for_result``, next) has no such
problem. Both are real rospy clients against the scripted move_base server; the node
clients below are written out to files and run as subprocesses.
"""

from __future__ import annotations

import textwrap
import time
from pathlib import Path

import pytest

from ros_clients import TUTORIAL_DONE_CB_CLIENT, server_log, start_scripted_server
from ros_support import RosMaster

pytestmark = pytest.mark.ros

P_SEQ = [1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 3.0, 1.0, 0.0, 1.0, 2.0, 0.0]
YEA_SEQ = [0.0, 90.0, 180.0, -90.0]

# The same sequence done right: wait for each result on the main thread, then send.
SEQUENCE_CLIENT = textwrap.dedent(
    """
    import math
    import actionlib
    import rospy
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

    rospy.init_node("sequence_client")
    points = rospy.get_param("~p_seq")
    yaws = rospy.get_param("~yea_seq")
    client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
    assert client.wait_for_server(rospy.Duration(10.0))
    for n, yaw in enumerate(yaws):
        goal = MoveBaseGoal()
        goal.target_pose.header.frame_id = "map"
        goal.target_pose.header.stamp = rospy.Time.now()
        x, y, z = points[3 * n:3 * n + 3]
        goal.target_pose.pose.position.x, goal.target_pose.pose.position.y = x, y
        goal.target_pose.pose.orientation.z = math.sin(math.radians(yaw) / 2)
        goal.target_pose.pose.orientation.w = math.cos(math.radians(yaw) / 2)
        client.send_goal(goal)
        assert client.wait_for_result(rospy.Duration(30.0))
        print("DONE %d status %d" % (n + 1, client.get_state()), flush=True)
    print("FINAL GOAL REACHED", flush=True)
    """
)


def goals_received(log: Path) -> list[tuple[float, float]]:
    return [(r["x"], r["y"]) for r in server_log(log) if r["event"] == "goal"]


def start_succeeding_server(master: RosMaster, log: Path) -> None:
    start_scripted_server(master, "--then", "succeed:0.3", "--log", str(log))


def test_plain_sequence_client_gets_every_goal_succeeded(ros_master: RosMaster, tmp_path):
    log = tmp_path / "server.jsonl"
    start_succeeding_server(ros_master, log)
    script = tmp_path / "sequence_client.py"
    script.write_text(SEQUENCE_CLIENT)
    ros_master.set_param("/sequence_client/p_seq", P_SEQ)
    ros_master.set_param("/sequence_client/yea_seq", YEA_SEQ)
    client = ros_master.start_python(script)
    assert client.wait(timeout=60) == 0, client.output()
    assert [f"DONE {n} status 3" in client.output() for n in (1, 2, 3, 4)] == [True] * 4
    assert len(goals_received(log)) == 4


def test_tutorial_done_cb_client_stalls_after_its_second_goal(ros_master: RosMaster, tmp_path):
    log = tmp_path / "server.jsonl"
    start_succeeding_server(ros_master, log)
    script = tmp_path / "move_base_seq.py"
    script.write_text(TUTORIAL_DONE_CB_CLIENT)
    ros_master.set_param("/move_base_seq/p_seq", P_SEQ)
    ros_master.set_param("/move_base_seq/yea_seq", YEA_SEQ)
    client = ros_master.start_python(script)
    client.wait_for_output("DONE 1 status 3", timeout=30)
    # Goal 2 is sent from inside done_cb and reaches SUCCEEDED on the server ...
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        if [r["status"] for r in server_log(log) if r["event"] == "done"] == ["SUCCEEDED"] * 2:
            break
        time.sleep(0.1)
    else:
        pytest.fail(f"goal 2 never succeeded on the server:\n{log.read_text()}")
    # ... but its result never reaches done_cb: bounded wait (10x a goal's duration).
    time.sleep(3.0)
    assert client.running(), client.output()
    assert "DONE 2" not in client.output()
    assert goals_received(log) == [(1.0, 0.0), (2.0, 0.0)]
