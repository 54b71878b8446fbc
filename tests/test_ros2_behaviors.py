"""Nav2's behaviours (spin, backup, drive_on_heading, wait, assisted_teleop) on the ROS 2
simulator node, through real rclpy action clients (``tests/ros2_clients.py behavior``), as
nav2_simple_commander's ``spin()`` / ``backup()`` / ``driveOnHeading()`` / ``wait()``
send them. The cases and Nav2's answers are ``tests/nav2_behavior_cases.py``'s, which
``tests/test_nav2_real.py`` holds against the real behaviour server.
"""

from __future__ import annotations

import subprocess
from collections.abc import Iterator

import pytest

from nav2_behavior_cases import CASES, BehaviorCase
from ros2_support import ros2_environment, ros2_prefix
from test_ros2_sim import MAP, SPEED, START, SimProcess

pytestmark = pytest.mark.ros2


@pytest.fixture
def sim() -> Iterator[SimProcess]:
    prefix = ros2_prefix()
    assert prefix is not None
    node = SimProcess(
        ros2_environment(prefix), "--map", str(MAP), f"--start={START}", "--speed", SPEED
    )
    yield node
    err = node.stop()
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


@pytest.mark.parametrize("case", CASES, ids=[case.name for case in CASES])
def test_the_stand_in_answers_a_behaviour_goal_as_nav2_does(
    sim: SimProcess, case: BehaviorCase
) -> None:
    seen = sim.client("behavior", case.kind, **case.options)
    assert (seen["status"], seen["error_code"]) == (case.status, case.error_code), seen
    assert case.check(seen), seen


def test_spin_and_drive_feedback_grows_as_the_robot_goes(sim: SimProcess) -> None:
    # Long enough at the node's 4x for several feedback messages (every 0.1 s of wall time).
    spun = sim.client("behavior", "spin", value=6.0)
    turned = [f["angular_distance_traveled"] for f in spun["feedback"]]
    assert len(turned) >= 3 and turned == sorted(turned)
    ahead = sim.client("behavior", "drive_on_heading", value=0.4, speed=0.05)
    driven = [f["distance_traveled"] for f in ahead["feedback"]]
    assert len(driven) >= 3 and driven == sorted(driven)


def test_wait_lasts_its_time(sim: SimProcess) -> None:
    seen = sim.client("behavior", "wait", value=2.0)
    assert seen["status"] == "SUCCEEDED"
    assert seen["took"] >= 2.0 / float(SPEED)  # simulated seconds at the node's speed


def test_ros2_action_send_goal_runs_assisted_teleop_until_its_allowance(sim: SimProcess) -> None:
    done = subprocess.run(
        [
            "ros2",
            "action",
            "send_goal",
            "/assisted_teleop",
            "nav2_msgs/action/AssistedTeleop",
            "{time_allowance: {sec: 2}}",
            "--feedback",
        ],
        env=sim.env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert "current_teleop_duration" in done.stdout  # feedback: the time it has run
    assert "Goal finished with status: ABORTED" in done.stdout, done.stdout
    assert "error_code: 731" in done.stdout  # TIMEOUT
