"""What each of nav2_bringup's costmap layers holds, from the stand-in's world, no ROS.

nav2_bringup's global costmap stacks ``static_layer``, ``obstacle_layer`` and
``inflation_layer``; its local one ``voxel_layer`` and ``inflation_layer``. Nav2
publishes each layer that keeps cells of its own (not the inflation layer) under the
layer's name. The stand-in's costmaps are made otherwise (the map and the other robots,
inflated: :mod:`navseq.sim.costmap`), so the layers are shown as such a layer would hold
them:

- the static layer: the map, cell for cell — ``LETHAL`` (254) where occupied,
  ``NO_INFORMATION`` (255) where unknown (nav2_bringup tracks unknown space), ``FREE``
  (0) elsewhere; not inflated (inflation is a layer of its own);
- the obstacle layer and the voxel layer: ``LETHAL`` at the cells of the laser's hits
  within ``obstacle_max_range`` (2.5 m, nav2_bringup's) — the walls it sees and the other
  robots — ``FREE`` elsewhere. Simplification: Nav2 keeps marks until a ray clears
  them; the stand-in's layers hold the last scan's marks only;
- the voxel grid: the voxel layer's columns, a bit per ``z_resolution`` (0.05 m, 16
  voxels from 0 m): a hit sets the bit of the laser's height.

The hits are placed from the pose the robot believes it has (as Nav2 places them
through the localisation's transforms), though measured from the true one.
"""

from __future__ import annotations

import math

import numpy as np

from navseq.geometry import Pose2D, compose
from navseq.sim.costmap import FREE, LETHAL, NO_INFORMATION
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.scan import LaserSpec

OBSTACLE_MAX_RANGE = 2.5  # m: nav2_bringup's obstacle_max_range (both layers)
Z_RESOLUTION = 0.05  # m: nav2_bringup's voxel_layer z_resolution
Z_VOXELS = 16  # nav2_bringup's voxel_layer z_voxels


def static_layer(grid: OccupancyGrid) -> np.ndarray:
    """The static layer's costs: the map, cell for cell."""
    cost = np.full(grid.data.shape, FREE, dtype=np.uint8)
    cost[grid.unknown_mask()] = NO_INFORMATION
    cost[grid.occupied_mask()] = LETHAL
    return cost


def scan_hits(
    ranges: np.ndarray, spec: LaserSpec, pose: Pose2D, max_range: float = OBSTACLE_MAX_RANGE
) -> np.ndarray:
    """The world points (N, 2) of the beams that hit something within ``max_range``,
    for a robot at ``pose``."""
    sensor = compose(pose, Pose2D(spec.mount_x, 0.0, 0.0))
    ranges = np.asarray(ranges, dtype=float)
    hit = np.isfinite(ranges) & (ranges <= max_range)
    angles = sensor.yaw + spec.angles[hit]
    return np.column_stack(
        (sensor.x + ranges[hit] * np.cos(angles), sensor.y + ranges[hit] * np.sin(angles))
    )


def obstacle_layer(grid: OccupancyGrid, hits: np.ndarray) -> np.ndarray:
    """The obstacle layer's costs on ``grid``'s cells: lethal where a hit falls."""
    cost = np.full(grid.data.shape, FREE, dtype=np.uint8)
    if len(hits):
        rows, cols = grid.world_to_cells(hits[:, 0], hits[:, 1])
        inside = (rows >= 0) & (rows < grid.height) & (cols >= 0) & (cols < grid.width)
        cost[rows[inside], cols[inside]] = LETHAL
    return cost


def voxel_columns(layer: np.ndarray, height: float) -> np.ndarray:
    """The voxel grid's columns (uint32, one per cell of ``layer``): the bit of
    ``height`` set where the layer is lethal."""
    bit = min(max(math.floor(height / Z_RESOLUTION), 0), Z_VOXELS - 1)
    columns = np.zeros(layer.shape, dtype=np.uint32)
    columns[layer == LETHAL] = np.uint32(1 << bit)
    return columns


__all__ = [
    "OBSTACLE_MAX_RANGE",
    "Z_RESOLUTION",
    "Z_VOXELS",
    "obstacle_layer",
    "scan_hits",
    "static_layer",
    "voxel_columns",
]
