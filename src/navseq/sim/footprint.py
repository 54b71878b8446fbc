"""The robot's footprint and exact, fast tests of whether it overlaps an obstacle or a robot.

A footprint is a polygon in the robot frame (x forward, y left), as costmap_2d's
``footprint`` parameter. ``footprint_collides`` asks whether any grid cell that the
polygon overlaps (even partly) is occupied or unknown, or lies off the map. Overlap is
decided exactly with the separating-axis theorem between the polygon and each cell
square, so a footprint that only grazes the corner of an occupied cell collides, and
one that merely touches a cell's edge does not. ``footprints_overlap`` applies the same
theorem, with the same convention for touching, to two placed footprints (robots).

The tests use the convex hull of the polygon; for a non-convex footprint that is
conservative (it may report a collision in a notch of the polygon).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from navseq.geometry import Pose2D
from navseq.sim.occupancy import OccupancyGrid, blocked_values


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
    _hull_points: tuple[tuple[float, float], ...] = field(init=False, repr=False, compare=False)
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
        object.__setattr__(self, "_hull_points", tuple(map(tuple, hull.tolist())))
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

    def _hull_at(self, pose: Pose2D) -> tuple[np.ndarray, np.ndarray]:
        """(vertices, edge normals) of the convex hull placed at a pose, world frame."""
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)
        rotation = np.array([[c, s], [-s, c]])
        return self._hull @ rotation + (pose.x, pose.y), self._normals @ rotation


def footprint_collides(grid: OccupancyGrid, footprint: Footprint, pose: Pose2D) -> bool:
    """True if the footprint at ``pose`` overlaps an occupied or unknown cell or leaves the map.

    Cheap where it matters (every simulation step): only the blocked cells inside the
    footprint's bounding box get the exact overlap test, and there are usually none.
    """
    placed = _PlacedHull.of(grid, footprint, pose)
    if placed.leaves(grid):
        return True
    col0, row0, col1, row1 = placed.box()
    # No cache of blocked cells: grid.data may be edited in place (tests, clearing).
    window = blocked_values(grid.data[row0:row1, col0:col1])
    if not window.any():
        return False
    rows, cols = np.nonzero(window)
    return bool(placed.overlaps(rows + row0, cols + col0).any())


def footprints_overlap(
    a: Footprint, pose_a: Pose2D, b: Footprint, pose_b: Pose2D, margin: float = 0.0
) -> bool:
    """True if footprint ``a`` at ``pose_a`` and ``b`` at ``pose_b`` overlap (two robots).

    Exact for the convex hulls (separating axes: the edge normals of both); touching is
    no overlap. With ``margin``, hulls less than ``margin`` apart along every axis also
    count: that is ``b`` grown by at least ``margin`` all round (a little more at its
    corners). Robots whose circumscribed circles are farther apart are rejected with a
    few float operations, which is the usual answer.
    """
    reach = a.circumscribed_radius + b.circumscribed_radius + margin
    dx, dy = pose_b.x - pose_a.x, pose_b.y - pose_a.y
    if dx * dx + dy * dy >= reach * reach:
        return False
    vertices_a, normals_a = a._hull_at(pose_a)
    vertices_b, normals_b = b._hull_at(pose_b)
    axes = np.vstack((normals_a, normals_b))
    min_b, max_b = _extent(vertices_b, axes)
    return not _separated(*_extent(vertices_a, axes), min_b - margin, max_b + margin).any()


def clearance_map(grid: OccupancyGrid) -> np.ndarray:
    """Metres from each cell centre to the nearest obstacle, unknown cell or map edge.

    A footprint whose circumscribed circle, centred anywhere in a cell, stays more than
    ``clearance - 2 * resolution`` away cannot overlap any blocked cell: the cheap test
    that lets a caller skip the exact footprint test far from obstacles.
    """
    blocked = np.pad(grid.occupied_mask() | grid.unknown_mask(), 1, constant_values=True)
    distance = ndimage.distance_transform_edt(~blocked)[1:-1, 1:-1]
    return (distance * grid.resolution).astype(np.float32)


class CollisionChecker:
    """``footprint_collides`` for one grid and footprint, fast where nothing is near.

    The exact test costs far more than the rest of a simulation step; the clearance map
    answers with one array lookup for every pose that is far from all obstacles.
    """

    def __init__(self, grid: OccupancyGrid, footprint: Footprint) -> None:
        self.grid = grid
        self.footprint = footprint
        self.clearance = clearance_map(grid)
        self._safe_clearance = footprint.circumscribed_radius + 2.0 * grid.resolution

    def collides(self, pose: Pose2D) -> bool:
        row, col = self.grid.world_to_cell(pose.x, pose.y)
        clearance = self.clearance
        inside = 0 <= row < clearance.shape[0] and 0 <= col < clearance.shape[1]
        if inside and clearance[row, col] > self._safe_clearance:
            return False
        return footprint_collides(self.grid, self.footprint, pose)


def footprint_cells(
    grid: OccupancyGrid, footprint: Footprint, pose: Pose2D
) -> tuple[np.ndarray, np.ndarray] | None:
    """(rows, cols) of every cell the footprint overlaps, or None if it leaves the map."""
    placed = _PlacedHull.of(grid, footprint, pose)
    if placed.leaves(grid):
        return None
    col0, row0, col1, row1 = placed.box()
    rows, cols = np.mgrid[row0:row1, col0:col1]
    rows, cols = rows.ravel(), cols.ravel()
    keep = placed.overlaps(rows, cols)
    return rows[keep], cols[keep]


@dataclass(frozen=True)
class _PlacedHull:
    """The footprint's convex hull at a pose, in grid units.

    In grid units cell (row, col) is the unit square [col, col + 1] x [row, row + 1].
    Touching counts as no overlap (a tolerance of 1e-9 cells absorbs rounding). The
    few vertices are plain floats: numpy's per-call overhead would dominate.
    """

    xs: tuple[float, ...]  # vertex coordinates along the column axis
    ys: tuple[float, ...]  # ... and along the row axis
    rotation: np.ndarray  # robot frame -> grid frame, for row vectors
    footprint: Footprint

    @classmethod
    def of(cls, grid: OccupancyGrid, footprint: Footprint, pose: Pose2D) -> _PlacedHull:
        gx, gy = grid.world_to_grid(pose.x, pose.y)
        yaw = pose.yaw - grid.origin.yaw
        c, s = math.cos(yaw), math.sin(yaw)
        scale = 1.0 / grid.resolution
        points = footprint._hull_points
        xs = tuple(gx + (c * px - s * py) * scale for px, py in points)
        ys = tuple(gy + (s * px + c * py) * scale for px, py in points)
        return cls(xs, ys, np.array([[c, s], [-s, c]]), footprint)

    def leaves(self, grid: OccupancyGrid) -> bool:
        """True if part of the hull lies outside the map's rectangle."""
        return (
            min(self.xs) < -_EPSILON
            or min(self.ys) < -_EPSILON
            or max(self.xs) > grid.width + _EPSILON
            or max(self.ys) > grid.height + _EPSILON
        )

    def box(self) -> tuple[int, int, int, int]:
        """(col0, row0, col1, row1), end exclusive: the cells the bounding box overlaps."""
        return (
            max(math.floor(min(self.xs) + _EPSILON), 0),
            max(math.floor(min(self.ys) + _EPSILON), 0),
            math.ceil(max(self.xs) - _EPSILON),
            math.ceil(max(self.ys) - _EPSILON),
        )

    def overlaps(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Which of these cells (all inside ``box()``) the hull overlaps: separating axes.

        The grid axes are settled by the bounding box; along each edge normal a cell
        projects to its centre's projection +- half the square's extent.
        """
        normals = self.footprint._normals @ self.rotation
        hull_min, hull_max = _extent(np.column_stack((self.xs, self.ys)), normals)
        half_extent = 0.5 * (np.abs(normals[:, 0]) + np.abs(normals[:, 1]))
        centres = np.column_stack((cols + 0.5, rows + 0.5))
        centre_projection = centres @ normals.T  # (cells, edges)
        separated = _separated(
            hull_min, hull_max, centre_projection - half_extent, centre_projection + half_extent
        )
        return np.asarray(~separated.any(axis=1))


_EPSILON = 1e-9


def _extent(vertices: np.ndarray, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) of the vertices' projections on each axis (the rows of ``axes``)."""
    projection = vertices @ axes.T  # (vertices, axes)
    return projection.min(axis=0), projection.max(axis=0)


def _separated(
    min_a: np.ndarray, max_a: np.ndarray, min_b: np.ndarray, max_b: np.ndarray
) -> np.ndarray:
    """Per axis, whether two projected intervals are apart; touching (within
    ``_EPSILON``) counts as apart. The arguments broadcast (several shapes at once)."""
    return (min_b >= max_a - _EPSILON) | (max_b <= min_a + _EPSILON)


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
