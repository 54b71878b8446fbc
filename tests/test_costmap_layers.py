"""What the stand-in's costmap layers hold (:mod:`navseq.sim.costmap_layers`), without
ROS: the static layer is the map cell for cell, the obstacle layer the laser's marks."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from navseq.geometry import Pose2D
from navseq.sim.costmap import FREE, LETHAL, NO_INFORMATION
from navseq.sim.costmap_layers import obstacle_layer, scan_hits, static_layer, voxel_columns
from navseq.sim.occupancy import load_map
from navseq.sim.scan import TURTLEBOT3_LDS, ray_cast

MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"


def test_the_static_layer_is_the_map_cell_for_cell() -> None:
    grid = load_map(MAP)
    layer = static_layer(grid)
    assert layer.shape == grid.data.shape
    assert np.array_equal(layer == LETHAL, grid.data == 100)
    assert np.array_equal(layer == NO_INFORMATION, grid.data == -1)
    assert np.array_equal(layer == FREE, grid.data == 0)


def test_the_obstacle_layer_marks_what_the_laser_hits_within_its_range() -> None:
    grid = load_map(MAP)
    pose = Pose2D(-2.0, -0.5, 0.0)
    ranges = ray_cast(grid, pose, TURTLEBOT3_LDS)
    hits = scan_hits(ranges, TURTLEBOT3_LDS, pose)
    assert len(hits) > 100
    assert np.all(np.hypot(hits[:, 0] - pose.x, hits[:, 1] - pose.y) <= 2.5 + 0.05)
    layer = obstacle_layer(grid, hits)
    marked = np.argwhere(layer == LETHAL)
    assert len(marked) > 20
    assert set(np.unique(layer)) == {FREE, LETHAL}
    # Every mark is on a wall of the map or next to one (the beam stops at its face).
    walls = grid.data == 100
    near_wall = walls.copy()
    for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        near_wall |= np.roll(walls, (dr, dc), axis=(0, 1))
    assert all(near_wall[row, col] for row, col in marked)


def test_a_voxel_column_holds_the_lasers_height() -> None:
    layer = np.array([[FREE, LETHAL]], dtype=np.uint8)
    columns = voxel_columns(layer, 0.182)
    assert columns.tolist() == [[0, 1 << math.floor(0.182 / 0.05)]]
