"""The ROS 2 command line against ``navseq sim --ros2`` (issue 20): ``ros2 action
send_goal`` with a short valid goal for every action the stand-in serves, and Nav2's
lifecycle services under Nav2's node names as ``ros2 lifecycle get`` would ask them.

The test machine's minimal ROS 2 has no ``ros2 lifecycle`` verb (ros2lifecycle is not in
it), so its requests go through ``ros2 service call``: ``get_state`` is what ``ros2
lifecycle get NODE`` calls, and the managers' ``is_active`` what Nav2's tools ask.

One stand-in serves the whole module (the TurtleBot3 arena, the robot at (-2, -0.5)
facing +x, the docks of ``examples/turtlebot3_docks.yaml`` and ``examples/gps.yaml``'s
datum); the goals run in the order listed, each leaving the robot on a free lane.
"""

from __future__ import annotations

import re
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from cli_support import EXAMPLES
from ros2_support import SimNode, ros2_environment, ros2_prefix
from test_ros2_gps import DATUM, SOUTH_GATE
from test_ros2_sim import MAP, SPEED, START

pytestmark = pytest.mark.ros2

BRINGUP = Path(__file__).with_name("data") / "nav2_bringup_interfaces.yaml"
DOCKS = EXAMPLES / "turtlebot3_docks.yaml"
ROUTE_GRAPH = EXAMPLES / "turtlebot3_route_graph.geojson"
CLI_TIMEOUT = 120  # wall s: the CLI's start, discovery and the goal at the stand-in's speed


def _pose(x: float, y: float) -> str:
    position = f"{{x: {x}, y: {y}}}"
    return f"{{header: {{frame_id: map}}, pose: {{position: {position}, orientation: {{w: 1.0}}}}}}"


def _path(*points: tuple[float, float]) -> str:
    return f"{{header: {{frame_id: map}}, poses: [{', '.join(_pose(x, y) for x, y in points)}]}}"


LAT, LON = SOUTH_GATE.split(",")
#: (action, type, goal, the status ``ros2 action send_goal`` ends with), in run order.
GOALS = [
    ("navigate_to_pose", "NavigateToPose", f"{{pose: {_pose(-1.5, -0.5)}}}", "SUCCEEDED"),
    (
        "navigate_through_poses",
        "NavigateThroughPoses",
        f"{{poses: [{_pose(-1.2, -0.5)}, {_pose(-1.5, -0.5)}]}}",
        "SUCCEEDED",
    ),
    ("follow_waypoints", "FollowWaypoints", f"{{poses: [{_pose(-1.8, -0.5)}]}}", "SUCCEEDED"),
    ("compute_path_to_pose", "ComputePathToPose", f"{{goal: {_pose(-0.55, -0.55)}}}", "SUCCEEDED"),
    (
        "compute_path_through_poses",
        "ComputePathThroughPoses",
        f"{{goals: [{_pose(-0.55, -0.55)}, {_pose(-0.55, 0.55)}]}}",
        "SUCCEEDED",
    ),
    (
        "smooth_path",
        "SmoothPath",
        f"{{path: {_path((-1.8, -0.5), (-1.6, -0.45), (-1.4, -0.5))}}}",
        "SUCCEEDED",
    ),
    (
        "follow_path",
        "FollowPath",
        f"{{path: {_path((-1.8, -0.5), (-1.65, -0.5), (-1.5, -0.5))}}}",
        "SUCCEEDED",
    ),
    ("spin", "Spin", "{target_yaw: 0.5, time_allowance: {sec: 10}}", "SUCCEEDED"),
    ("backup", "BackUp", "{target: {x: 0.1}, speed: 0.05, time_allowance: {sec: 10}}", "SUCCEEDED"),
    (
        "drive_on_heading",
        "DriveOnHeading",
        "{target: {x: 0.1}, speed: 0.05, time_allowance: {sec: 10}}",
        "SUCCEEDED",
    ),
    ("wait", "Wait", "{time: {sec: 1}}", "SUCCEEDED"),
    # No operator command comes: the behaviour runs out its time allowance and ends as
    # Nav2's does, ABORTED with TIMEOUT.
    ("assisted_teleop", "AssistedTeleop", "{time_allowance: {sec: 1}}", "ABORTED"),
    (
        "dock_robot",
        "DockRobot",
        "{use_dock_id: true, dock_id: home_dock, navigate_to_staging_pose: true}",
        "SUCCEEDED",
    ),
    ("undock_robot", "UndockRobot", "{dock_type: ''}", "SUCCEEDED"),
    (
        "follow_gps_waypoints",
        "FollowGPSWaypoints",
        f"{{gps_poses: [{{position: {{latitude: {LAT}, longitude: {LON}}}}}]}}",
        "SUCCEEDED",
    ),
    ("compute_route", "ComputeRoute", "{start_id: 1, goal_id: 10}", "SUCCEEDED"),
    # Tracking ends when the robot, driven by another client along the route, arrives;
    # a goal to a node the graph lacks ends at once, as the route server's do.
    ("compute_and_track_route", "ComputeAndTrackRoute", "{start_id: 1, goal_id: 99}", "ABORTED"),
]
#: nav2_bringup's lifecycle nodes (navigation and localization).
LIFECYCLE_NODES = [
    "controller_server",
    "smoother_server",
    "planner_server",
    "route_server",
    "behavior_server",
    "velocity_smoother",
    "collision_monitor",
    "bt_navigator",
    "waypoint_follower",
    "docking_server",
    "map_server",
    "amcl",
]
STATUS_LINE = re.compile(r"^Goal finished with status: (\w+)$", re.MULTILINE)


