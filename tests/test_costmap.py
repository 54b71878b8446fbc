"""Costmap: lethal obstacles, inscribed band and costmap_2d's exponential inflation."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from navseq.geometry import Pose2D
from navseq.sim.costmap import (
    FREE,
    INSCRIBED,
    LETHAL,
    NO_INFORMATION,
    Costmap,
    CostmapParams,
)
from navseq.sim.occupancy import OccupancyGrid, load_map

REPO_MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"
RESOLUTION = 0.05


def single_obstacle_grid(size: int = 61) -> OccupancyGrid:
    data = np.zeros((size, size), np.int8)
    data[size // 2, size // 2] = 100
    return OccupancyGrid(data, RESOLUTION, Pose2D(0.0, 0.0, 0.0))


def expected_cost(distance: float, params: CostmapParams) -> int:
    """costmap_2d InflationLayer::computeCost, written out for one distance."""
    if distance == 0:
        return LETHAL
    if distance <= params.inscribed_radius:
        return INSCRIBED
    if distance > params.inflation_radius:
        return FREE
    factor = math.exp(-params.cost_scaling_factor * (distance - params.inscribed_radius))
    return int((INSCRIBED - 1) * factor)


def test_costs_around_one_obstacle_follow_costmap_2d() -> None:
    grid = single_obstacle_grid()
    params = CostmapParams(inflation_radius=1.0, cost_scaling_factor=3.0, inscribed_radius=0.105)
    costmap = Costmap.from_grid(grid, params)
    centre = grid.height // 2
    for row in range(grid.height):
        for col in range(grid.width):
            distance = math.hypot(row - centre, col - centre) * RESOLUTION
            assert costmap.cost[row, col] == expected_cost(distance, params), (row, col)


def test_defaults_are_turtlebot3_burger() -> None:
    params = CostmapParams()
    assert (params.inflation_radius, params.cost_scaling_factor) == (1.0, 3.0)
    assert params.inscribed_radius == pytest.approx(0.105)
    assert params.unknown_is_lethal


def test_bands_lethal_inscribed_decay_free() -> None:
    grid = single_obstacle_grid()
    costmap = Costmap.from_grid(grid)
    x0, y0 = grid.cell_to_world(30, 30)
    assert costmap.cost_at(x0, y0) == LETHAL
    assert costmap.cost_at(x0 + 0.10, y0) == INSCRIBED  # 2 cells: 0.10 m <= 0.105 m
    assert costmap.cost_at(x0 + 0.15, y0) == int(252 * math.exp(-3.0 * 0.045))
    # Farther is cheaper, all the way to the inflation radius.
    costs = [costmap.cost_at(x0 + k * RESOLUTION, y0) for k in range(3, 21)]
    assert all(a >= b for a, b in itertools.pairwise(costs))
    assert costs[-1] > FREE  # exactly 1.0 m away: still inflated
    assert costmap.cost_at(x0 + 1.05, y0) == FREE
    assert not costmap.is_free(x0 + 0.10, y0)
    # Traversable only where the burger's corners (0.148 m out) clear the obstacle's
    # square: 0.15 m from its centre is 0.125 m from its edge, 0.20 m is 0.175 m.
    assert not costmap.is_free(x0 + 0.15, y0)
    assert costmap.is_free(x0 + 0.20, y0)


def test_unknown_is_lethal_by_default() -> None:
    data = np.zeros((40, 40), np.int8)
    data[:, :10] = -1
    grid = OccupancyGrid(data, RESOLUTION)
    lethal_unknown = Costmap.from_grid(grid)
    assert (lethal_unknown.cost[:, :10] == NO_INFORMATION).all()
    assert (lethal_unknown.cost[:, 10:12] == INSCRIBED).all()  # inflated like a wall
    assert lethal_unknown.cost[:, 12].min() > FREE

    unknown_is_free = Costmap.from_grid(grid, CostmapParams(unknown_is_lethal=False))
    assert (unknown_is_free.cost == FREE).all()
    assert unknown_is_free.is_free(*grid.cell_to_world(5, 5))


def test_outside_the_map_is_no_information() -> None:
    costmap = Costmap.from_grid(single_obstacle_grid())
    assert costmap.cost_at(-0.01, 0.5) == NO_INFORMATION
    assert costmap.cost_at(0.5, 100.0) == NO_INFORMATION
    assert not costmap.is_free(-0.01, 0.5)


def test_empty_map_is_all_free_and_cost_is_read_only() -> None:
    costmap = Costmap.from_grid(OccupancyGrid(np.zeros((5, 7), np.int8), RESOLUTION))
    assert costmap.cost.dtype == np.uint8
    assert costmap.cost.shape == (5, 7)
    assert (costmap.cost == FREE).all()
    with pytest.raises(ValueError):
        costmap.cost[0, 0] = 1


def test_cell_conversions_delegate_to_the_grid() -> None:
    grid = OccupancyGrid(np.zeros((5, 7), np.int8), 0.1, Pose2D(1.0, 2.0, 0.3))
    costmap = Costmap.from_grid(grid)
    assert costmap.world_to_cell(1.5, 2.6) == grid.world_to_cell(1.5, 2.6)
    assert costmap.cell_to_world(2, 3) == grid.cell_to_world(2, 3)


def test_turtlebot3_world_costmap() -> None:
    costmap = Costmap.from_grid(load_map(REPO_MAP))
    # Between pillars there is room; on a pillar's wall there is not.
    assert costmap.is_free(0.55, 0.55)
    assert costmap.cost_at(0.2, 0.0) == LETHAL
    assert costmap.cost_at(0.0, 0.0) == NO_INFORMATION
    assert not costmap.is_free(0.27, 0.0)  # within 0.105 m of the pillar wall


@pytest.mark.parametrize(
    "settings",
    [{"inflation_radius": -1.0}, {"cost_scaling_factor": float("nan")}, {"inscribed_radius": "x"}],
)
def test_bad_params_are_refused(settings: dict) -> None:
    with pytest.raises(ValueError, match=next(iter(settings))):
        CostmapParams(**settings)


def test_costs_become_occupancy_values_as_nav2s_costmap_publisher_makes_them() -> None:
    from navseq.sim.costmap import occupancy_values

    costs = np.array([0, 1, 128, 252, 253, 254, 255], dtype=np.uint8)
    assert occupancy_values(costs).tolist() == [0, 1, 50, 98, 99, 100, -1]
