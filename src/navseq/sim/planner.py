"""Global planner: the cheapest 8-connected path on the costmap, found with A*.

The objective is the one scikit-image's ``MCP_Geometric`` minimises, so the two can be
checked against each other:

- a cell's *traversal cost* is ``1 + TRAVERSAL_COST_WEIGHT * cost / 252`` for costs
  below ``INSCRIBED`` and infinite (impassable) otherwise; with the default weight of
  3.0 a cell next to the inscribed band is 4x as expensive to cross as open floor,
  which keeps plans off walls without long detours;
- a step to one of the 8 neighbours costs its length (1 or sqrt 2 cells) times the
  mean of the two cells' traversal costs, in metres (step lengths times resolution),
  so a plan through open floor costs exactly its length. Diagonal steps between two
  blocked cells are allowed, as in ``MCP_Geometric``: the cells are blocked for the
  robot's centre, not solid, and the controller checks the real footprint.

A* uses the octile distance times the smallest traversal cost as its heuristic. It
never overestimates and is consistent, so the first time the goal leaves the queue its
cost is optimal. The search runs in a small C extension (``navseq.sim._astar``) when
it was compiled, otherwise in the pure-Python twin below (same algorithm, ~50x slower).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np

from navseq.sim.costmap import INSCRIBED, Costmap

try:  # the optional compiled search; the fallback below gives the same plans
    from navseq.sim import _astar as _compiled_astar  # type: ignore[attr-defined]
except ImportError:  # pragma: no cover - depends on the build
    _compiled_astar = None

TRAVERSAL_COST_WEIGHT = 3.0
SQRT2 = math.sqrt(2.0)


@dataclass(frozen=True, eq=False)
class Plan:
    """A planned path from the start cell to the goal cell."""

    points: np.ndarray  # (N, 2) world x, y of cell centres, start cell first, goal cell last
    length: float  # metres along ``points``
    cost: float  # the planner's objective (metres weighted by traversal cost)


def traversal_costs(weight: float = TRAVERSAL_COST_WEIGHT) -> np.ndarray:
    """Traversal cost of each of the 256 cost bytes (``inf`` = impassable)."""
    table = np.full(256, np.inf)
    passable = np.arange(INSCRIBED)
    table[:INSCRIBED] = 1.0 + weight * passable / 252.0
    return table


_TRAVERSAL_LUT = traversal_costs()


def compiled_search_available() -> bool:
    """True when the C search was built (otherwise the pure-Python one is used)."""
    return _compiled_astar is not None


def plan_path(
    costmap: Costmap,
    start: tuple[float, float],
    goal: tuple[float, float],
    *,
    use_compiled: bool | None = None,
) -> Plan | None:
    """The cheapest path between two world points, or None if there is none.

    Start and goal snap to the cells containing them; either one off the map or not
    traversable means no plan. Only traversable cells are searched: those where the
    robot, centred there, clears every obstacle by its circumscribed radius
    (:meth:`Costmap.free_mask`), so no plan leads through a gap the robot cannot turn in.
    ``use_compiled`` forces a backend (``None``: the C one if available).
    """
    grid = costmap.grid
    start_cell = grid.world_to_cell(*start)
    goal_cell = grid.world_to_cell(*goal)
    cost = costmap.planning_cost
    for row, col in (start_cell, goal_cell):
        if not grid.in_bounds(row, col) or cost[row, col] >= INSCRIBED:
            return None

    cells = search_cells(cost, start_cell, goal_cell, use_compiled=use_compiled)
    if cells is None:
        return None
    path_cells, cost_in_cells = cells
    points = grid.cells_to_world(path_cells[:, 0], path_cells[:, 1])
    length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
    return Plan(points=points, length=length, cost=cost_in_cells * grid.resolution)


def search_cells(
    cost: np.ndarray,
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    lut: np.ndarray = _TRAVERSAL_LUT,
    use_compiled: bool | None = None,
) -> tuple[np.ndarray, float] | None:
    """A* on a uint8 cost array: ((N, 2) row/col path, objective in cells) or None.

    ``lut`` maps each cost byte to a traversal cost (``inf`` = impassable).
    """
    if use_compiled and _compiled_astar is None:
        raise RuntimeError("the compiled A* (navseq.sim._astar) is not built")
    compiled = _compiled_astar is not None if use_compiled is None else use_compiled
    width = cost.shape[1]
    cost = np.ascontiguousarray(cost, dtype=np.uint8)
    lut = np.ascontiguousarray(lut, dtype=np.float64)
    if not (np.isfinite(lut[cost[start]]) and np.isfinite(lut[cost[goal]])):
        return None
    finite = lut[np.isfinite(lut)]
    heuristic_scale = float(finite.min()) if finite.size else 1.0
    start_index = start[0] * width + start[1]
    goal_index = goal[0] * width + goal[1]
    search = _compiled_astar.search if compiled else _search_python
    found = search(cost, width, lut, start_index, goal_index, heuristic_scale)
    if found is None:
        return None
    total, indices = found
    flat = np.asarray(indices, dtype=np.intp)
    return np.column_stack(np.divmod(flat, width)), float(total)


def reach_lengths(
    costmap: Costmap,
    start: tuple[float, float],
    goals: list[tuple[float, float]],
    *,
    use_compiled: bool | None = None,
) -> np.ndarray:
    """Metres from ``start`` to each of ``goals`` along the plans :func:`plan_path` would
    make (``inf`` where it would make none), from one search that stops once it reached
    them all: for the distances between many places, one search per place instead of
    one per pair. Places snap to their cells as in :func:`plan_path`."""
    grid = costmap.grid
    cost = np.ascontiguousarray(costmap.planning_cost, dtype=np.uint8)
    lut = np.ascontiguousarray(_TRAVERSAL_LUT, dtype=np.float64)
    width = cost.shape[1]
    lengths = np.full(len(goals), np.inf)
    row, col = grid.world_to_cell(*start)
    if not grid.in_bounds(row, col) or cost[row, col] >= INSCRIBED:
        return lengths
    targets = np.full(len(goals), -1, dtype=np.int64)
    for index, goal in enumerate(goals):
        goal_row, goal_col = grid.world_to_cell(*goal)
        if grid.in_bounds(goal_row, goal_col) and cost[goal_row, goal_col] < INSCRIBED:
            targets[index] = goal_row * width + goal_col
    known = targets >= 0
    if use_compiled and _compiled_astar is None:
        raise RuntimeError("the compiled A* (navseq.sim._astar) is not built")
    compiled = _compiled_astar is not None if use_compiled is None else use_compiled
    reach = _compiled_reach if compiled else _reach_python
    cells = reach(cost, width, lut, row * width + col, targets[known])
    lengths[known] = cells * grid.resolution
    return lengths


def reach_routes(
    costmap: Costmap,
    start: tuple[float, float],
    goals: list[tuple[float, float]],
    anchor_m: float,
    *,
    use_compiled: bool | None = None,
) -> np.ndarray:
    """:func:`reach_lengths` with the headings: per goal a row of metres, the heading
    (rad) the route leaves ``start`` with and the heading it arrives with (``inf`` and
    NaN, NaN where there is no route). Each heading is the direction from one end to the
    route's cell ``anchor_m`` along it (about the controller's lookahead: what a robot
    turns to before it drives off, and drives in as it arrives); NaN for a goal in
    ``start``'s own cell."""
    grid = costmap.grid
    cost = np.ascontiguousarray(costmap.planning_cost, dtype=np.uint8)
    lut = np.ascontiguousarray(_TRAVERSAL_LUT, dtype=np.float64)
    width = cost.shape[1]
    rows = np.full((len(goals), 3), np.nan)
    rows[:, 0] = np.inf
    row, col = grid.world_to_cell(*start)
    if not grid.in_bounds(row, col) or cost[row, col] >= INSCRIBED:
        return rows
    targets = np.full(len(goals), -1, dtype=np.int64)
    for index, goal in enumerate(goals):
        goal_row, goal_col = grid.world_to_cell(*goal)
        if grid.in_bounds(goal_row, goal_col) and cost[goal_row, goal_col] < INSCRIBED:
            targets[index] = goal_row * width + goal_col
    known = np.flatnonzero(targets >= 0)
    if use_compiled and _compiled_astar is None:
        raise RuntimeError("the compiled A* (navseq.sim._astar) is not built")
    compiled = _compiled_astar is not None if use_compiled is None else use_compiled
    origin = row * width + col
    anchor_cells = anchor_m / grid.resolution
    if compiled:
        raw = _compiled_astar.routes(
            cost, width, lut, origin, targets[known].tobytes(), anchor_cells
        )
        found = np.frombuffer(raw, dtype=np.float64).reshape(-1, 3)
    else:
        found = _routes_python(cost, width, lut, origin, targets[known], anchor_cells)
    reached = np.isfinite(found[:, 0])
    rows[known, 0] = found[:, 0] * grid.resolution
    here = grid.cells_to_world(np.array([row]), np.array([col]))[0]
    ends = grid.cells_to_world(*np.divmod(targets[known], width))
    for column, (tails, heads) in enumerate(
        ((np.broadcast_to(here, ends.shape), found[:, 1]), (found[:, 2], ends)), start=1
    ):
        tail_xy = _anchor_xy(grid, tails, width)
        head_xy = _anchor_xy(grid, heads, width)
        delta = head_xy - tail_xy
        moved = reached & (np.hypot(delta[:, 0], delta[:, 1]) > 0)
        rows[known[moved], column] = np.arctan2(delta[moved, 1], delta[moved, 0])
    return rows


