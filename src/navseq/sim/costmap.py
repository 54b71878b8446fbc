"""A costmap like costmap_2d's static + inflation layers: what a robot centre costs here.

Each cell gets a cost byte with costmap_2d's meanings:

- ``LETHAL`` (254): an obstacle cell;
- ``INSCRIBED`` (253): within ``inscribed_radius`` of an obstacle, so the robot's
  footprint would certainly touch it — the robot centre must not be here;
- 1..252: ``252 * exp(-cost_scaling_factor * (d - inscribed_radius))`` for distances
  ``d`` up to ``inflation_radius``, so plans keep clear of walls where they can;
- ``FREE`` (0): farther away;
- ``NO_INFORMATION`` (255): unknown cells. With ``unknown_is_lethal`` (the default,
  like a planner that does not allow unknown space) they also act as obstacles for
  inflation; without it they are read as free space, as costmap_2d's static layer does
  with ``track_unknown_space: false``.

Distances are Euclidean between cell centres (``scipy.ndimage.distance_transform_edt``),
as costmap_2d's inflation layer computes them.

Obstacles that are not on the map (other robots) are added with
:meth:`Costmap.with_obstacles`, like costmap_2d's obstacle layer over the static one.

Where the robot centre may be *for planning* is stricter than the cost bands: a cell
is traversable only if the circle of ``circumscribed_radius`` about its centre touches
no blocked cell (obstacle, unknown cell, or — with ``unknown_is_lethal`` — the map edge,
beyond which nothing is known). That is where the robot can turn in place whatever its
heading, as navfn on a costmap whose inscribed/circumscribed costs come from the
footprint: a corridor narrower than the robot's turning circle is not planned through,
so the robot never drives into a gap it cannot turn in or get out of. ``clearance`` holds,
per cell, the distance from its centre to the nearest blocked cell's square (m).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from navseq.sim.occupancy import OccupancyGrid

FREE, INSCRIBED, LETHAL, NO_INFORMATION = 0, 253, 254, 255


@dataclass(frozen=True)
class CostmapParams:
    """Inflation settings; defaults are the TurtleBot3 burger's navigation parameters."""

    inflation_radius: float = 1.0  # m: cells farther than this from an obstacle cost 0
    cost_scaling_factor: float = 3.0  # 1/m: how fast the cost decays with distance
    inscribed_radius: float = 0.105  # m: the footprint's inscribed radius
    # m: the footprint's circumscribed radius (the burger's corner, 0.148 m); cells with
    # less clearance are not traversable for planning
    circumscribed_radius: float = math.hypot(0.105, 0.105)
    unknown_is_lethal: bool = True

    def __post_init__(self) -> None:
        names = (
            "inflation_radius",
            "cost_scaling_factor",
            "inscribed_radius",
            "circumscribed_radius",
        )
        for name in names:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and 0.0 <= value < float("inf")):
                raise ValueError(f"costmap {name} must be a number >= 0, got {value!r}")


