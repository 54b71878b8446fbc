"""A simulated 2-D laser scanner: ranges ray-cast on the map and the other robots, no ROS.

The stand-in's ``scan`` (``sensor_msgs/LaserScan``) is what a TurtleBot3's LDS-01 would
see from the robot's *true* pose: every beam marched through the map in steps of half a
cell until it enters an occupied cell, and cut at the first edge of another robot's
footprint it crosses (exact segment intersection). Unknown cells and the map's edge
return nothing, as open space would. A beam that hits nothing within ``range_max`` is
``inf`` (REP 117); one that hits nearer than ``range_min`` too, as the scanner cannot
measure it. No noise: runs stay reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from navseq.geometry import Pose2D, compose
from navseq.sim.footprint import Footprint
from navseq.sim.occupancy import OccupancyGrid


@dataclass(frozen=True)
class LaserSpec:
    """A scanner's beams and where it sits on the robot (TurtleBot3's LDS-01 by default:
    360 beams, 0.12-3.5 m, 5 Hz, ``base_scan`` 0.032 m behind and 0.172 m above
    ``base_link``, as turtlebot3_description places it)."""

    beams: int = 360
    range_min: float = 0.12
    range_max: float = 3.5
    rate: float = 5.0  # scans per second
    mount_x: float = -0.032  # m: base_scan ahead of base_link (behind, here)
    height: float = 0.172  # m above base_link

    @property
    def angle_increment(self) -> float:
        return 2.0 * math.pi / self.beams

    @property
    def angles(self) -> np.ndarray:
        """Beam angles in the scanner frame, from 0 counter-clockwise."""
        return np.arange(self.beams) * self.angle_increment


TURTLEBOT3_LDS = LaserSpec()


def ray_cast(
    grid: OccupancyGrid,
    pose: Pose2D,
    spec: LaserSpec = TURTLEBOT3_LDS,
    others: Sequence[tuple[Pose2D, Footprint]] = (),
) -> np.ndarray:
    """The ranges (float32, one per beam) a scanner on a robot at ``pose`` measures."""
    sensor = compose(pose, Pose2D(spec.mount_x, 0.0, 0.0))
    angles = sensor.yaw + spec.angles
    directions = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    ranges = _map_ranges(grid, sensor, directions, spec.range_max)
    for at, footprint in others:
        ranges = np.minimum(ranges, _polygon_ranges(sensor, directions, footprint, at))
    out = ranges.astype(np.float32)
    out[(out > spec.range_max) | (out < spec.range_min)] = np.inf
    return out


def _map_ranges(
    grid: OccupancyGrid, sensor: Pose2D, directions: np.ndarray, range_max: float
) -> np.ndarray:
    """Distance along each beam to the first occupied cell (inf: none within range)."""
    step = grid.resolution / 2.0
    distances = np.arange(step, range_max + step, step)
    xs = sensor.x + directions[:, 0:1] * distances[None, :]
    ys = sensor.y + directions[:, 1:2] * distances[None, :]
    rows, cols = grid.world_to_cells(xs.ravel(), ys.ravel())
    rows, cols = rows.reshape(xs.shape), cols.reshape(xs.shape)
    inside = (rows >= 0) & (rows < grid.height) & (cols >= 0) & (cols < grid.width)
    occupied = grid.occupied_mask()
    hit = np.zeros(xs.shape, dtype=bool)
    hit[inside] = occupied[rows[inside], cols[inside]]
    first = np.argmax(hit, axis=1)
    return np.where(hit.any(axis=1), distances[first], np.inf)


def _polygon_ranges(
    sensor: Pose2D, directions: np.ndarray, footprint: Footprint, at: Pose2D
) -> np.ndarray:
    """Distance along each beam to the first edge of ``footprint`` placed at ``at``."""
    corners = np.array(
        [
            (p.x, p.y)
            for p in (compose(at, Pose2D(float(x), float(y), 0.0)) for x, y in footprint.polygon)
        ]
    )
    starts, ends = corners, np.roll(corners, -1, axis=0)
    edges = ends - starts  # (E, 2)
    to_start = starts - np.array([sensor.x, sensor.y])  # (E, 2)
    dx, dy = directions[:, 0:1], directions[:, 1:2]  # (B, 1)
    # Solve sensor + t * direction = start + u * edge for t >= 0, 0 <= u <= 1.
    denominator = dx * edges[None, :, 1] - dy * edges[None, :, 0]  # (B, E)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (
            to_start[None, :, 0] * edges[None, :, 1] - to_start[None, :, 1] * edges[None, :, 0]
        ) / (denominator)
        u = (to_start[None, :, 0] * dy - to_start[None, :, 1] * dx) / denominator
    valid = (np.abs(denominator) > 1e-12) & (t >= 0.0) & (u >= 0.0) & (u <= 1.0)
    return np.where(valid, t, np.inf).min(axis=1)


__all__ = ["TURTLEBOT3_LDS", "LaserSpec", "ray_cast"]
