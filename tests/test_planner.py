"""Global planner: optimal for its objective (against MCP_Geometric and a brute-force
Dijkstra), a valid path, and None (never a hang) when there is no plan."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from skimage.graph import MCP_Geometric

from navseq.geometry import Pose2D
from navseq.sim.costmap import INSCRIBED, LETHAL, NO_INFORMATION, Costmap
from navseq.sim.occupancy import OccupancyGrid, load_map
from navseq.sim.planner import (
    TRAVERSAL_COST_WEIGHT,
    compiled_search_available,
    plan_path,
    search_cells,
    traversal_costs,
)

REPO_MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"

BACKENDS = [
    pytest.param(False, id="python"),
    pytest.param(
        True,
        id="compiled",
        marks=pytest.mark.skipif(
            not compiled_search_available(), reason="navseq.sim._astar was not built"
        ),
    ),
]


@pytest.fixture(scope="module")
def turtlebot3_costmap() -> Costmap:
    return Costmap.from_grid(load_map(REPO_MAP))


@pytest.fixture(scope="module")
def random_costmap() -> Costmap:
    """300 x 300 cells of random blocks and speckle, inflated."""
    rng = np.random.default_rng(7)
    data = np.zeros((300, 300), np.int8)
    for _ in range(40):
        row, col = rng.integers(0, 300, 2)
        height, width = rng.integers(3, 30, 2)
        data[row : row + height, col : col + width] = 100
    data[rng.random(data.shape) < 0.002] = 100
    return Costmap.from_grid(OccupancyGrid(data, 0.05, Pose2D(-7.5, -7.5, 0.0)))


def traversal(cost: np.ndarray) -> np.ndarray:
    return traversal_costs()[cost]


def mcp_optimum(cost: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> float:
    """scikit-image's optimum for the same objective (length x mean of cell costs), cells."""
    mcp = MCP_Geometric(traversal(cost), fully_connected=True)
    cumulative, _ = mcp.find_costs([start], [goal])
    return float(cumulative[goal])


def dijkstra_optimum(cost: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> float:
    """Brute force: every 8-neighbour edge of the grid written out, scipy's Dijkstra."""
    weights = traversal(cost)
    height, width = cost.shape
    sources, targets, lengths = [], [], []
    for row in range(height):
        for col in range(width):
            for d_row, d_col in ((0, 1), (1, 0), (1, 1), (1, -1)):
                r, c = row + d_row, col + d_col
                if not (0 <= r < height and 0 <= c < width):
                    continue
                if np.isinf(weights[row, col]) or np.isinf(weights[r, c]):
                    continue
                step = math.hypot(d_row, d_col)
                sources.append(row * width + col)
                targets.append(r * width + c)
                lengths.append(step * 0.5 * (weights[row, col] + weights[r, c]))
    graph = coo_matrix((lengths, (sources, targets)), shape=(cost.size, cost.size)).tocsr()
    distances = dijkstra(graph, directed=False, indices=start[0] * width + start[1])
    return float(distances[goal[0] * width + goal[1]])


def assert_valid_path(cost: np.ndarray, cells: np.ndarray, start, goal, total: float) -> None:
    """Consecutive 8-neighbours through passable cells, and the cost it claims."""
    assert tuple(cells[0]) == tuple(start)
    assert tuple(cells[-1]) == tuple(goal)
    steps = np.diff(cells, axis=0)
    assert np.abs(steps).max(initial=0) <= 1
    assert (np.abs(steps).sum(axis=1) > 0).all()
    weights = traversal(cost)[cells[:, 0], cells[:, 1]]
    assert np.isfinite(weights).all()
    recomputed = np.sum(np.linalg.norm(steps, axis=1) * 0.5 * (weights[:-1] + weights[1:]))
    assert recomputed == pytest.approx(total, rel=1e-9, abs=1e-9)


small_cost_grids = arrays(
    np.uint8,
    st.tuples(st.integers(1, 9), st.integers(1, 9)),
    elements=st.sampled_from([0, 0, 0, 0, 30, 120, 252, INSCRIBED, LETHAL, NO_INFORMATION]),
)


@pytest.mark.parametrize("use_compiled", BACKENDS)
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cost=small_cost_grids, data=st.data())
def test_optimal_against_brute_force_dijkstra(use_compiled: bool, cost: np.ndarray, data) -> None:
    height, width = cost.shape
    start = (data.draw(st.integers(0, height - 1)), data.draw(st.integers(0, width - 1)))
    goal = (data.draw(st.integers(0, height - 1)), data.draw(st.integers(0, width - 1)))
    found = search_cells(cost, start, goal, use_compiled=use_compiled)
    optimum = dijkstra_optimum(cost, start, goal) if cost[start] < INSCRIBED else math.inf
    if math.isinf(optimum) or cost[goal] >= INSCRIBED:
        assert found is None
        return
    assert found is not None
    cells, total = found
    assert total == pytest.approx(optimum, rel=1e-9, abs=1e-12)
    assert_valid_path(cost, cells, start, goal, total)