@dataclass(frozen=True, eq=False)
class Costmap:
    """Per-cell costs (uint8, same shape and orientation as ``grid.data``)."""

    grid: OccupancyGrid
    params: CostmapParams = field(default_factory=CostmapParams)
    cost: np.ndarray = field(default=None)  # type: ignore[arg-type]
    clearance: np.ndarray = field(default=None)  # type: ignore[arg-type]

    def __post_init__(self) -> None:
        if self.cost is None:
            object.__setattr__(self, "cost", inflate(self.grid, self.params))
        if self.clearance is None:
            object.__setattr__(self, "clearance", clearance_to_blocked(self.grid, self.params))
        if self.cost.shape != self.grid.data.shape or self.clearance.shape != self.cost.shape:
            raise ValueError("cost or clearance array and grid differ in shape")
        self.cost.setflags(write=False)
        self.clearance.setflags(write=False)
        traversable = (self.cost < INSCRIBED) & (
            self.clearance >= np.float32(self.params.circumscribed_radius)
        )
        traversable.setflags(write=False)
        object.__setattr__(self, "_traversable", traversable)
        planning = np.where(traversable, self.cost, np.uint8(INSCRIBED)).astype(np.uint8)
        planning.setflags(write=False)
        object.__setattr__(self, "_planning_cost", planning)

    @classmethod
    def from_grid(cls, grid: OccupancyGrid, params: CostmapParams | None = None) -> Costmap:
        return cls(grid, params or CostmapParams())

    @property
    def resolution(self) -> float:
        return self.grid.resolution

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        return self.grid.world_to_cell(x, y)

    def cell_to_world(self, row: int, col: int) -> tuple[float, float]:
        return self.grid.cell_to_world(row, col)

    def cost_at(self, x: float, y: float) -> int:
        """Cost of the cell under a world point; ``NO_INFORMATION`` off the map."""
        row, col = self.grid.world_to_cell(x, y)
        if not self.grid.in_bounds(row, col):
            return NO_INFORMATION
        return int(self.cost[row, col])

    def is_free(self, x: float, y: float) -> bool:
        """True if the cell under this point is traversable: the robot, centred there, can
        turn in place without touching anything (see the module docstring)."""
        row, col = self.grid.world_to_cell(x, y)
        return self.grid.in_bounds(row, col) and bool(self.free_mask()[row, col])

    def free_mask(self) -> np.ndarray:
        """Cells where the planner may put the robot centre (read-only)."""
        return self._traversable  # type: ignore[attr-defined]

    @property
    def planning_cost(self) -> np.ndarray:
        """``cost`` with every cell that is not traversable raised to ``INSCRIBED``."""
        return self._planning_cost  # type: ignore[attr-defined]

    def clearance_at(self, x: float, y: float) -> float:
        """The clearance (m) of the cell under a world point; 0 off the map."""
        row, col = self.grid.world_to_cell(x, y)
        if not self.grid.in_bounds(row, col):
            return 0.0
        return float(self.clearance[row, col])

    def with_obstacles(
        self, rows: np.ndarray, cols: np.ndarray, *, padding: float = 0.0
    ) -> Costmap:
        """This costmap plus lethal cells at (``rows``, ``cols``), inflated as usual.

        ``grid`` stays the map's: the extra obstacles live in ``cost`` only. The result
        equals inflating the map with those cells occupied, but costs an EDT of a window
        around them only: the cost falls with the distance to the nearest obstacle, so
        the cost of the union is the larger of the two costs, and beyond
        ``inflation_radius`` of the new cells nothing changes. ``padding`` (m) grows the
        new obstacles all round before they are inflated.
        """
        return self.with_obstacle_groups([(rows, cols)], padding=padding)

    def with_obstacle_groups(
        self, groups: Sequence[tuple[np.ndarray, np.ndarray]], *, padding: float = 0.0
    ) -> Costmap:
        """:meth:`with_obstacles` for several groups of cells (rows, cols) at once, each
        inflated in a window of its own: robots metres apart cost a few small windows
        rather than one that spans them all. The same costs as one group of them all,
        for the same reason (the larger cost of each, the smaller clearance)."""
        groups = [
            (np.asarray(rows, dtype=np.intp), np.asarray(cols, dtype=np.intp))
            for rows, cols in groups
        ]
        groups = [(rows, cols) for rows, cols in groups if rows.size]
        if not groups:
            return self
        reach = math.ceil((self.params.inflation_radius + padding) / self.grid.resolution) + 1
        height, width = self.cost.shape
        cost = self.cost.copy()
        clearance = self.clearance.copy()
        windows = []
        for rows, cols in groups:
            top, bottom = max(int(rows.min()) - reach, 0), min(int(rows.max()) + reach + 1, height)
            left, right = max(int(cols.min()) - reach, 0), min(int(cols.max()) + reach + 1, width)
            blocked = np.zeros((bottom - top, right - left), dtype=bool)
            blocked[rows - top, cols - left] = True
            distance, to_square = _distances(blocked, self.grid.resolution)
            if padding > 0.0:
                distance = np.maximum(distance - padding, 0.0)
                to_square = np.maximum(to_square - padding, 0.0)
            window = (slice(top, bottom), slice(left, right))
            np.maximum(cost[window], cost_of_distance(distance, self.params), out=cost[window])
            np.minimum(clearance[window], to_square.astype(np.float32), out=clearance[window])
            windows.append(window)
        return self._patched(cost, clearance, windows)

    def _patched(
        self, cost: np.ndarray, clearance: np.ndarray, windows: list[tuple[slice, slice]]
    ) -> Costmap:
        """A costmap with ``cost`` and ``clearance``, which differ from this one's only in
        ``windows``: what derives from them is recomputed there only (fleets rebuild a
        costmap with the robots in it many times a second; the whole map each time cost
        more than the rest of the rebuild)."""
        patched = object.__new__(Costmap)
        for name, value in (
            ("grid", self.grid),
            ("params", self.params),
            ("cost", cost),
            ("clearance", clearance),
        ):
            object.__setattr__(patched, name, value)
        cost.setflags(write=False)
        clearance.setflags(write=False)
        traversable = self.free_mask().copy()
        planning = self.planning_cost.copy()
        for window in windows:
            traversable[window] = (cost[window] < INSCRIBED) & (
                clearance[window] >= np.float32(self.params.circumscribed_radius)
            )
            planning[window] = np.where(traversable[window], cost[window], np.uint8(INSCRIBED))
        traversable.setflags(write=False)
        planning.setflags(write=False)
        object.__setattr__(patched, "_traversable", traversable)
        object.__setattr__(patched, "_planning_cost", planning)
        return patched


