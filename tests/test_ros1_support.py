"""The ROS test harness itself: a private master, node processes, clean shutdown."""

from __future__ import annotations

import signal
import textwrap

import pytest

from ros_support import RosMaster, port_is_free, running_master

pytestmark = pytest.mark.ros

TALKER = textwrap.dedent(
    """
    import rospy
    from std_msgs.msg import String
    rospy.init_node("talker")
    pub = rospy.Publisher("chatter", String, queue_size=1, latch=True)
    pub.publish(String(rospy.get_param("~greeting", "none")))
    print("talker up", flush=True)
    rospy.spin()
    """
)


def test_nodes_talk_to_the_private_master_and_stop_cleanly(ros_master: RosMaster, tmp_path):
    script = tmp_path / "talker.py"
    script.write_text(TALKER)
    ros_master.set_param("/talker/greeting", "hello")
    talker = ros_master.start_python(script)
    talker.wait_for_output("talker up", timeout=20)
    ros_master.wait_for_publisher("/chatter")
    assert "/talker" in ros_master.node_names()
    assert ros_master.get_param("/talker/greeting") == "hello"
    talker.stop(signal.SIGINT)
    assert not talker.running()


def test_master_port_is_released_after_shutdown(tmp_path):
    pytest.importorskip("rospy")
    with running_master(tmp_path / "ros") as master:
        port = master.port
        assert master.master_online()
        assert not port_is_free(port)
    assert port_is_free(port)


# A launcher that starts its "node" in a session of its own, as roslaunch does, then is
# killed before it could stop it: the node must not outlive the test's master.
LAUNCHER = textwrap.dedent(
    """
    import subprocess, sys, time
    stubborn = "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); time.sleep(600)"
    node = subprocess.Popen([sys.executable, "-c", stubborn], start_new_session=True)
    print(node.pid, flush=True)
    time.sleep(600)
    """
)


def test_a_node_its_launcher_left_behind_is_stopped_with_the_master(tmp_path):
    with running_master(tmp_path / "ros") as master:
        script = tmp_path / "launcher.py"
        script.write_text(LAUNCHER)
        launcher = master.start_python(script)
        pid = int(wait_for_first_line(launcher))
        launcher.stop(signal.SIGKILL, timeout=5)  # roslaunch killed: its node orphaned
        assert alive(pid)  # the premise: still running after its launcher is gone
    assert not alive(pid)


def alive(pid: int) -> bool:
    """Running (not gone, not a zombie waiting to be reaped)."""
    from pathlib import Path

    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "\nState:\tZ" not in status


def wait_for_first_line(process) -> str:
    from ros_support import wait_for

    return wait_for(lambda: process.output().strip().splitlines()[:1], 20, "the pid")[0]