def _anchor_xy(grid: object, cells: np.ndarray, width: int) -> np.ndarray:
    """World x, y of flat cell indices given as floats (or points already, shape (N, 2))."""
    array = np.asarray(cells)
    if array.ndim == 2:
        return array
    flat = np.where(array >= 0, array, 0).astype(np.int64)
    return grid.cells_to_world(*np.divmod(flat, width))  # type: ignore[attr-defined]


def _routes_python(
    cost: np.ndarray, width: int, lut: np.ndarray, start: int, targets: np.ndarray, anchor: float
) -> np.ndarray:
    """The readable twin of ``_astar.c``'s ``routes``: per target its length in cells,
    departure anchor and arrival anchor cells (-1 when there is no route)."""
    traversal = lut[cost.ravel()].tolist()
    height = cost.size // width
    wanted = {int(target) for target in targets}
    best, length = {start: 0.0}, {start: 0.0}
    parent, leaves = {start: start}, {start: start}
    closed: set[int] = set()
    queue = [(0.0, start)]
    inf = math.inf
    while queue and wanted:
        g, cell = heapq.heappop(queue)
        if cell in closed:
            continue
        closed.add(cell)
        wanted.discard(cell)
        row, col = divmod(cell, width)
        here = traversal[cell]
        for dr, dc, step in _STEPS:
            r, c = row + dr, col + dc
            if not (0 <= r < height and 0 <= c < width):
                continue
            neighbour = r * width + c
            there = traversal[neighbour]
            if there == inf or neighbour in closed:
                continue
            candidate = g + step * 0.5 * (here + there)
            if candidate < best.get(neighbour, inf):
                best[neighbour] = candidate
                length[neighbour] = length[cell] + step
                parent[neighbour] = cell
                leaves[neighbour] = neighbour if length[neighbour] <= anchor else leaves[cell]
                heapq.heappush(queue, (candidate, neighbour))
    found = np.full((len(targets), 3), -1.0)
    found[:, 0] = inf
    for index, target in enumerate(int(t) for t in targets):
        if target not in closed:
            continue
        back = target
        while back != start and length[target] - length[back] < anchor:
            back = parent[back]
        found[index] = (length[target], leaves[target], back)
    return found