def inflate(grid: OccupancyGrid, params: CostmapParams) -> np.ndarray:
    """The cost array of a grid: lethal obstacles, inscribed band, exponential decay."""
    obstacles = grid.occupied_mask()
    unknown = grid.unknown_mask()
    if params.unknown_is_lethal:
        obstacles = obstacles | unknown
    keepout = grid.keepout_mask()
    if keepout is not None:  # a keepout zone costs what an obstacle does (filters.py)
        obstacles = obstacles | keepout

    cost = np.zeros(grid.data.shape, dtype=np.uint8)
    if obstacles.any():
        distance = ndimage.distance_transform_edt(~obstacles) * grid.resolution
        cost[:] = cost_of_distance(distance, params)
    if params.unknown_is_lethal:
        cost[unknown] = NO_INFORMATION
    return cost


def clearance_to_blocked(grid: OccupancyGrid, params: CostmapParams) -> np.ndarray:
    """Per cell, metres from its centre to the nearest blocked cell's square (float32).

    Blocked: occupied, and unknown when ``unknown_is_lethal`` — which also puts a blocked
    border round the map, for nothing beyond it is known.
    """
    blocked = grid.occupied_mask()
    keepout = grid.keepout_mask()
    if keepout is not None:
        blocked = blocked | keepout
    if params.unknown_is_lethal:
        blocked = np.pad(blocked | grid.unknown_mask(), 1, constant_values=True)
    _, to_square = _distances(blocked, grid.resolution)
    if params.unknown_is_lethal:
        to_square = to_square[1:-1, 1:-1]
    return to_square.astype(np.float32)


def _distances(blocked: np.ndarray, resolution: float) -> tuple[np.ndarray, np.ndarray]:
    """(centre-to-centre, centre-to-square) distances (m) to the nearest blocked cell.

    The square distance is taken to the cell whose centre is nearest, which is the
    nearest square but for rounding-sized differences; with no blocked cell both are inf.
    """
    if not blocked.any():
        infinite = np.full(blocked.shape, np.inf)
        return infinite, infinite
    distance, (near_rows, near_cols) = ndimage.distance_transform_edt(~blocked, return_indices=True)
    rows = np.arange(blocked.shape[0])[:, np.newaxis]  # broadcast: no full index arrays
    cols = np.arange(blocked.shape[1])[np.newaxis, :]
    d_row = np.maximum(np.abs(near_rows - rows) - 0.5, 0.0)
    d_col = np.maximum(np.abs(near_cols - cols) - 0.5, 0.0)
    to_square = np.hypot(d_row, d_col)
    to_square[blocked] = 0.0
    return distance * resolution, to_square * resolution


def cost_of_distance(distance: np.ndarray, params: CostmapParams) -> np.ndarray:
    """costmap_2d's ``computeCost``: cost byte for a distance (m) to the nearest obstacle."""
    beyond_inscribed = np.maximum(distance - params.inscribed_radius, 0.0)
    decay = np.exp(-params.cost_scaling_factor * beyond_inscribed)
    # costmap_2d casts to unsigned char, i.e. truncates.
    cost = np.floor((INSCRIBED - 1) * decay).astype(np.uint8)
    cost = np.where(distance <= params.inscribed_radius, np.uint8(INSCRIBED), cost)
    cost = np.where(distance > params.inflation_radius, np.uint8(FREE), cost)
    return np.where(distance == 0, np.uint8(LETHAL), cost).astype(np.uint8)


def occupancy_values(cost: np.ndarray) -> np.ndarray:
    """Costs as a ``nav_msgs/OccupancyGrid``'s values, by Nav2's costmap publisher's
    table: free 0, inscribed 99, lethal 100, unknown -1, the rest spread over 1..98."""
    table = np.empty(256, dtype=np.int8)
    table[0] = 0
    middle = np.arange(1, INSCRIBED)
    table[1:INSCRIBED] = 1 + (97 * (middle - 1)) // 251
    table[INSCRIBED], table[LETHAL], table[NO_INFORMATION] = 99, 100, -1
    return table[cost]
