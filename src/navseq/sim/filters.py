"""Nav2's costmap filters on the simulator's map: keepout zones and speed zones.

A mission's filters (:class:`navseq.mission.costmap_filters.CostmapFilter`: a mask in
map_server format and its ``costmap_filter_info_server`` parameters) are read once and
resampled onto the map's own cells (each map cell takes the mask cell under its centre;
the mask may have another resolution, origin or size). The result rides on the map
(:attr:`OccupancyGrid.filters`), so that every costmap built from it — pre-flight, the
simulated server's, its cleared costmap, the route planner's, the ETA's — holds the
keepout zones, and the controller and the ETA read the speed limits:

- keepout (type 0): a mask cell of value 100 (occupied, as map_server reads it) is a
  zone the robot's centre never plans through, and, as an obstacle does, with its
  circumscribed radius to spare (stricter than Nav2, whose planners treat the robot as
  a point against the filter's lethal cells);
- speed (type 1, percent of the maximum speed; type 2, m/s): a cell of value ``v``
  limits the speed to ``base + multiplier * v``; a value of 0 or unknown (-1) and a
  limit <= 0 (or above 100 %) mean no limit, as Nav2's SpeedFilter.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from navseq.errors import NavseqError
from navseq.mission.costmap_filters import CostmapFilter, FilterType
from navseq.sim.costmap import Costmap
from navseq.sim.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, load_map


@dataclass(frozen=True, eq=False)
class MapFilters:
    """The filters resampled onto a map's cells (arrays of the map's shape, read-only).

    ``keepout``: cells in a keepout zone. ``speed_limit``: each cell's limit (NaN: none),
    in percent of the maximum speed or, with ``speed_absolute``, in m/s. ``sources``:
    the masks, for legends and messages.
    """

    keepout: np.ndarray | None = None
    speed_limit: np.ndarray | None = None
    speed_absolute: bool = False
    sources: tuple[str, ...] = ()

    def in_keepout(self, grid: OccupancyGrid, x: float, y: float) -> bool:
        if self.keepout is None:
            return False
        row, col = grid.world_to_cell(x, y)
        return grid.in_bounds(row, col) and bool(self.keepout[row, col])

    def keepout_source(self) -> str:
        return ", ".join(self.sources)

    def speed_cap(self, grid: OccupancyGrid, x: float, y: float, max_speed: float) -> float:
        """The speed allowed at (x, y) for a robot whose top speed is ``max_speed``."""
        if self.speed_limit is None:
            return max_speed
        row, col = grid.world_to_cell(x, y)
        if not grid.in_bounds(row, col):
            return max_speed
        return cap_speed(float(self.speed_limit[row, col]), self.speed_absolute, max_speed)


def cap_speed(limit: float, absolute: bool, max_speed: float) -> float:
    """``max_speed`` under one cell's limit (NaN: no limit)."""
    if math.isnan(limit):
        return max_speed
    return min(max_speed, limit) if absolute else max_speed * limit / 100.0


def with_filters(grid: OccupancyGrid, filters: Sequence[CostmapFilter]) -> OccupancyGrid:
    """``grid`` with ``filters`` read and laid over its cells (added to any it has);
    ``grid`` itself without any.

    Raises NavseqError for a mask that cannot be read (naming its file and key).
    """
    if not filters:
        return grid
    had = grid.filters or MapFilters()
    keepout, speed_limit, absolute = had.keepout, had.speed_limit, had.speed_absolute
    for spec in filters:
        try:
            mask = load_map(spec.mask)
        except NavseqError as error:  # named where the mission gives the filter
            raise NavseqError(
                f"the mask cannot be read: {error}", source=spec.where, subject="filters"
            ) from None
        values = mask_on_grid(mask, grid)
        if spec.type is FilterType.KEEPOUT:
            zone = (values >= OCCUPIED) | (values < UNKNOWN)
            keepout = zone if keepout is None else keepout | zone
            continue
        limits = speed_limits(values, spec)
        absolute = spec.type is FilterType.SPEED_ABSOLUTE
        # One speed filter acts in Nav2 (its speed_limit topic); a later one wins where
        # it limits.
        speed_limit = (
            limits if speed_limit is None else np.where(np.isnan(limits), speed_limit, limits)
        )
    for array in (keepout, speed_limit):
        if array is not None:
            array.setflags(write=False)
    sources = (*had.sources, *(str(spec.mask) for spec in filters))
    return dataclasses.replace(grid, filters=MapFilters(keepout, speed_limit, absolute, sources))


def speed_limits(values: np.ndarray, spec: CostmapFilter) -> np.ndarray:
    """Each cell's speed limit from its mask value (NaN: no limit), as Nav2's SpeedFilter."""
    limits = (spec.base + spec.multiplier * values.astype(np.float32)).astype(np.float32)
    no_limit = (values == FREE) | (values == UNKNOWN) | (limits <= 0.0)
    if spec.type is FilterType.SPEED_PERCENT:
        no_limit |= limits > 100.0
    limits[no_limit] = np.nan
    return limits


def mask_on_grid(mask: OccupancyGrid, grid: OccupancyGrid) -> np.ndarray:
    """The mask's value under each of ``grid``'s cell centres (UNKNOWN off the mask)."""
    rows, cols = np.indices(grid.data.shape)
    centres = grid.cells_to_world(rows.ravel(), cols.ravel())
    mask_rows, mask_cols = mask.world_to_cells(centres[:, 0], centres[:, 1])
    inside = (
        (mask_rows >= 0) & (mask_rows < mask.height) & (mask_cols >= 0) & (mask_cols < mask.width)
    )
    values = np.full(mask_rows.shape, UNKNOWN, dtype=mask.data.dtype)
    values[inside] = mask.data[mask_rows[inside], mask_cols[inside]]
    return values.reshape(grid.data.shape)


def costmap_with_filters(costmap: Costmap, filters: Sequence[CostmapFilter]) -> Costmap:
    """``costmap`` rebuilt on its map with ``filters`` laid over it; itself without any.

    For the faces that keep one costmap per map (validate, plan, the API): a mission's
    filters are its own, so they are added to a copy.
    """
    if not filters:
        return costmap
    return Costmap.from_grid(with_filters(costmap.grid, filters), costmap.params)


def load_filtered_map(map_path: str | Path, filters: Sequence[CostmapFilter]) -> OccupancyGrid:
    """A map_server map with a mission's costmap filters over it."""
    return with_filters(load_map(map_path), filters)


__all__ = [
    "MapFilters",
    "cap_speed",
    "costmap_with_filters",
    "load_filtered_map",
    "mask_on_grid",
    "speed_limits",
    "with_filters",
]
