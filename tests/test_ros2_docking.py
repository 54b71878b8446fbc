"""Docking on the ROS 2 simulator node (``--docks``): ``dock_robot`` / ``undock_robot``
through real rclpy clients (``tests/ros2_clients.py dock`` / ``undock``), the ``ros2
action send_goal`` a Nav2 user types, and the error codes opennav_docking gives. Robot
at (-2, -0.5) facing +x; docks of ``examples/turtlebot3_docks.yaml``: ``home_dock`` at
(-0.5, -0.5) and ``north_dock`` at (-0.5, 0.5), both facing +x, staging 0.7 m west."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from nav2_real_support import nav2_missing_reason, nav2_prefix
from ros2_support import ros2_environment, ros2_prefix
from test_ros2_sim import MAP, REPO, SPEED, START, SimProcess

pytestmark = pytest.mark.ros2

DOCKS = REPO / "examples" / "turtlebot3_docks.yaml"
COMMANDER = Path(__file__).with_name("nav2") / "commander_docking.py"
DOCKING = [1, 2, 3, 4]  # NAV_TO_STAGING_POSE, INITIAL_PERCEPTION, CONTROLLING, WAIT_FOR_CHARGE


@pytest.fixture
def sim() -> Iterator[SimProcess]:
    prefix = ros2_prefix()
    assert prefix is not None
    node = SimProcess(
        ros2_environment(prefix),
        "--map",
        str(MAP),
        f"--start={START}",
        "--speed",
        SPEED,
        "--docks",
        str(DOCKS),
    )
    yield node
    err = node.stop()
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


def _at(pose: list[float] | None, x: float, y: float, slack: float) -> bool:
    return pose is not None and math.hypot(pose[0] - x, pose[1] - y) <= slack


def test_docking_by_id_stages_approaches_and_undocking_backs_out(sim: SimProcess) -> None:
    docked = sim.client("dock", "home_dock")
    assert (docked["status"], docked["success"], docked["error_code"]) == ("SUCCEEDED", True, 0)
    assert docked["states"] == DOCKING  # staging, perception, approach, charging, in order
    assert _at(docked["pose"], -0.5, -0.5, 0.05)  # within the docking threshold
    undocked = sim.client("undock")
    assert (undocked["status"], undocked["success"], undocked["error_code"]) == (
        "SUCCEEDED",
        True,
        0,
    )
    assert _at(undocked["pose"], -1.2, -0.5, 0.08)  # the staging pose, 0.7 m back
    assert abs(undocked["pose"][2]) < 0.1  # still facing the dock


def test_a_robot_already_docked_or_not_docked_is_left_where_it_is(sim: SimProcess) -> None:
    # opennav_docking returns without a result: the action server ends the goal ABORTED
    # with the default result (success true, code 0).
    not_docked = sim.client("undock")
    assert (not_docked["status"], not_docked["success"], not_docked["error_code"]) == (
        "ABORTED",
        True,
        0,
    )
    assert _at(not_docked["pose"], -2.0, -0.5, 0.01)
    assert sim.client("dock", "north_dock")["status"] == "SUCCEEDED"
    again = sim.client("dock", "home_dock")  # the plugin still sees the robot docked
    assert (again["status"], again["error_code"]) == ("ABORTED", 0)
    assert _at(again["pose"], -0.5, 0.5, 0.05)


def test_goals_nav2_refuses_end_with_its_docking_codes(sim: SimProcess) -> None:
    unknown = sim.client("dock", "garage")
    assert (unknown["status"], unknown["success"], unknown["error_code"]) == (
        "ABORTED",
        False,
        901,  # DOCK_NOT_IN_DB
    )
    in_nowhere = sim.client("dock", "-0.5,-0.5,0", frame="nowhere")
    assert (in_nowhere["status"], in_nowhere["error_code"]) == ("ABORTED", 999)  # UNKNOWN
    # A dock by pose, no staging navigation, the pillar at (-1.1, 0) in between: the
    # controller cannot get there.
    blocked = sim.client("dock", "-0.1,0.05,0", value=1)
    assert (blocked["status"], blocked["error_code"]) == ("ABORTED", 905)  # FAILED_TO_CONTROL
    assert _at(blocked["pose"], -2.0, -0.5, 0.01)
    # A staging pose in the wall south-west: the navigation to it fails.
    walled = sim.client("dock", "-1.7,-2.3,0")
    assert (walled["status"], walled["error_code"]) == ("ABORTED", 903)  # FAILED_TO_STAGE


def test_a_cancelled_docking_ends_canceled(sim: SimProcess) -> None:
    seen = sim.client("dock", "north_dock", cancel_after=1.0)
    assert (seen["status"], seen["success"]) == ("CANCELED", False)
    assert not _at(seen["pose"], -0.5, 0.5, 0.3)


def test_ros2_action_send_goal_docks_and_undocks(sim: SimProcess) -> None:
    for action, kind, goal in (
        ("/dock_robot", "nav2_msgs/action/DockRobot", "{dock_id: home_dock}"),
        ("/undock_robot", "nav2_msgs/action/UndockRobot", "{}"),
    ):
        done = subprocess.run(
            ["ros2", "action", "send_goal", action, kind, goal],
            env=sim.env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == 0, done.stderr
        assert "Goal accepted" in done.stdout
        assert "Goal finished with status: SUCCEEDED" in done.stdout, done.stdout
        assert "success: true" in done.stdout


def test_nav2_simple_commander_runs_assisted_teleop_docks_and_undocks_unchanged() -> None:
    """example_assisted_teleop's assistedTeleop (ended by its time allowance: FAILED, as
    on Nav2), then dockRobotByID, undockRobot and dockRobotByPose: each call returns."""
    reason = nav2_missing_reason()
    if reason is not None:
        pytest.skip(reason)
    prefix = nav2_prefix()
    assert prefix is not None
    node = SimProcess(
        ros2_environment(prefix),
        "--map",
        str(MAP),
        f"--start={START}",
        "--speed",
        SPEED,
        "--docks",
        str(DOCKS),
    )
    try:
        done = subprocess.run(
            [sys.executable, str(COMMANDER)],
            env=node.env,
            capture_output=True,
            text=True,
            timeout=180,
        )
    finally:
        err = node.stop()
    assert done.returncode == 0, done.stderr[-3000:]
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert seen == {
        "assistedTeleop accepted": True,
        "assistedTeleop": "FAILED",  # TIMEOUT after its 2 s
        "dockRobotByID": "SUCCEEDED",
        "undockRobot": "SUCCEEDED",
        "dockRobotByPose": "SUCCEEDED",
    }
    assert "Robot is charging!" in err and "Robot has undocked!" in err
    assert "Traceback" not in err


def test_an_inactive_docking_server_rejects_goals_as_nav2s_does(sim: SimProcess) -> None:
    def run(*command: str) -> str:
        done = subprocess.run(command, env=sim.env, capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        return done.stdout

    deactivate = "{transition: {id: 4}}"  # lifecycle_msgs/Transition DEACTIVATE
    run("ros2", "service", "call", "/docking_server/change_state",
        "lifecycle_msgs/srv/ChangeState", deactivate)  # fmt: skip
    refused = run(
        "ros2", "action", "send_goal", "/dock_robot", "nav2_msgs/action/DockRobot",
        "{dock_id: home_dock}",
    )  # fmt: skip
    assert "Goal was rejected" in refused, refused
