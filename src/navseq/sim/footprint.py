"""The robot's footprint and an exact, fast test of whether it overlaps an obstacle.

A footprint is a polygon in the robot frame (x forward, y left), as costmap_2d's
``footprint`` parameter. ``footprint_collides`` asks whether any grid cell that the
polygon overlaps (even partly) is occupied or unknown, or lies off the map. Overlap is
decided exactly with the separating-axis theorem between the polygon and each cell
square, so a footprint that only grazes the corner of an occupied cell collides, and
one that merely touches a cell's edge does not.

The test uses the convex hull of the polygon; for a non-convex footprint that is
conservative (it may report a collision in a notch of the polygon).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from navseq.geometry import Pose2D
from navseq.sim.occupancy import OccupancyGrid


@dataclass(frozen=True, eq=False)
class Footprint:
    """A robot outline in metres, robot frame; radii are derived from it.

    ``inscribed_radius``: the largest circle about the robot centre inside the polygon
    (costmap_2d's notion: the distance to the nearest edge). ``circumscribed_radius``:
    the distance to the farthest vertex.
    """

    polygon: np.ndarray
    inscribed_radius: float = field(init=False)
    circumscribed_radius: float = field(init=False)
    _hull: np.ndarray = field(init=False, repr=False, compare=False)
    _normals: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        polygon = np.asarray(self.polygon, dtype=float).reshape(-1, 2)
        if len(polygon) < 3:
            raise ValueError("a footprint needs at least 3 points")
        polygon.setflags(write=False)
        hull = _convex_hull(polygon)
        edges = np.roll(hull, -1, axis=0) - hull
        normals = np.column_stack((edges[:, 1], -edges[:, 0]))
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        object.__setattr__(self, "polygon", polygon)
        object.__setattr__(self, "_hull", hull)
        object.__setattr__(self, "_normals", normals)
        object.__setattr__(self, "inscribed_radius", _distance_to_boundary(polygon))
        object.__setattr__(
            self, "circumscribed_radius", float(np.linalg.norm(polygon, axis=1).max())
        )

    @classmethod
    def circle(cls, radius: float, sides: int = 16) -> Footprint:
        """A regular polygon approximating a round robot of ``radius`` (circumscribed)."""
        angles = np.linspace(0.0, 2.0 * math.pi, sides, endpoint=False)
        return cls(np.column_stack((radius * np.cos(angles), radius * np.sin(angles))))

    def at(self, pose: Pose2D) -> np.ndarray:
        """The polygon placed at a pose, in world coordinates, shape (N, 2)."""
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)
        rotation = np.array([[c, s], [-s, c]])
        return self.polygon @ rotation + (pose.x, pose.y)


def footprint_collides(grid: OccupancyGrid, footprint: Footprint, pose: Pose2D) -> bool:
    """True if the footprint at ``pose`` overlaps an occupied or unknown cell or leaves the map."""
    cells = footprint_cells(grid, footprint, pose)
    if cells is None:
        return True
    rows, cols = cells
    values = grid.data[rows, cols]
    return bool(np.any((values >= 100) | (values < 0)))


def footprint_cells(
    grid: OccupancyGrid, footprint: Footprint, pose: Pose2D
) -> tuple[np.ndarray, np.ndarray] | None:
    """(rows, cols) of every cell the footprint overlaps, or None if one is off the map."""
    # Work in grid units (cells), where cell (r, c) is the square [c, c+1] x [r, r+1].
    gx, gy = grid.world_to_grid(pose.x, pose.y)
    yaw = pose.yaw - grid.origin.yaw
    c, s = math.cos(yaw), math.sin(yaw)
    rotation = np.array([[c, s], [-s, c]])
    hull = footprint._hull @ rotation / grid.resolution + (gx, gy)
    normals = footprint._normals @ rotation

    low = np.floor(hull.min(axis=0)).astype(int)
    high = np.ceil(hull.max(axis=0)).astype(int)  # exclusive
    col_range = np.arange(low[0], high[0])
    row_range = np.arange(low[1], high[1])
    centre_x, centre_y = np.meshgrid(col_range + 0.5, row_range + 0.5)
    centre_x, centre_y = centre_x.ravel(), centre_y.ravel()

    # Separating axes: the grid axes are handled by the bounding box above; along each
    # edge normal the cell's projection is its centre's +- half the square's extent.
    hull_projection = hull @ normals.T  # (vertices, edges)
    hull_min, hull_max = hull_projection.min(axis=0), hull_projection.max(axis=0)
    half_extent = 0.5 * (np.abs(normals[:, 0]) + np.abs(normals[:, 1]))
    centre_projection = np.outer(centre_x, normals[:, 0]) + np.outer(centre_y, normals[:, 1])
    keep = np.all(
        (centre_projection - half_extent < hull_max - 1e-9)
        & (centre_projection + half_extent > hull_min + 1e-9),
        axis=1,
    )
    cols = np.floor(centre_x[keep]).astype(np.intp)
    rows = np.floor(centre_y[keep]).astype(np.intp)
    if (
        rows.size == 0
        or rows.min() < 0
        or cols.min() < 0
        or rows.max() >= grid.height
        or cols.max() >= grid.width
    ):
        return None
    return rows, cols


def _convex_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull (Andrew's monotone chain); few points, plain Python."""
    ordered = sorted({(float(x), float(y)) for x, y in points})
    if len(ordered) < 3:
        raise ValueError("a footprint needs at least 3 distinct points")

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    upper: list[tuple[float, float]] = []
    for point in ordered:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], point) <= 0:
            lower.pop()
        lower.append(point)
    for point in reversed(ordered):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], point) <= 0:
            upper.pop()
        upper.append(point)
    hull = np.array(lower[:-1] + upper[:-1])
    if len(hull) < 3:
        raise ValueError("a footprint must enclose an area")
    return hull


def _distance_to_boundary(polygon: np.ndarray) -> float:
    """Distance from the robot centre (0, 0) to the nearest polygon edge."""
    start = polygon
    end = np.roll(polygon, -1, axis=0)
    edge = end - start
    length_squared = np.maximum((edge**2).sum(axis=1), 1e-18)
    t = np.clip(-(start * edge).sum(axis=1) / length_squared, 0.0, 1.0)
    nearest = start + t[:, np.newaxis] * edge
    return float(np.linalg.norm(nearest, axis=1).min())


TURTLEBOT3_BURGER = Footprint(
    np.array([[-0.105, -0.105], [-0.105, 0.105], [0.041, 0.105], [0.041, -0.105]])
)
"""ROBOTIS' costmap footprint for the TurtleBot3 burger (about 0.15 x 0.21 m)."""