def _compiled_reach(
    cost: np.ndarray, width: int, lut: np.ndarray, start: int, targets: np.ndarray
) -> np.ndarray:
    raw = _compiled_astar.distances(cost, width, lut, start, targets.tobytes())
    return np.frombuffer(raw, dtype=np.float64)


def _reach_python(
    cost: np.ndarray, width: int, lut: np.ndarray, start: int, targets: np.ndarray
) -> np.ndarray:
    """Dijkstra until every target is closed; the readable twin of ``_astar.c``'s
    ``distances``: each target's length in cells along its cheapest route (the lengths
    of :func:`_routes_python`, without anchors)."""
    return _routes_python(cost, width, lut, start, targets, anchor=0.0)[:, 0]


_STEPS = tuple(
    (dr, dc, SQRT2 if dr and dc else 1.0) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc
)


def _search_python(
    cost: np.ndarray,
    width: int,
    lut: np.ndarray,
    start: int,
    goal: int,
    heuristic_scale: float,
) -> tuple[float, list[int]] | None:
    """A* over flat cell indices; the readable twin of ``_astar.c``."""
    traversal = lut[cost.ravel()].tolist()
    height = cost.size // width
    goal_row, goal_col = divmod(goal, width)
    diagonal_extra = SQRT2 - 1.0

    def heuristic(row: int, col: int) -> float:
        dr, dc = abs(row - goal_row), abs(col - goal_col)
        return heuristic_scale * (max(dr, dc) + diagonal_extra * min(dr, dc))

    best = {start: 0.0}
    parent: dict[int, int] = {}
    closed: set[int] = set()
    # Ties on f go to the deeper entry (larger g), which expands fewer cells.
    queue = [(heuristic(*divmod(start, width)), -0.0, start)]
    inf = math.inf
    while queue:
        _, negative_g, cell = heapq.heappop(queue)
        if cell in closed:
            continue
        closed.add(cell)
        g = -negative_g
        if cell == goal:
            path = [cell]
            while cell != start:
                cell = parent[cell]
                path.append(cell)
            path.reverse()
            return g, path
        row, col = divmod(cell, width)
        here = traversal[cell]
        for dr, dc, step in _STEPS:
            r, c = row + dr, col + dc
            if not (0 <= r < height and 0 <= c < width):
                continue
            neighbour = r * width + c
            there = traversal[neighbour]
            if there == inf or neighbour in closed:
                continue
            candidate = g + step * 0.5 * (here + there)
            if candidate < best.get(neighbour, inf):
                best[neighbour] = candidate
                parent[neighbour] = cell
                heapq.heappush(queue, (candidate + heuristic(r, c), -candidate, neighbour))
    return None
