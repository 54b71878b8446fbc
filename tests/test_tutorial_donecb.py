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

import json
import textwrap
import time
from pathlib import Path

import pytest

from ros_support import RosMaster

pytestmark = pytest.mark.ros

SERVER = Path(__file__).resolve().parent / "ros_scripted_server.py"
P_SEQ = [1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 3.0, 1.0, 0.0, 1.0, 2.0, 0.0]
YEA_SEQ = [0.0, 90.0, 180.0, -90.0]

# The tutorial's node, trimmed of its logging, with its structure and callback logic kept.
TUTORIAL_DONE_CB_CLIENT = textwrap.dedent(
    """
    import math
    import actionlib
    import rospy
    from geometry_msgs.msg import Point, Pose, Quaternion
    from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal


    def quaternion_from_euler(roll, pitch, yaw, axes="sxyz"):
        # Debian has no python3-tf; the tutorial only ever rotates about z.
        return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


    class MoveBaseSeq:
        def __init__(self):
            rospy.init_node("move_base_seq")
            points_seq = rospy.get_param("move_base_seq/p_seq")
            yaweulerangles_seq = rospy.get_param("move_base_seq/yea_seq")
            quat_seq = [
                Quaternion(*quaternion_from_euler(0, 0, yaw * math.pi / 180, axes="sxyz"))
                for yaw in yaweulerangles_seq
            ]
            self.pose_seq = []
            self.goal_cnt = 0
            points = [points_seq[i:i + 3] for i in range(0, len(points_seq), 3)]
            for n, point in enumerate(points):
                self.pose_seq.append(Pose(Point(*point), quat_seq[n]))
            self.client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
            if not self.client.wait_for_server(rospy.Duration(10.0)):
                rospy.signal_shutdown("Action server not available!")
                return
            self.movebase_client()

        def active_cb(self):
            pass

        def feedback_cb(self, feedback):
            pass

        def done_cb(self, status, result):
            self.goal_cnt += 1
            print("DONE %d status %d" % (self.goal_cnt, status), flush=True)
            if status == 3:
                if self.goal_cnt < len(self.pose_seq):
                    next_goal = MoveBaseGoal()
                    next_goal.target_pose.header.frame_id = "map"
                    next_goal.target_pose.header.stamp = rospy.Time.now()
                    next_goal.target_pose.pose = self.pose_seq[self.goal_cnt]
                    self.client.send_goal(next_goal, self.done_cb, self.active_cb,
                                          self.feedback_cb)
                else:
                    print("FINAL GOAL REACHED", flush=True)
                    rospy.signal_shutdown("Final goal pose reached!")
            else:
                rospy.signal_shutdown("goal failed")

        def movebase_client(self):
            goal = MoveBaseGoal()
            goal.target_pose.header.frame_id = "map"
            goal.target_pose.header.stamp = rospy.Time.now()
            goal.target_pose.pose = self.pose_seq[self.goal_cnt]
            self.client.send_goal(goal, self.done_cb, self.active_cb, self.feedback_cb)
            rospy.spin()


    if __name__ == "__main__":
        MoveBaseSeq()
    """
)

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
    records = [json.loads(line) for line in log.read_text().splitlines() if line.strip()]
    return [(r["x"], r["y"]) for r in records if r["event"] == "goal"]


def start_scripted_server(master: RosMaster, log: Path) -> None:
    server = master.start_python(SERVER, "--then", "succeed:0.3", "--log", str(log))
    server.wait_for_output("scripted move_base ready", timeout=20)


def test_plain_sequence_client_gets_every_goal_succeeded(ros_master: RosMaster, tmp_path):
    log = tmp_path / "server.jsonl"
    start_scripted_server(ros_master, log)
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
    start_scripted_server(ros_master, log)
    script = tmp_path / "move_base_seq.py"
    script.write_text(TUTORIAL_DONE_CB_CLIENT)
    ros_master.set_param("/move_base_seq/p_seq", P_SEQ)
    ros_master.set_param("/move_base_seq/yea_seq", YEA_SEQ)
    client = ros_master.start_python(script)
    client.wait_for_output("DONE 1 status 3", timeout=30)
    # Goal 2 is sent from inside done_cb and reaches SUCCEEDED on the server ...
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        records = [json.loads(line) for line in log.read_text().splitlines() if line]
        if [r["status"] for r in records if r["event"] == "done"] == ["SUCCEEDED"] * 2:
            break
        time.sleep(0.1)
    else:
        pytest.fail(f"goal 2 never succeeded on the server:\n{log.read_text()}")
    # ... but its result never reaches done_cb: bounded wait (10x a goal's duration).
    time.sleep(3.0)
    assert client.running(), client.output()
    assert "DONE 2" not in client.output()
    assert goals_received(log) == [(1.0, 0.0), (2.0, 0.0)]
