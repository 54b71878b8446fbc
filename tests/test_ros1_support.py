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
