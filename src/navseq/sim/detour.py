"""Re-planning around a robot that came near the plan, without a search of the whole map.

In a fleet, robots come near each other's plans all the time; each time the navigation
server re-plans. An A* over the whole map costs milliseconds on a warehouse, and in a
fleet of twenty it was most of the simulator's time. Most of those re-plans are not
needed, and the rest only have to change the plan near the robot:

- :func:`blocked_stretch` tells whether the rest of the plan is still traversable on
  the costmap that holds the robots now. If it is, the plan is kept as it is (the robot
  passes the other one as it would pass a wall).
- Otherwise :func:`local_detour` searches only a window round the blocked stretch:
  from the robot to a point of the plan just past it, then on along the old plan. When
  no way exists inside the window, the caller plans over the whole map as before.

A detour is the cheapest way within its window to where it rejoins the plan; a way
round through a far aisle is found by the whole-map search when the window has none.
"""

from __future__ import annotations

import math

import numpy as np

from navseq.sim.costmap import INSCRIBED, Costmap
from navseq.sim.planner import Plan, search_cells


def blocked_stretch(costmap: Costmap, points: np.ndarray) -> np.ndarray:
    """Per point of ``points`` (N, 2, world), True where the robot centre may not be
    on ``costmap`` (its cell is not traversable, or off the map)."""
    grid = costmap.grid
    rows, cols = grid.world_to_cells(points[:, 0], points[:, 1])
    cost = costmap.planning_cost
    inside = (rows >= 0) & (rows < cost.shape[0]) & (cols >= 0) & (cols < cost.shape[1])
    blocked = ~inside
    blocked[inside] = cost[rows[inside], cols[inside]] >= INSCRIBED
    return blocked


def local_detour(
    costmap: Costmap,
    start: tuple[float, float],
    rest: np.ndarray,
    blocked: np.ndarray,
    *,
    rejoin: float = 1.0,
    margin: float = 2.0,
    largest_share: float = 0.25,
) -> Plan | None:
    """A plan from ``start`` round the ``blocked`` points of ``rest`` (the plan ahead,
    first point where the robot is) that rejoins ``rest`` ``rejoin`` metres past them;
    None when the window (the stretch up to there grown by ``margin`` metres, at most
    ``largest_share`` of the map) has no way, or the plan's end itself is blocked.

    ``start`` must be traversable; the detour's first point is ``start`` exactly and its
    last points are ``rest``'s from where it rejoins.
    """
    grid = costmap.grid
    flagged = np.flatnonzero(blocked)
    if flagged.size == 0:
        return None
    last = int(flagged[-1])
    if last == len(rest) - 1:
        return None  # the goal end is taken: no detour reaches it
    steps = np.hypot(np.diff(rest[:, 0]), np.diff(rest[:, 1]))
    along = np.concatenate(([0.0], np.cumsum(steps)))
    beyond = np.flatnonzero(along >= along[last] + rejoin)
    end = int(beyond[0]) if beyond.size else len(rest) - 1
    if blocked[end]:
        return None
    cost = costmap.planning_cost
    height, width = cost.shape
    start_row, start_col = grid.world_to_cell(*start)
    end_row, end_col = grid.world_to_cell(float(rest[end, 0]), float(rest[end, 1]))
    rows, cols = grid.world_to_cells(rest[: end + 1, 0], rest[: end + 1, 1])
    pad = math.ceil(margin / grid.resolution)
    top = max(min(int(rows.min()), start_row) - pad, 0)
    bottom = min(max(int(rows.max()), start_row) + pad + 1, height)
    left = max(min(int(cols.min()), start_col) - pad, 0)
    right = min(max(int(cols.max()), start_col) + pad + 1, width)
    if (bottom - top) * (right - left) > largest_share * height * width:
        return None  # as dear as the whole map: let the caller search that
    if not (top <= start_row < bottom and left <= start_col < right):
        return None
    found = search_cells(
        cost[top:bottom, left:right],
        (start_row - top, start_col - left),
        (end_row - top, end_col - left),
    )
    if found is None:
        return None
    cells, cost_in_cells = found
    head = grid.cells_to_world(cells[:, 0] + top, cells[:, 1] + left)
    head[0] = start
    if len(head) == 1:
        head = np.array([start, rest[end]], dtype=float)
    head[-1] = rest[end]
    points = np.vstack((head, rest[end + 1 :]))
    lengths = np.hypot(np.diff(points[:, 0]), np.diff(points[:, 1]))
    length = float(lengths.sum())
    tail = float(lengths[len(head) - 1 :].sum())  # the old plan's own stretch, at its length
    return Plan(points=points, length=length, cost=cost_in_cells * grid.resolution + tail)


__all__ = ["blocked_stretch", "local_detour"]
