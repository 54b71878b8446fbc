"""The ROS 2 the tests run against: present where CI unpacked it, and isolated per run."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from ros2_support import ros2_available, ros2_environment, ros2_prefix

AVAILABLE, MISSING_REASON = ros2_available()

# `.ci/run` sets this after unpacking ROS 2: from then on a missing ROS 2 is a failure,
# not a skip, so the ros2 tests cannot silently stop running.
EXPECTED = os.environ.get("NAVSEQ_EXPECT_ROS2") == "1"

ROUND_TRIP = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String
from nav2_msgs.action import NavigateToPose

rclpy.init()
node = Node("navseq_env_probe")
got = []
node.create_subscription(String, "probe", lambda msg: got.append(msg.data), 10)
pub = node.create_publisher(String, "probe", 10)
for _ in range(100):
    pub.publish(String(data="hello"))
    rclpy.spin_once(node, timeout_sec=0.05)
    if got:
        break
print(got[0] if got else "nothing", NavigateToPose.Goal().pose.header.frame_id == "")
node.destroy_node()
rclpy.shutdown()
"""


def test_ros2_is_there_when_ci_installed_it() -> None:
    if not EXPECTED:
        pytest.skip("NAVSEQ_EXPECT_ROS2 is not set (CI sets it after unpacking ROS 2)")
    assert AVAILABLE, MISSING_REASON


@pytest.mark.ros2
def test_a_ros2_process_talks_to_itself_on_a_private_domain() -> None:
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix, domain_id=77)
    assert env["ROS_DOMAIN_ID"] == "77"
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    result = subprocess.run(
        [sys.executable, "-c", ROUND_TRIP], env=env, capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["hello", "True"]
