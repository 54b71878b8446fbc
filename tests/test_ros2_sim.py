"""The ROS 2 simulator node against real rclpy clients (tests/ros2_clients.py).

Every test starts its own node (``python -m navseq.ros2.sim_node``) on a private
ROS_DOMAIN_ID, at 4x speed, on the TurtleBot3 world with the robot at (-2, -0.5)
facing +x, and stops it with SIGINT at the end: the node must then exit 0 without a
traceback.
"""

from __future__ import annotations

import itertools
import json
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from navseq.sim.occupancy import load_map
from ros2_support import SimNode, ros2_environment, ros2_prefix

pytestmark = pytest.mark.ros2

REPO = Path(__file__).resolve().parents[1]
MAP = REPO / "maps" / "turtlebot3_world.yaml"
CLIENTS = Path(__file__).with_name("ros2_clients.py")
START = "-2,-0.5,0"
SPEED = "4"


class SimProcess(SimNode):
    """A running sim node, and Nav2 clients run against it (``tests/ros2_clients.py``)."""

    def client(self, verb: str, *poses: str, **options: Any) -> dict[str, Any]:
        done = subprocess.run(
            client_command(verb, poses, options),
            env=self.env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == 0, done.stderr
        return dict(json.loads(done.stdout.strip().splitlines()[-1]))

    def client_async(self, verb: str, *poses: str, **options: Any) -> subprocess.Popen[str]:
        return subprocess.Popen(
            client_command(verb, poses, options),
            env=self.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )


def client_command(verb: str, poses: tuple[str, ...], options: dict[str, Any]) -> list[str]:
    """Options first, then ``--``: poses like ``-2,0,0`` are not options."""
    command = [sys.executable, str(CLIENTS)]
    for key, value in options.items():
        command += [f"--{key.replace('_', '-')}", str(value)]
    return [*command, verb, "--", *poses]


def collect(process: subprocess.Popen[str]) -> dict[str, Any]:
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    return dict(json.loads(out.strip().splitlines()[-1]))


@pytest.fixture
def env() -> dict[str, str]:
    prefix = ros2_prefix()
    assert prefix is not None
    return ros2_environment(prefix)


@pytest.fixture
def sim(env: dict[str, str]) -> Iterator[SimProcess]:
    node = SimProcess(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED)
    yield node
    err = node.stop()
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


def test_navigate_to_pose_reaches_the_goal_with_feedback_getting_closer(sim: SimProcess):
    seen = sim.client("navigate", "-0.8,-0.5,90")
    assert seen["status"] == "SUCCEEDED"
    assert seen["error_code"] == 0
    distances = [f["distance_remaining"] for f in seen["feedback"]]
    assert len(distances) >= 5
    assert distances[0] > 0.9
    assert distances[-1] < 0.3
    assert all(later <= earlier + 0.05 for earlier, later in itertools.pairwise(distances))
    times = [f["navigation_time"] for f in seen["feedback"]]
    assert times == sorted(times) and times[-1] > 3.0  # simulated seconds: 1.2 m at 0.22 m/s
    assert any(f["eta"] > 0 for f in seen["feedback"])
    assert {f["frame"] for f in seen["feedback"]} == {"map"}


def test_a_goal_deep_in_a_wall_is_aborted_with_nav2s_planner_code(sim: SimProcess):
    # Farther than the planner's tolerance (0.5 m) from any free cell.
    seen = sim.client("navigate", "-2.3,-2.3,0")
    assert seen["status"] == "ABORTED"
    assert seen["error_code"] == 206  # ComputePathToPose GOAL_OCCUPIED
    assert "obstacle" in seen["error_msg"]


def test_a_goal_in_a_pillar_succeeds_at_the_nearest_free_cell_as_nav2s_does(sim: SimProcess):
    # Nav2 Jazzy (NavFn, tolerance 0.5 m) plans to a free cell near it and SUCCEEDS there.
    seen = sim.client("navigate", "-1.1,0,0")
    assert (seen["status"], seen["error_code"], seen["error_msg"]) == ("SUCCEEDED", 0, "")
    assert -1.7 < seen["feedback"][-1]["x"] < -1.3  # short of the pillar (-1.1), west of it


def test_a_goal_in_an_unknown_frame_ends_aborted_without_code_or_message_as_in_nav2(
    env: dict[str, str],
):
    node = SimProcess(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED)
    try:
        seen = node.client("navigate", "-0.8,-0.5,0", frame="nowhere")
    finally:
        err = node.stop()
    assert (seen["status"], seen["error_code"], seen["error_msg"]) == ("ABORTED", 0, "")
    assert "frame 'nowhere' is not 'map'" in err  # the reason is in the node's log


def test_a_client_cancel_ends_canceled_and_the_robot_stops(sim: SimProcess):
    seen = sim.client("navigate", "2,0.5,0", cancel_after=2.0)
    assert seen["cancel_accepted"] is True
    assert seen["status"] == "CANCELED"
    assert seen["x_before_cancel"] > -1.95  # it was driving when canceled
    assert seen["stopped_after"] is not None and seen["stopped_after"] < 1.0, seen
    assert seen["moving_at_end"] is False


def test_a_second_clients_goal_preempts_the_first_which_ends_aborted(sim: SimProcess):
    first = sim.client_async("navigate", "2,0.5,0")
    second = sim.client_async("navigate", "-1.2,-0.5,0", delay=3.0)
    first_seen, second_seen = collect(first), collect(second)
    assert first_seen["status"] == "ABORTED"  # Nav2's accept_pending_goal aborts it
    assert first_seen["error_code"] == 0
    assert second_seen["status"] == "SUCCEEDED"


def test_the_map_is_transient_local_so_a_late_subscriber_gets_it(sim: SimProcess):
    seen = sim.client("map", timeout=20)
    assert seen["map"] == [384, 384, 0.05]
    assert seen["frame"] == "map"
    grid = load_map(MAP)  # the same cells as the file: free, occupied, unknown
    assert seen["cells"] == {str(v): int((grid.data == v).sum()) for v in (-1, 0, 100)}


def test_nav2_clients_find_it_ready_localized_and_can_clear_costmaps(sim: SimProcess):
    seen = sim.client("ready", "-1.5,-0.5,90", timeout=20)
    assert seen["bt_navigator"] == "active"
    assert seen["amcl"] == "active"
    assert seen["amcl_pose"] == pytest.approx([-1.5, -0.5], abs=1e-6)  # the estimate, set there
    assert seen["global_costmap"] == seen["local_costmap"] == "cleared"


def test_navigate_through_poses_passes_the_first_pose_and_stops_at_the_last(sim: SimProcess):
    seen = sim.client("through", "-1.2,-0.5,0", "-0.5,-1.7,0")
    assert seen["status"] == "SUCCEEDED"
    remaining = [f["number_of_poses_remaining"] for f in seen["feedback"]]
    assert remaining[0] == 2 and remaining[-1] == 1
    assert remaining == sorted(remaining, reverse=True)


def test_follow_waypoints_lists_a_missed_waypoint(sim: SimProcess, env: dict[str, str]):
    # Nav2's default stop_on_failure: the mission ends at the waypoint in the wall.
    seen = sim.client("waypoints", "-1.5,-0.5,0", "-2.3,-2.3,0", "-1.0,-0.5,0")
    assert seen["status"] == "ABORTED"
    assert seen["missed"] == [{"index": 1, "error_code": 206}]
    assert {f["current_waypoint"] for f in seen["feedback"]} <= {0, 1}  # never on to 2


def test_follow_waypoints_goes_on_without_stop_on_failure(env: dict[str, str]):
    sim = SimProcess(
        env,
        "--map",
        str(MAP),
        f"--start={START}",
        "--speed",
        SPEED,
        "--ros-args",
        "-p",
        "stop_on_failure:=false",
    )
    try:
        seen = sim.client("waypoints", "-1.5,-0.5,0", "-2.3,-2.3,0", "-1.0,-0.5,0")
    finally:
        err = sim.stop(signal.SIGTERM)
        code = sim.process.returncode
    assert seen["status"] == "SUCCEEDED"
    assert seen["missed"] == [{"index": 1, "error_code": 206}]
    assert 2 in {f["current_waypoint"] for f in seen["feedback"]}  # went on past it
    assert code == 0, err


def test_compute_path_to_pose_plans_from_the_robot(sim: SimProcess):
    seen = sim.client("path", "-0.5,-1.7,0")
    assert seen["status"] == "SUCCEEDED"
    assert seen["frame"] == "map"
    assert seen["points"] > 10
    assert seen["last"] == pytest.approx([-0.5, -1.7], abs=1e-6)
    blocked = sim.client("path", "-2.3,-2.3,0")
    assert blocked["status"] == "ABORTED"
    assert blocked["error_code"] == 206
    near = sim.client("path", "-1.1,0,0")  # in the pillar: to a free cell within 0.5 m
    assert near["status"] == "SUCCEEDED"
    assert 0.0 < abs(near["last"][0] - -1.1) + abs(near["last"][1]) <= 0.75


def test_a_namespaced_robot_serves_under_its_namespace(env: dict[str, str]):
    sim = SimProcess(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED, "--ns", "robot1")
    try:
        seen = sim.client("navigate", "-1.4,-0.5,0", ns="robot1")
        ready = sim.client("ready", "-1.5,-0.5,0", ns="robot1", timeout=20)
        late = sim.client("map", ns="robot1", timeout=20)
    finally:
        err = sim.stop()
        code = sim.process.returncode
    assert seen["status"] == "SUCCEEDED"
    assert ready["bt_navigator"] == "active"
    assert late["map"] == [384, 384, 0.05]
    assert code == 0, err


def test_the_ros2_cli_command_of_the_docs_drives_it(sim: SimProcess):
    """docs/ros2.md's `ros2 action send_goal` line, as a user would type it."""
    done = subprocess.run(
        [
            "ros2",
            "action",
            "send_goal",
            "/navigate_to_pose",
            "nav2_msgs/action/NavigateToPose",
            "{pose: {header: {frame_id: map}, pose: {position: {x: -1.5, y: -0.5}, "
            "orientation: {w: 1.0}}}}",
        ],
        env=sim.env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert "Goal finished with status: SUCCEEDED" in done.stdout
    docs = (REPO / "docs" / "ros2.md").read_text()
    assert "ros2 action send_goal /navigate_to_pose nav2_msgs/action/NavigateToPose" in docs


def test_the_launch_file_of_the_docs_starts_a_namespaced_robot(env: dict[str, str]):
    """docs/ros2.md's `ros2 launch launch/sim.launch.py speed:=2 ns:=robot1`."""
    python = sys.executable  # the venv's, which imports navseq
    launch = subprocess.Popen(
        ["ros2", "launch", "launch/sim.launch.py", "speed:=2", "ns:=robot1", f"python:={python}"],
        cwd=REPO,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        command = client_command("navigate", ("-1.6,-0.5,0",), {"ns": "robot1", "timeout": 90})
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=150)
    finally:
        launch.send_signal(signal.SIGINT)
        try:
            output, _ = launch.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            launch.kill()
            output, _ = launch.communicate()
    assert done.returncode == 0, f"{done.stderr}\n{output}"
    assert json.loads(done.stdout.strip().splitlines()[-1])["status"] == "SUCCEEDED"
    assert launch.returncode == 0, output
    assert "Traceback" not in output
