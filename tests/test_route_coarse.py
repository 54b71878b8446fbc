"""Coarse routes on big maps: exact near each place, a graph of the free space between,
with the same reachability as the planner's and lengths close to its plans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from navseq.geometry import Pose2D
from navseq.route import coarse
from navseq.sim.costmap import Costmap
from navseq.sim.occupancy import OccupancyGrid
from navseq.sim.planner import compiled_search_available, reach_routes

pytestmark = pytest.mark.skipif(
    not compiled_search_available(), reason="the compiled search is not built"
)
ANCHOR_M = 0.33
BLOCK = 8  # wider than the doorway's free cells: the door is inside blocks, never a block


def doorway_costmap() -> Costmap:
    """Two halls joined by one door just wide enough for the robot, shelves in the west
    hall, and a sealed room in the south-east corner no path leads into."""
    from navseq.commands.common import costmap_for_robot

    data = np.zeros((160, 240), np.int8)
    data[:2, :] = data[-2:, :] = 100
    data[:, :2] = data[:, -2:] = 100
    data[:, 118:122] = 100  # the wall between the halls
    data[70:83, 118:122] = 0  # the door
    for row in range(20, 140, 30):  # shelves
        data[row : row + 6, 20:100] = 100
    data[110:, 170:] = 100  # the sealed room's walls
    data[116:154, 176:234] = 0
    grid = OccupancyGrid(data, 0.05, Pose2D(0.0, 0.0, 0.0), "doorway")
    return costmap_for_robot(grid)


def spots(costmap: Costmap, count: int, seed: int) -> list[tuple[float, float]]:
    cells = np.argwhere(costmap.free_mask())
    rng = np.random.default_rng(seed)
    chosen = cells[rng.choice(len(cells), size=count, replace=False)]
    return [costmap.cell_to_world(int(row), int(col)) for row, col in chosen]


def both_ways(costmap: Costmap, places: list[tuple[float, float]]) -> tuple[np.ndarray, ...]:
    """Every route from each place to those after it: the coarse way and one exact search
    per place, as (coarse, exact) rows of metres, departure and arrival headings."""
    routes = coarse.CoarseRoutes(costmap, places, ANCHOR_M, block=BLOCK)
    for index in range(len(places)):
        routes.prepare(index)
    rough = [routes.reach(i, np.arange(i + 1, len(places))) for i in range(len(places) - 1)]
    exact = [reach_routes(costmap, p, places[i + 1 :], ANCHOR_M) for i, p in enumerate(places)]
    return np.concatenate(rough), np.concatenate(exact[:-1])


def test_the_door_narrower_than_a_block_still_joins_the_halls() -> None:
    costmap = doorway_costmap()
    door = costmap.free_mask()[70:83, 118:122]
    assert door.any(axis=1).sum() > 0 and door.sum(axis=1).max() < BLOCK  # a narrow door
    west, east = (2.0, 3.8), (10.0, 3.8)
    rough, exact = both_ways(costmap, [west, east])
    assert math.isfinite(exact[0, 0])
    assert rough[0, 0] == pytest.approx(exact[0, 0], rel=0.03)


def test_coarse_lengths_agree_with_the_planner_s_and_unreachable_stays_unreachable() -> None:
    costmap = doorway_costmap()
    places = spots(costmap, 40, seed=3)
    sealed = [(9.9, 6.8), (11.0, 7.4)]  # inside the sealed room
    wall = [(6.0, 3.0)]  # in the wall between the halls
    rough, exact = both_ways(costmap, places + sealed + wall)
    reachable = np.isfinite(exact[:, 0])
    np.testing.assert_array_equal(np.isfinite(rough[:, 0]), reachable)
    assert reachable.sum() > 500 and (~reachable).sum() > 80
    error = np.abs(rough[reachable, 0] - exact[reachable, 0]) / exact[reachable, 0]
    # Where two ways cost the planner nearly the same, the graph may take the other one
    # (up to a fifth longer or shorter): rarely.
    assert np.median(error) < 0.01 and np.quantile(error, 0.95) < 0.05 and error.max() < 0.25
    # Where a route is, it leaves and arrives much as the planner's does.
    for column in (1, 2):
        both = reachable & np.isfinite(exact[:, column])
        turn = np.abs(np.angle(np.exp(1j * (rough[both, column] - exact[both, column]))))
        assert np.median(turn) < 0.2


def test_big_maps_take_the_coarse_way_and_small_ones_the_exact(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from navseq.route.travel import route_table

    costmap = doorway_costmap()
    places = [*spots(costmap, 12, seed=5), (9.9, 6.8)]
    assert not coarse.worth_it(costmap, len(places))
    exact = route_table(costmap, places, ANCHOR_M)
    monkeypatch.setattr(coarse, "EXACT_CELLS_AT_MOST", 0)
    fresh = Costmap.from_grid(costmap.grid, costmap.params)
    monkeypatch.setattr(coarse, "TARGET_BLOCKS", 200)  # big blocks: visibly coarse
    made = []
    real_graph = coarse.build_graph
    monkeypatch.setattr(
        coarse, "build_graph", lambda *args: made.append(args[2]) or real_graph(*args)
    )
    from navseq.route import distances, travel

    monkeypatch.setattr(distances, "_KEPT", type(distances._KEPT)())
    monkeypatch.setattr(travel, "_KEPT", type(travel._KEPT)())
    rough = route_table(fresh, places, ANCHOR_M)
    assert made and made[0] > 2  # the coarse graph was made, with blocks of several cells
    np.testing.assert_array_equal(np.isfinite(rough.metres), np.isfinite(exact.metres))
    finite = np.isfinite(exact.metres)
    np.testing.assert_allclose(rough.metres[finite], exact.metres[finite], rtol=0.1)