@pytest.mark.parametrize("use_compiled", BACKENDS)
def test_within_one_percent_of_mcp_geometric(
    use_compiled: bool, random_costmap: Costmap, turtlebot3_costmap: Costmap
) -> None:
    rng = np.random.default_rng(3)
    checked = 0
    for costmap in (random_costmap, turtlebot3_costmap):
        free_cells = np.argwhere(costmap.cost < INSCRIBED)
        for _ in range(6):
            start, goal = (tuple(free_cells[i]) for i in rng.choice(len(free_cells), 2))
            optimum = mcp_optimum(costmap.cost, start, goal)
            found = search_cells(costmap.cost, start, goal, use_compiled=use_compiled)
            if math.isinf(optimum):
                assert found is None
                continue
            assert found is not None
            cells, total = found
            assert total <= 1.01 * optimum
            assert total >= optimum * (1 - 1e-9)  # nothing beats the optimum
            assert_valid_path(costmap.cost, cells, start, goal, total)
            checked += 1
    assert checked >= 8


@pytest.mark.parametrize("use_compiled", BACKENDS)
def test_plan_in_world_coordinates(use_compiled: bool, turtlebot3_costmap: Costmap) -> None:
    start, goal = (-2.0, -0.5), (2.0, 0.5)
    plan = plan_path(turtlebot3_costmap, start, goal, use_compiled=use_compiled)
    assert plan is not None
    grid = turtlebot3_costmap.grid
    # First and last points are the centres of the start and goal cells.
    assert plan.points[0] == pytest.approx(grid.cell_to_world(*grid.world_to_cell(*start)))
    assert plan.points[-1] == pytest.approx(grid.cell_to_world(*grid.world_to_cell(*goal)))
    steps = np.linalg.norm(np.diff(plan.points, axis=0), axis=1)
    assert steps.max() <= grid.resolution * math.sqrt(2) + 1e-9
    assert plan.length == pytest.approx(steps.sum())
    # Longer than the straight line (pillars are in the way), not absurdly so.
    assert math.dist(start, goal) < plan.length < 1.5 * math.dist(start, goal)
    # Every point is free, and the cost weights length by traversal cost.
    assert all(turtlebot3_costmap.is_free(x, y) for x, y in plan.points)
    assert plan.length <= plan.cost <= (1 + TRAVERSAL_COST_WEIGHT) * plan.length


def test_plans_keep_away_from_walls_when_there_is_room() -> None:
    # A 4 m wide corridor; start and goal 0.5 m off the bottom wall. The cheapest path
    # leaves the wall's inflation (1 m) rather than hug it.
    data = np.zeros((80, 120), np.int8)
    data[0, :] = data[-1, :] = 100
    costmap = Costmap.from_grid(OccupancyGrid(data, 0.05))
    plan = plan_path(costmap, (0.5, 0.5), (5.5, 0.5))
    assert plan is not None
    assert plan.points[:, 1].max() > 1.0
    assert plan.points[:, 1].max() < 1.2  # ... and goes no farther than it pays to


def test_start_equals_goal_is_a_one_point_plan(turtlebot3_costmap: Costmap) -> None:
    plan = plan_path(turtlebot3_costmap, (0.5, 0.5), (0.51, 0.51))
    assert plan is not None
    assert len(plan.points) == 1
    assert plan.length == 0 and plan.cost == 0


@pytest.mark.parametrize(
    ("start", "goal"),
    [
        ((0.0, 0.0), (0.5, 0.5)),  # start inside a pillar
        ((0.5, 0.5), (0.2, 0.0)),  # goal on a pillar wall
        ((0.5, 0.5), (0.27, 0.0)),  # goal in the inscribed band
        ((0.5, 0.5), (50.0, 0.0)),  # goal off the map
        ((-50.0, 0.0), (0.5, 0.5)),  # start off the map
        ((0.5, 0.5), (-8.0, 8.0)),  # goal in unknown space outside the arena
    ],
)
def test_no_plan_when_start_or_goal_is_not_free(turtlebot3_costmap, start, goal) -> None:
    assert plan_path(turtlebot3_costmap, start, goal) is None


@pytest.mark.parametrize("use_compiled", BACKENDS)
def test_no_plan_into_an_enclosed_pocket(use_compiled: bool) -> None:
    data = np.zeros((100, 100), np.int8)
    data[40:61, 40] = data[40:61, 60] = data[40, 40:61] = data[60, 40:61] = 100
    costmap = Costmap.from_grid(OccupancyGrid(data, 0.05))
    inside, outside = (2.5, 2.5), (0.5, 0.5)
    assert costmap.is_free(*inside) and costmap.is_free(*outside)
    assert plan_path(costmap, outside, inside, use_compiled=use_compiled) is None
    assert plan_path(costmap, inside, outside, use_compiled=use_compiled) is None
    assert plan_path(costmap, inside, (2.4, 2.6), use_compiled=use_compiled) is not None


def test_forcing_a_missing_compiled_backend_is_an_error(monkeypatch) -> None:
    import navseq.sim.planner as planner

    monkeypatch.setattr(planner, "_compiled_astar", None)
    with pytest.raises(RuntimeError):
        search_cells(np.zeros((2, 2), np.uint8), (0, 0), (1, 1), use_compiled=True)
    assert not planner.compiled_search_available()
