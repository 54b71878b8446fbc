"""Pre-flight: find every waypoint the robot could never reach, before it moves.

``check_mission`` looks at a mission against a costmap and reports, all at once:

- a waypoint off the map;
- a waypoint inside an obstacle, or in unmapped (unknown) space;
- a waypoint in the inflated footprint: closer to an obstacle than the robot's
  inscribed radius (cost ``INSCRIBED``), where the robot centre cannot be;
- a waypoint that no path connects to the one before it (or to the start pose, for
  the first waypoint; or to the last waypoint, for the first one of the next round
  when the mission loops);
- a start pose off the map, in an obstacle or in the inflated footprint.

Reachability uses the connected components of the free region (the cells where the
robot centre may be, 8-connected as the planner moves), so it costs one labelling of
the map instead of one plan per leg. Where a waypoint is merely too close to a wall
the message suggests the nearest free spot.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.sim.costmap import INSCRIBED, LETHAL, NO_INFORMATION, Costmap

_EIGHT_CONNECTED = np.ones((3, 3), dtype=bool)


def check_mission(
    mission: Mission,
    costmap: Costmap,
    start: Pose2D | None = None,
    *,
    numbers: Sequence[int] | None = None,
) -> list[NavseqError]:
    """Every problem that would stop the robot reaching the mission's waypoints.

    ``start`` defaults to ``mission.start``. An empty list means the mission is
    feasible on this map (as far as a static map can tell). ``numbers`` are the
    waypoints' indices in the file when ``mission`` is the readable part of a
    faulty one, so that messages number them as the file does.
    """
    start = start if start is not None else mission.start
    numbers = range(len(mission.waypoints)) if numbers is None else numbers
    free = _FreeRegions(costmap)
    problems: list[NavseqError] = []

    start_region: int | None = None
    if start is not None:
        problem = _placement_problem(free, start.x, start.y, "the robot cannot start there")
        if problem:
            position = _format_position(start.x, start.y)
            problems.append(
                NavseqError(f"{position} {problem}", source=mission.source, subject="start")
            )
        else:
            start_region = free.region_at(start.x, start.y)

    # The reference for reachability: the last place the robot is known to get to.
    previous_label, previous_region = ("the start pose", start_region)
    regions: list[int | None] = []
    for index, waypoint in zip(numbers, mission.waypoints, strict=True):
        source = waypoint.where or mission.source
        subject = waypoint.label(index)
        position = _format_position(waypoint.x, waypoint.y)
        problem = _placement_problem(free, waypoint.x, waypoint.y, "the robot cannot stop there")
        if problem:
            problems.append(NavseqError(f"{position} {problem}", source=source, subject=subject))
            regions.append(None)
            continue
        region = free.region_at(waypoint.x, waypoint.y)
        regions.append(region)
        if previous_region is not None and region != previous_region:
            problems.append(
                NavseqError(
                    f"{position} cannot be reached from {previous_label}: "
                    "no free path connects them on the map",
                    source=source,
                    subject=subject,
                )
            )
        previous_label = f"{subject} {position}"
        previous_region = region

    loops_again = mission.loops is None or mission.loops > 1
    if loops_again and len(mission.waypoints) > 1:
        first, last = regions[0], regions[-1]
        if first is not None and last is not None and first != last:
            waypoint, last_waypoint = mission.waypoints[0], mission.waypoints[-1]
            problems.append(
                NavseqError(
                    f"{_format_position(waypoint.x, waypoint.y)} cannot be reached from "
                    f"{last_waypoint.label(numbers[-1])} "
                    f"{_format_position(last_waypoint.x, last_waypoint.y)} "
                    "to start the next loop: no free path connects them on the map",
                    source=waypoint.where or mission.source,
                    subject=waypoint.label(numbers[0]),
                )
            )
    return problems


def _placement_problem(free: _FreeRegions, x: float, y: float, consequence: str) -> str | None:
    """Why the robot centre cannot be at (x, y), or None if it can."""
    costmap = free.costmap
    if not costmap.grid.contains(x, y):
        xmin, ymin, xmax, ymax = costmap.grid.bounds
        return (
            f"is outside the map (x {xmin:.2f} .. {xmax:.2f}, y {ymin:.2f} .. {ymax:.2f} m, "
            f"{costmap.grid.source})"
        )
    cost = costmap.cost_at(x, y)
    if cost == LETHAL:
        return "is inside an obstacle" + free.nearest_hint(x, y)
    if cost == NO_INFORMATION:
        return "is in unmapped space (unknown cells)" + free.nearest_hint(x, y)
    if cost >= INSCRIBED:
        radius = costmap.params.inscribed_radius
        return (
            f"is within the robot's inscribed radius ({radius:.3f} m) of an obstacle: "
            f"{consequence}" + free.nearest_hint(x, y)
        )
    return None


def _format_position(x: float, y: float) -> str:
    return f"at ({x:.2f}, {y:.2f})"


@dataclass
class _FreeRegions:
    """Connected components of the cells where the robot centre may be."""

    costmap: Costmap

    def __post_init__(self) -> None:
        self.free = self.costmap.free_mask()
        self.labels, _ = ndimage.label(self.free, structure=_EIGHT_CONNECTED)
        self._free_cells: np.ndarray | None = None

    def region_at(self, x: float, y: float) -> int:
        row, col = self.costmap.world_to_cell(x, y)
        return int(self.labels[row, col])

    def nearest_hint(self, x: float, y: float) -> str:
        """``"; the nearest free spot is at (x, y)"`` or an empty string."""
        if self._free_cells is None:
            self._free_cells = np.argwhere(self.free)
        if len(self._free_cells) == 0:
            return "; the map has no free space at all"
        row, col = self.costmap.world_to_cell(x, y)
        nearest = np.argmin(((self._free_cells - (row, col)) ** 2).sum(axis=1))
        free_x, free_y = self.costmap.cell_to_world(*self._free_cells[nearest])
        return f"; the nearest free spot is {_format_position(free_x, free_y)}"
