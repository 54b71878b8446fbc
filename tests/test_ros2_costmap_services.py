"""The costmap and planner services a Nav2 client calls besides ``get_costmap`` and
``clear_entirely_*``, on the ROS 2 simulator node, through ``ros2 service call`` as a
user types it. Robot at (-2, -0.5); the arena's pillar at (-1.1, 0)."""

from __future__ import annotations

import re
import subprocess
from collections.abc import Iterator

import pytest

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
    err = node.stop()  # a test may have stopped it already to read its log
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


def call(sim: SimProcess, service: str, kind: str, request: str) -> str:
    done = subprocess.run(
        ["ros2", "service", "call", service, kind, request],
        env=sim.env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def pose(x: float, y: float) -> str:
    where = f"position: {{x: {x}, y: {y}}}, orientation: {{w: 1.0}}"
    return f"{{header: {{frame_id: map}}, pose: {{{where}}}}}"


def path(*poses: str) -> str:
    return f"{{path: {{header: {{frame_id: map}}, poses: [{', '.join(poses)}]}}}}"


def cost_of(reply: str) -> float:
    match = re.search(r"cost=([0-9.]+)", reply)
    assert match, reply
    return float(match.group(1))


def test_get_cost_reads_the_costmap_free_and_in_the_pillar(sim: SimProcess) -> None:
    service, kind = "/global_costmap/get_cost_global_costmap", "nav2_msgs/srv/GetCost"
    free = cost_of(call(sim, service, kind, "{x: -2.0, y: -0.5}"))
    assert free < 253  # inflated near the wall, but neither inscribed nor lethal
    assert cost_of(call(sim, service, kind, "{x: -1.1, y: 0.0}")) >= 254  # the pillar
    # The local costmap's frame is odom, which starts at the start pose: (0, 0) is the
    # robot, whose footprint touches nothing there.
    local = "/local_costmap/get_cost_local_costmap"
    assert cost_of(call(sim, local, kind, "{x: 0.0, y: 0.0, use_footprint: true}")) == free
    # (0.9, 0.5) in odom is the pillar's edge in map: the footprint there touches it.
    assert cost_of(call(sim, local, kind, "{x: 0.9, y: 0.5, use_footprint: true}")) == 254


def test_is_path_valid_names_the_poses_in_an_obstacle(sim: SimProcess) -> None:
    through_pillar = path(pose(-2.0, -0.5), pose(-1.1, 0.0), pose(-1.5, -0.5))
    seen = call(sim, "/is_path_valid", "nav2_msgs/srv/IsPathValid", through_pillar)
    assert "is_valid=False" in seen and "invalid_pose_indices=[1]" in seen, seen
    clear = path(pose(-2.0, -0.5), pose(-1.5, -0.5))
    assert "is_valid=True" in call(sim, "/is_path_valid", "nav2_msgs/srv/IsPathValid", clear)


def test_the_region_clears_answer_and_are_logged(sim: SimProcess) -> None:
    said_by_call: list[str] = []
    for service, kind, request, said in (
        (
            "/global_costmap/clear_around_global_costmap",
            "ClearCostmapAroundRobot",
            "{reset_distance: 1.0}",
            "global_costmap: cleared around the robot",
        ),
        (
            "/local_costmap/clear_except_local_costmap",
            "ClearCostmapExceptRegion",
            "{reset_distance: 1.0}",
            "local_costmap: cleared except a region",
        ),
        (
            "/global_costmap/clear_around_pose_global_costmap",
            "ClearCostmapAroundPose",
            f"{{pose: {pose(-1.0, -0.5)}, reset_distance: 1.0}}",
            "global_costmap: cleared around a pose",
        ),
    ):
        assert "response" in call(sim, service, f"nav2_msgs/srv/{kind}", request)
        said_by_call.append(said)
    log = sim.stop()
    for said in said_by_call:
        assert said in log
