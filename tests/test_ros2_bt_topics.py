"""bt_navigator's topics on the ROS 2 simulator node: ``behavior_tree_log`` while
``navigate_to_pose`` goals run, and the ``controller_selector`` a client publishes
(``tests/ros2_route_clients.py btlog``). Robot at (-2, -0.5) facing +x."""

from __future__ import annotations

import subprocess

import pytest

from test_ros2_route_server import run_client, start_sim

pytestmark = pytest.mark.ros2


def _first(events: list[list], name: str, uid: int, current: str) -> int:
    return next(
        index
        for index, (node, node_uid, _previous, status) in enumerate(events)
        if (node, node_uid, status) == (name, uid, current)
    )


def test_the_log_shows_the_phases_of_a_navigate_to_pose_goal() -> None:
    sim = start_sim()
    try:
        seen = run_client(sim, "btlog", "-1.0,-0.5", "-1.5,-0.5")
    finally:
        err = sim.stop()
    assert "Traceback" not in err
    assert seen["results"] == [["SUCCEEDED", 0], ["SUCCEEDED", 0]]
    events = seen["events"]
    # The first goal, in order: the tree starts, plans, follows, succeeds, goes idle
    # (its end published with the second goal's first message, as Nav2's bt_navigator).
    phases = [
        _first(events, "NavigateRecovery", 1, "RUNNING"),
        _first(events, "ComputePathToPose", 7, "SUCCESS"),
        _first(events, "FollowPath", 12, "RUNNING"),
        _first(events, "FollowPath", 12, "SUCCESS"),
        _first(events, "NavigateRecovery", 1, "SUCCESS"),
    ]
    assert phases == sorted(phases)
    starts = [e for e in events if e[:2] == ["NavigateRecovery", 1] and e[3] == "RUNNING"]
    assert len(starts) == 2  # one tree run per goal


def test_an_unknown_controller_selection_fails_goals_as_nav2s_controller_server_does() -> None:
    sim = start_sim()
    try:
        seen = run_client(sim, "btlog", "-1.0,-0.5", controller="Nope")
    finally:
        err = sim.stop()
    assert seen["results"] == [["ABORTED", 101]]  # FollowPath INVALID_CONTROLLER
    assert "controller_selector: 'Nope' is not a plugin of controller_server" in err


def test_a_selection_published_with_the_ros2_cli_is_taken() -> None:
    sim = start_sim()
    try:
        done = subprocess.run(
            [
                "ros2",
                "topic",
                "pub",
                "--once",
                "--qos-durability",
                "transient_local",
                "/controller_selector",
                "std_msgs/msg/String",
                "{data: FollowPath}",
            ],
            env=sim.env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert done.returncode == 0, done.stderr
        seen = run_client(sim, "btlog", "-1.0,-0.5")
    finally:
        err = sim.stop()
    assert "controller_selector: FollowPath selected" in err
    assert seen["results"] == [["SUCCEEDED", 0]]
