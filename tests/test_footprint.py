"""Footprint geometry and the exact footprint-versus-grid collision test."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as PolygonPath

from navseq.geometry import Pose2D
from navseq.sim.footprint import (
    TURTLEBOT3_BURGER,
    Footprint,
    footprint_cells,
    footprint_collides,
)
from navseq.sim.occupancy import OccupancyGrid


def free_grid(size: int = 40, resolution: float = 0.05, origin: Pose2D | None = None):
    return OccupancyGrid(np.zeros((size, size), np.int8), resolution, origin or Pose2D(0, 0, 0))


def with_cell(grid: OccupancyGrid, row: int, col: int, value: int) -> OccupancyGrid:
    data = grid.data.copy()
    data[row, col] = value
    return OccupancyGrid(data, grid.resolution, grid.origin)


def test_turtlebot3_burger_dimensions() -> None:
    fp = TURTLEBOT3_BURGER
    assert fp.polygon.shape == (4, 2)
    extent = fp.polygon.max(axis=0) - fp.polygon.min(axis=0)
    assert extent == pytest.approx((0.146, 0.21))
    assert fp.inscribed_radius == pytest.approx(0.041)  # the front edge is closest
    assert fp.circumscribed_radius == pytest.approx(math.hypot(0.105, 0.105))


def test_square_footprint_radii_and_placement() -> None:
    square = Footprint(np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * 0.1)
    assert square.inscribed_radius == pytest.approx(0.1)
    assert square.circumscribed_radius == pytest.approx(0.1 * math.sqrt(2))
    placed = square.at(Pose2D(2.0, 3.0, math.pi / 4))
    assert np.linalg.norm(placed - (2.0, 3.0), axis=1) == pytest.approx([0.1 * math.sqrt(2)] * 4)
    assert placed[:, 0].max() == pytest.approx(2.0 + 0.1 * math.sqrt(2))


def test_degenerate_footprints_are_rejected() -> None:
    with pytest.raises(ValueError):
        Footprint(np.array([[0.0, 0.0], [1.0, 0.0]]))
    with pytest.raises(ValueError):
        Footprint(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]))


def test_free_floor_does_not_collide() -> None:
    grid = free_grid()
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(1.0, 1.0, 0.3))


@pytest.mark.parametrize("value", [100, -1])
def test_occupied_or_unknown_cell_under_the_robot_collides(value: int) -> None:
    grid = with_cell(free_grid(), 20, 20, value)
    x, y = grid.cell_to_world(20, 20)
    assert footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(x, y, 0.0))
    # Move the robot so the obstacle is well clear of its 0.15 m radius.
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(x + 0.3, y, 0.0))


def test_leaving_the_map_collides() -> None:
    grid = free_grid()  # 2 m x 2 m
    assert footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(0.05, 1.0, 0.0))
    assert footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(1.0, 1.96, math.pi / 2))
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(0.2, 1.0, 0.0))


def test_heading_matters_for_a_long_robot() -> None:
    # A 0.4 m x 0.1 m robot; an obstacle 0.15 m ahead is hit only when facing it.
    long_robot = Footprint(np.array([[-0.2, -0.05], [0.2, -0.05], [0.2, 0.05], [-0.2, 0.05]]))
    grid = free_grid()
    x, y = grid.cell_to_world(20, 23)  # 3 cells (0.15 m) to the +x side of cell (20, 20)
    robot_x, robot_y = grid.cell_to_world(20, 20)
    grid = with_cell(grid, 20, 23, 100)
    assert footprint_collides(grid, long_robot, Pose2D(robot_x, robot_y, 0.0))
    assert not footprint_collides(grid, long_robot, Pose2D(robot_x, robot_y, math.pi / 2))
    assert (x, y) != (robot_x, robot_y)


def test_grazing_a_cell_corner_collides_and_touching_an_edge_does_not() -> None:
    square = Footprint(np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * 0.1)
    grid = with_cell(free_grid(resolution=0.1), 10, 12, 100)  # cell spans x 1.2..1.3, y 1.0..1.1
    # Right edge exactly on x = 1.2: touches the cell's edge only.
    assert not footprint_collides(grid, square, Pose2D(1.1, 1.05, 0.0))
    assert footprint_collides(grid, square, Pose2D(1.1 + 1e-4, 1.05, 0.0))
    # Rotated 45 degrees, the square's corner pokes 1 mm into the cell at (1.201, 1.05).
    reach = 0.1 * math.sqrt(2)
    assert footprint_collides(grid, square, Pose2D(1.2 - reach + 1e-3, 1.05, math.pi / 4))
    assert not footprint_collides(grid, square, Pose2D(1.2 - reach - 1e-3, 1.05, math.pi / 4))


def test_rotated_map_origin_is_honoured() -> None:
    grid = free_grid(origin=Pose2D(5.0, -1.0, math.pi / 2))
    grid = with_cell(grid, 20, 20, 100)
    x, y = grid.cell_to_world(20, 20)
    assert footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(x, y, 0.0))
    assert not footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(x - 0.5, y, 0.0))
    # Off the map: the rotated grid covers world x in [3, 5], not [5, 7].
    assert footprint_collides(grid, TURTLEBOT3_BURGER, Pose2D(6.0, 0.0, 0.0))


def reference_cells(grid: OccupancyGrid, polygon_world: np.ndarray, spacing: float) -> set:
    """Cells containing any of a dense sample of the polygon's inside (a subset of the truth)."""
    low, high = polygon_world.min(axis=0), polygon_world.max(axis=0)
    xs = np.arange(low[0], high[0], spacing)
    ys = np.arange(low[1], high[1], spacing)
    points = np.array(np.meshgrid(xs, ys)).reshape(2, -1).T
    inside = points[PolygonPath(polygon_world).contains_points(points)]
    c, s = math.cos(grid.origin.yaw), math.sin(grid.origin.yaw)
    dx, dy = inside[:, 0] - grid.origin.x, inside[:, 1] - grid.origin.y
    cols = np.floor((c * dx + s * dy) / grid.resolution).astype(int)
    rows = np.floor((-s * dx + c * dy) / grid.resolution).astype(int)
    return set(zip(rows.tolist(), cols.tolist(), strict=True))


