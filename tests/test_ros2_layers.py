"""The costmap layers, footprint topics, costmap lifecycle nodes and collision monitor of
``navseq sim --ros2``, read by a real rclpy client (``tests/ros2_layer_clients.py``) as
RViz, a behaviour tree or nav2_simple_commander would: their content, not only their
names (tests/test_ros2_interfaces.py holds the names and types)."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from navseq.sim.costmap import LETHAL, NO_INFORMATION
from navseq.sim.footprint import TURTLEBOT3_BURGER
from navseq.sim.occupancy import load_map
from ros2_support import ros2_environment, ros2_prefix
from test_ros2_sim import MAP, SPEED, START, SimProcess

pytestmark = pytest.mark.ros2
CLIENTS = Path(__file__).with_name("ros2_layer_clients.py")
# Facing the arena's pillar at (-1.1, 0), 0.9 m ahead.
FACING_PILLAR = "-2,0,0"


def client(sim: SimProcess, verb: str, *options: str) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, str(CLIENTS), verb, *options],
        env=sim.env,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def _sim(start: str, *more: str) -> Iterator[SimProcess]:
    prefix = ros2_prefix()
    assert prefix is not None
    node = SimProcess(
        ros2_environment(prefix), "--map", str(MAP), f"--start={start}", "--speed", SPEED, *more
    )
    yield node
    err = node.stop()
    assert node.process.returncode == 0, err
    assert "Traceback" not in err


@pytest.fixture
def sim() -> Iterator[SimProcess]:
    yield from _sim(START)


@pytest.fixture
def sim_facing_pillar() -> Iterator[SimProcess]:
    yield from _sim(FACING_PILLAR)


# A Nav2 params file's collision_monitor section with a stop polygon (Nav2's docs' example
# shape): 0.4 m ahead of the robot, 0.6 m wide.
STOP_PARAMS = """
collision_monitor:
  ros__parameters:
    polygons: ["PolygonStop"]
    PolygonStop:
      type: "polygon"
      points: "[[0.4, 0.3], [0.4, -0.3], [0.0, -0.3], [0.0, 0.3]]"
      action_type: "stop"
      min_points: 4
      enabled: True
"""


@pytest.fixture
def sim_with_stop_polygon(tmp_path: Path) -> Iterator[SimProcess]:
    params = tmp_path / "nav2_params.yaml"
    params.write_text(STOP_PARAMS)
    yield from _sim(FACING_PILLAR, "--ros-args", "--params-file", str(params))


def test_layers_hold_the_map_and_the_lasers_marks_and_a_published_footprint_counts(
    sim: SimProcess,
) -> None:
    seen = client(sim, "layers")
    grid = load_map(MAP)
    for static in (seen["static_topic"], seen["static_service"]):
        assert static["size"] == [grid.width, grid.height]
        assert static["frame"] == "map"
        cells = np.array(static["data"], dtype=np.uint8).reshape(grid.height, grid.width)
        assert np.array_equal(cells == LETHAL, grid.data == 100)
        assert np.array_equal(cells == NO_INFORMATION, grid.data == -1)
    obstacle = np.array(seen["obstacle_service"]["data"], dtype=np.uint8).reshape(
        grid.height, grid.width
    )
    marks = np.argwhere(obstacle == LETHAL)
    assert len(marks) > 20  # the laser sees the arena's walls and pillars
    xy = np.array([grid.cell_to_world(int(r), int(c)) for r, c in marks])
    assert np.hypot(xy[:, 0] + 2.0, xy[:, 1] + 0.5).max() < 2.6  # within obstacle_max_range
    voxels = seen["voxel_grid"]
    assert voxels["size"] == [60, 60, 16] and voxels["frame"] == "odom"
    assert voxels["columns"] == [0, 1 << 3]  # the laser's height, 0.18 m, in 5 cm voxels
    assert seen["clearing_endpoints"]["points"] > 20
    assert seen["clearing_endpoints"]["frame"] == "odom"
    before = np.array(seen["footprint_before"])
    outline = TURTLEBOT3_BURGER.polygon  # the robot stands at odom's origin, yaw 0
    assert np.allclose(before, outline, atol=1e-3)
    after = np.array(seen["footprint_after"])
    assert np.allclose(np.ptp(after, axis=0), [0.4, 0.4], atol=1e-3)


def test_the_costmap_nodes_follow_their_servers_through_the_lifecycle_manager(
    sim: SimProcess,
) -> None:
    seen = client(sim, "lifecycle")
    assert seen["started"] == {"global_costmap": "active", "local_costmap": "active"}
    assert seen["pause_success"] and seen["resume_success"]
    assert seen["pause"] == {"global_costmap": "inactive", "local_costmap": "inactive"}
    assert seen["resume"] == {"global_costmap": "active", "local_costmap": "active"}
    assert seen["events"] == ["deactivating", "inactive", "activating", "active"]


def test_the_collision_monitor_slows_a_command_at_an_obstacle_and_toggle_off_passes_it(
    sim_facing_pillar: SimProcess,
) -> None:
    seen = client(sim_facing_pillar, "monitor", "--seconds", "6")
    assert seen["states_on"][0] == [3, "FootprintApproach"]  # APPROACH
    assert seen["speeds_on"] and max(seen["speeds_on"]) == pytest.approx(0.2)
    assert min(seen["speeds_on"]) < 0.05  # it held the robot back before the pillar
    assert seen["toggle"] == [True, "Collision monitor toggled off successfully"]
    # Off, the command passes unchanged (the body itself stops at the pillar); a zero
    # now and then is the teleop's command timing out between two of the client's.
    off = seen["speeds_off"]
    assert off and sum(s == pytest.approx(0.2) for s in off) > 0.8 * len(off)
    assert seen["marker_points"] > 0


def test_a_stop_polygon_from_a_params_file_stops_the_robot_before_the_obstacle(
    sim_with_stop_polygon: SimProcess,
) -> None:
    seen = client(sim_with_stop_polygon, "monitor", "--seconds", "6")
    assert seen["states_on"][0] == [1, "PolygonStop"]  # STOP
    speeds = seen["speeds_on"]
    assert speeds[0] == pytest.approx(0.2) and speeds[-1] == 0.0
    assert all(s in (pytest.approx(0.2), 0.0) for s in speeds)  # no slowing: a stop
