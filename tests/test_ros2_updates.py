"""What the Nav2 stand-in republishes as Nav2's servers do (issue 20): the controller's
``received_global_plan``, the smoother's ``plan_smoothed``, and the costmaps' changes on
``*/costmap_updates`` (``map_msgs/OccupancyGridUpdate``) and ``*/costmap_raw_updates``
(``nav2_msgs/CostmapUpdate``), seen by a plain rclpy client (tests/nav2/updates_client.py)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from nav2_real_support import nav2_prefix
from navseq.sim.mapgen import save_map
from navseq.sim.occupancy import OCCUPIED, load_map
from ros2_support import SimNode, ros2_environment, ros2_prefix
from test_ros2_sim import MAP, SPEED, START
from test_ros2_world import run_script

pytestmark = pytest.mark.ros2

GOAL = (-1.5, -0.5)
BLOCK = ((-1.35, -0.2), (-1.25, -0.1))  # free in the map, 0.7 m from the start pose


def map_with_a_block(tmp_path: Path) -> tuple[Path, int]:
    """The test map with a small occupied block, and how many cells it turned occupied."""
    grid = load_map(MAP)
    data = grid.data.copy()
    (x0, y0), (x1, y1) = BLOCK
    row0, col0 = grid.world_to_cell(x0, y0)
    row1, col1 = grid.world_to_cell(x1, y1)
    block = data[row0 : row1 + 1, col0 : col1 + 1]
    assert (block < OCCUPIED).all(), "the block must be free in the test map"
    block[...] = OCCUPIED
    changed = dataclasses.replace(grid, data=data)
    return save_map(changed, tmp_path / "changed.yaml"), int(block.size)


def _prefix(which: str) -> Path:
    """The minimal ROS 2 the tests run on (no map_msgs: only the raw updates), or Nav2's
    build (map_msgs too: both kinds of updates)."""
    prefix = ros2_prefix() if which == "minimal" else nav2_prefix()
    if prefix is None and which == "nav2":
        pytest.skip("no real Nav2 tree (scripts/install-nav2.sh unpacks ../shared/ros2's)")
    assert prefix is not None
    return prefix


@pytest.mark.parametrize("which", ["minimal", "nav2"])
def test_the_stand_in_republishes_plans_and_costmap_updates(tmp_path: Path, which: str):
    env = ros2_environment(_prefix(which))
    changed_map, block_cells = map_with_a_block(tmp_path)
    sim = SimNode(env, "--map", str(MAP), f"--start={START}", "--speed", SPEED)
    try:
        seen = run_script(
            env, "updates_client.py", json.dumps({"map": str(changed_map), "goal": GOAL})
        )
    finally:
        err = sim.stop()
    assert "Traceback" not in err
    assert "costmap_raw_updates" in seen["update_topics"]
    if which == "nav2":
        assert "costmap_updates" in seen["update_topics"]
    # Nothing changed while the robot stood: no updates, only the full costmaps.
    assert seen["updates_before_change"] == 0
    assert seen["load_map"] == 0  # RESULT_SUCCESS
    for name, frame in (("global_costmap", "map"), ("local_costmap", "odom")):
        update = seen[name]
        assert update is not None, f"no {name} updates after the map changed"
        assert update["frame"] == frame
        assert update["same_size_as_before"]
        _x, _y, width, height = update["bounds"]
        assert update["raw_bounds"] == update["bounds"]
        assert update["data_sizes"] == [width * height, width * height]
        # The changed bounds: the block and its inflation, not the whole costmap.
        full_width, full_height = update["full_size"]
        assert 0 < width < full_width and 0 < height < full_height, update["bounds"]
        assert update["lethal_cells"] >= block_cells
        assert update["raw_matches_full_costmap"]
    # smooth_path's result, also on plan_smoothed.
    assert seen["smoothed_result"]
    assert seen["plan_smoothed"] == [seen["smoothed_result"]]
    # The controller's copy of the plan it takes: the planner's plan to the goal.
    received = seen["received_global_plan"]
    assert received and received == seen["plan"]
    assert seen["received_frame"] == "map"
    assert np.hypot(received[-1][0] - GOAL[0], received[-1][1] - GOAL[1]) < 0.1