@pytest.fixture(scope="module")
def standin() -> Iterator[SimNode]:
    prefix = ros2_prefix()
    assert prefix is not None
    env = ros2_environment(prefix)
    args = ["--map", str(MAP), f"--start={START}", "--speed", SPEED]
    node = SimNode(
        env, *args, "--docks", str(DOCKS), "--datum", DATUM, "--route-graph", str(ROUTE_GRAPH)
    )
    yield node
    err = node.stop()
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


def ros2(standin: SimNode, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["ros2", *args],
        env=standin.env,
        capture_output=True,
        text=True,
        timeout=CLI_TIMEOUT,
    )


def test_every_action_a_default_bringup_serves_but_the_known_gaps_gets_a_goal() -> None:
    """``tests/test_ros2_interfaces.py`` holds the served list to this data: so no action
    served is left without a ``send_goal`` below."""
    data = yaml.safe_load(BRINGUP.read_text())
    served = {
        name: kind for name, kind in data["actions"].items() if name not in data["gaps"]["actions"]
    }
    assert served == {action: f"nav2_msgs/action/{kind}" for action, kind, _, _ in GOALS}


@pytest.mark.parametrize(
    ("action", "kind", "goal", "status"), GOALS, ids=[goal[0] for goal in GOALS]
)
def test_ros2_action_send_goal(
    standin: SimNode, action: str, kind: str, goal: str, status: str
) -> None:
    sent = ros2(standin, "action", "send_goal", f"/{action}", f"nav2_msgs/action/{kind}", goal)
    assert sent.returncode == 0, sent.stderr
    assert "Goal accepted" in sent.stdout, sent.stdout
    assert STATUS_LINE.findall(sent.stdout) == [status], sent.stdout


@pytest.mark.parametrize("node", LIFECYCLE_NODES)
def test_nav2s_lifecycle_nodes_say_they_are_active(standin: SimNode, node: str) -> None:
    got = ros2(standin, "service", "call", f"/{node}/get_state", "lifecycle_msgs/srv/GetState")
    assert got.returncode == 0, got.stderr
    assert "id=3, label='active'" in got.stdout, got.stdout  # PRIMARY_STATE_ACTIVE


@pytest.mark.parametrize("manager", ["navigation", "localization"])
def test_both_lifecycle_managers_say_the_stack_is_active(standin: SimNode, manager: str) -> None:
    service = f"/lifecycle_manager_{manager}/is_active"
    got = ros2(standin, "service", "call", service, "std_srvs/srv/Trigger")
    assert got.returncode == 0, got.stderr
    assert "success=True" in got.stdout, got.stdout