def grown(polygon: np.ndarray, margin: float) -> np.ndarray:
    """A convex polygon with every edge pushed out by at least ``margin``."""
    centroid = polygon.mean(axis=0)
    offsets = polygon - centroid
    distances = np.linalg.norm(offsets, axis=1, keepdims=True)
    return centroid + offsets * (1 + 2 * margin / distances)


@settings(max_examples=100, deadline=None)
@given(
    x=st.floats(0.5, 1.5),
    y=st.floats(0.5, 1.5),
    yaw=st.floats(-math.pi, math.pi),
    grid_origin=st.sampled_from([Pose2D(0.0, 0.0, 0.0), Pose2D(1.0, -0.2, 0.4)]),
)
def test_cells_match_a_dense_sampling_reference(
    x: float, y: float, yaw: float, grid_origin: Pose2D
) -> None:
    grid = free_grid(origin=grid_origin)
    # (x, y) are in the map's own frame; place the robot there in the world.
    c, s = math.cos(grid_origin.yaw), math.sin(grid_origin.yaw)
    pose = Pose2D(grid_origin.x + c * x - s * y, grid_origin.y + s * x + c * y, yaw)
    cells = footprint_cells(grid, TURTLEBOT3_BURGER, pose)
    assert cells is not None
    found = set(zip(cells[0].tolist(), cells[1].tolist(), strict=True))
    polygon = TURTLEBOT3_BURGER.at(pose)
    assert reference_cells(grid, polygon, spacing=0.002) <= found
    # Every reported cell really overlaps the polygon: a dense sample of the polygon
    # grown by 1 mm hits it (sampling alone could miss slivers thinner than that).
    assert found <= reference_cells(grid, grown(polygon, 0.001), spacing=0.0004)


@settings(max_examples=200, deadline=None)
@given(
    x=st.floats(-0.1, 1.1),
    y=st.floats(-0.1, 1.1),
    yaw=st.floats(-math.pi, math.pi),
    seed=st.integers(0, 2**32 - 1),
)
def test_collides_exactly_when_an_overlapped_cell_is_blocked(
    x: float, y: float, yaw: float, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    data = rng.choice(np.array([0, 0, 0, 0, 0, 0, 0, 0, 50, 100, -1], np.int8), size=(20, 20))
    grid = OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0))
    pose = Pose2D(x, y, yaw)
    cells = footprint_cells(grid, TURTLEBOT3_BURGER, pose)
    if cells is None:
        expected = True  # part of the robot is off the map
    else:
        values = data[cells]
        expected = bool(((values == 100) | (values == -1)).any())
    assert footprint_collides(grid, TURTLEBOT3_BURGER, pose) == expected
