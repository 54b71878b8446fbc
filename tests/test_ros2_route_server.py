"""The route server on the ROS 2 simulator node (``--route-graph``): ``compute_route`` and
``compute_and_track_route`` through real rclpy clients (``tests/ros2_route_clients.py``),
on the example graph of the TurtleBot3 arena (``examples/turtlebot3_route_graph.geojson``:
two-way roads along y = -0.55 and y = 0.55 and across them, a one-way loop south
2 -> 9 -> 10 -> 3 and one north 7 -> 12 -> 11 -> 6). Robot at (-2, -0.5) facing +x,
next to node 1 (-1.65, -0.55); node 10 is (0.55, -1.55)."""

from __future__ import annotations

import itertools
import json
import math
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ros2_support import ros2_environment, ros2_prefix
from test_ros2_sim import MAP, REPO, SPEED, START, SimProcess

pytestmark = pytest.mark.ros2

GRAPH = REPO / "examples" / "turtlebot3_route_graph.geojson"
CLIENTS = Path(__file__).with_name("ros2_route_clients.py")


def run_client(sim: SimProcess, verb: str, *poses: str, **options: str) -> dict:
    """Options first, then ``--``: poses like ``-1.0,-0.5`` are not options."""
    flags = [part for key, value in options.items() for part in (f"--{key}", value)]
    done = subprocess.run(
        [sys.executable, str(CLIENTS), *flags, verb, "--", *poses],
        env=sim.env,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def start_sim(*extra: str) -> SimProcess:
    prefix = ros2_prefix()
    assert prefix is not None
    return SimProcess(
        ros2_environment(prefix), "--map", str(MAP), f"--start={START}", "--speed", SPEED, *extra
    )


@pytest.fixture
def sim() -> Iterator[SimProcess]:
    node = start_sim("--route-graph", str(GRAPH))
    yield node
    err = node.stop()
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


def test_compute_route_takes_the_one_way_loop_only_in_its_direction(sim: SimProcess) -> None:
    there = run_client(sim, "route", "1", "10")
    assert (there["status"], there["error_code"]) == ("SUCCEEDED", 0)
    assert there["nodes"] == [1, 2, 9, 10]  # the south loop runs 2 -> 9 -> 10 -> 3
    assert there["route_cost"] == pytest.approx(1.1 + 1.0 + 1.1, abs=1e-3)
    back = run_client(sim, "route", "10", "1")
    assert back["nodes"] == [10, 3, 2, 1]
    # A dense path along the edges, in the map frame, ending on node 10.
    path = there["path"]
    assert there["frame"] == "map"
    assert len(path) > 60
    assert path[0] == pytest.approx([-1.65, -0.55], abs=1e-6)
    assert path[-1] == pytest.approx([0.55, -1.55], abs=1e-6)
    steps = [math.dist(a, b) for a, b in itertools.pairwise(path)]
    assert max(steps) <= 0.05 + 1e-6


def test_poses_are_taken_to_their_nearest_nodes_and_unknown_ids_fail(sim: SimProcess) -> None:
    from_robot = run_client(sim, "route", "robot", "0.5,-1.5")
    assert from_robot["nodes"] == [1, 2, 9, 10]
    unknown = run_client(sim, "route", "1", "99")
    assert (unknown["status"], unknown["error_code"]) == ("ABORTED", 400)  # UNKNOWN


def test_tracking_a_route_while_follow_path_drives_it_ends_at_the_goal(sim: SimProcess) -> None:
    seen = run_client(sim, "track", "robot", "0.55,-1.55")
    assert (seen["status"], seen["error_code"]) == ("SUCCEEDED", 0)
    assert seen["follow_path"] == "SUCCEEDED"
    first = seen["feedback"][0]
    assert first["rerouted"] and first["nodes"] == [1, 2, 9, 10]
    passed = [f["last"] for f in seen["feedback"] if not f["rerouted"]]
    assert passed == [1, 2, 9, 10]  # every node, in the route's order
    assert math.dist(seen["pose"], [0.55, -1.55]) < 0.15


def test_a_reroute_plans_again_a_new_goal_preempts_and_a_cancel_cancels(sim: SimProcess) -> None:
    seen = run_client(sim, "interrupt", "1", "10")
    assert seen["reroute_answer"] is True
    first, second = seen["rerouted"]
    assert first[0] is True and first.count(True) == 2  # the start; planned again
    assert (seen["first"], seen["second"]) == ("ABORTED", "CANCELED")
    assert second[0] is True


def test_the_graph_is_drawn_and_a_bad_graph_file_leaves_none(sim: SimProcess, tmp_path) -> None:
    bad = tmp_path / "bad.geojson"
    bad.write_text('{"type": "FeatureCollection", "features": []}')
    seen = run_client(sim, "graph", file=str(bad))
    assert seen["nodes_drawn"] == 12
    assert seen["success"] is False
    nothing = run_client(sim, "route", "1", "10")
    # Nav2 Jazzy clears the graph before loading: goals then end with a default result.
    assert (nothing["status"], nothing["error_code"]) == ("ABORTED", 0)
    again = run_client(sim, "graph", file=str(GRAPH))
    assert again["success"] is True and again["nodes_drawn_after"] == 12


def test_without_a_graph_goals_abort_as_nav2s_do() -> None:
    node = start_sim()
    try:
        seen = run_client(node, "route", "1", "10")
    finally:
        err = node.stop()
    assert (seen["status"], seen["error_code"]) == ("ABORTED", 0)
    assert "No graph set! Aborting request." in err


def test_ros2_action_send_goal_computes_a_route(sim: SimProcess) -> None:
    done = subprocess.run(
        [
            "ros2",
            "action",
            "send_goal",
            "/compute_route",
            "nav2_msgs/action/ComputeRoute",
            "{start_id: 1, goal_id: 10}",
        ],
        env=sim.env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert "Goal finished with status: SUCCEEDED" in done.stdout, done.stdout
    node_ids = [int(n) for n in re.findall(r"nodeid: (\d+)", done.stdout)]
    assert node_ids == [1, 2, 9, 10]
