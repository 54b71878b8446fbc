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


def test_coarse_lengths_on_generated_warehouses_stay_within_the_documented_bounds() -> None:
    """docs/performance.md's bounds, on two generated warehouses (shelves, aisles, where
    two ways round a shelf often cost the planner nearly the same): the coarse lengths
    against one exact search per place, with the graph sized as for a big map."""
    from navseq.commands.common import costmap_for_robot
    from navseq.sim.mapgen import warehouse_map

    errors, nearest = [], []
    for seed in (0, 3):
        costmap = costmap_for_robot(warehouse_map(seed))
        places = spots(costmap, 40, seed=seed)
        routes = coarse.CoarseRoutes(costmap, places, ANCHOR_M)
        for index in range(len(places)):
            routes.prepare(index)
        count = len(places)
        rough, exact = np.zeros((count, count)), np.zeros((count, count))
        for i in range(count - 1):
            rough[i, i + 1 :] = routes.reach(i, np.arange(i + 1, count))[:, 0]
            exact[i, i + 1 :] = reach_routes(costmap, places[i], places[i + 1 :], ANCHOR_M)[:, 0]
        rough, exact = rough + rough.T, exact + exact.T
        np.testing.assert_array_equal(np.isfinite(rough), np.isfinite(exact))
        pairs = ~np.eye(count, dtype=bool) & np.isfinite(exact)
        off = np.abs(rough - exact) / np.where(pairs, exact, 1.0)
        errors.append(off[pairs])
        # Each place's three nearest (the legs a short tour is made of).
        closest = np.argsort(np.where(pairs, exact, np.inf), axis=1)[:, :3]
        nearest.append(np.take_along_axis(off, closest, axis=1).ravel())
    every, near = np.concatenate(errors), np.concatenate(nearest)
    assert np.median(every) < 0.01
    assert np.quantile(every, 0.95) < 0.04
    assert every.max() < 0.4  # a near tie round a shelf: the graph takes the other way
    assert np.quantile(near, 0.95) < 0.03 and near.max() < 0.15


def test_the_coarse_distances_are_kept_per_map_and_robot_for_the_next_order(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The studio's second Order… on a big map searches nothing again, nor makes the
    graph again, even from another costmap of the same map and robot; one moved place
    is one search."""
    from navseq.route import distances, travel
    from navseq.route.travel import route_table

    monkeypatch.setattr(coarse, "EXACT_CELLS_AT_MOST", 0)  # the coarse way, as on a big map
    monkeypatch.setattr(distances, "_KEPT", type(distances._KEPT)())
    monkeypatch.setattr(travel, "_KEPT", type(travel._KEPT)())
    monkeypatch.setattr(coarse, "_GRAPHS", type(coarse._GRAPHS)())
    made = []
    real_graph = coarse.build_graph
    monkeypatch.setattr(
        coarse, "build_graph", lambda *args: made.append(args[2]) or real_graph(*args)
    )
    costmap = doorway_costmap()
    places = spots(costmap, 30, seed=8)
    first = route_table(costmap, places, ANCHOR_M)
    known = distances.known_distances(costmap)
    searched = known.searched
    assert len(made) == 1 and searched == len(places) - 1
    again = Costmap.from_grid(costmap.grid, costmap.params)
    second = route_table(again, places[::-1], ANCHOR_M)
    assert known.searched == searched and len(made) == 1
    np.testing.assert_array_equal(second.metres, first.metres[::-1, ::-1])
    moved = [*places[:-1], spots(costmap, 31, seed=9)[-1]]
    route_table(again, moved, ANCHOR_M)
    assert known.searched == searched + 1


def test_the_graph_made_ahead_is_the_one_the_first_ordering_uses(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The studio's warm-up makes the graph once the opened mission is checked
    (LegPlanner.prepare_ordering): the first Order… then does not wait for it. A map
    where the exact searches pay makes none."""
    from navseq.route import distances, travel
    from navseq.route.legs import LegPlanner

    monkeypatch.setattr(distances, "_KEPT", type(distances._KEPT)())
    monkeypatch.setattr(travel, "_KEPT", type(travel._KEPT)())
    monkeypatch.setattr(coarse, "_GRAPHS", type(coarse._GRAPHS)())
    made = []
    real_graph = coarse.build_graph
    monkeypatch.setattr(
        coarse, "build_graph", lambda *args: made.append(args[2]) or real_graph(*args)
    )
    planner = LegPlanner(doorway_costmap())
    planner.prepare_ordering(12)
    assert made == []  # 12 places on a small map: the exact searches
    monkeypatch.setattr(coarse, "EXACT_CELLS_AT_MOST", 0)
    planner.prepare_ordering(12)
    assert len(made) == 1
    planner.routes(spots(planner.costmap, 12, seed=2), ANCHOR_M)
    assert len(made) == 1  # the same graph
