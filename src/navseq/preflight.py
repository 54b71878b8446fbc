"""Pre-flight: find every waypoint the robot could never reach, before it moves.

``check_mission`` looks at a mission against a costmap and reports, all at once:

- a waypoint off the map;
- a waypoint inside an obstacle, in unmapped (unknown) space, or in a keepout zone of
  the map's costmap filters (:mod:`navseq.sim.filters`);
- a waypoint where the robot cannot turn: closer to an obstacle, unknown space or the
  map edge than the footprint's circumscribed radius (the robot stops and turns to the
  goal's heading at every waypoint, and at the start it turns toward the first one);
- a waypoint that no path connects to the last place before it the robot can get to
  (the start pose, or an earlier waypoint), each such waypoint once: the leg after an
  unreachable waypoint is checked from the last reachable one, so an isolated point
  does not get its innocent successor blamed too. Without a start pose, the region
  most waypoints are in is taken for the robot's;
- a start pose off the map, where the footprint overlaps something (the exact test the
  simulated body uses), or where the robot cannot turn.

Reachability uses the connected components of the cells the planner may cross (those
that clear every obstacle by the circumscribed radius, 8-connected as the planner
moves), so it costs one labelling of the map instead of one plan per leg, and agrees
with the planner on narrow gaps. Where a waypoint is merely too close to a wall the
message suggests the nearest spot where the robot fits with ``clearance_margin_m`` to
spare and that is reachable from the place the robot comes from; the problem is then a
:class:`MisplacedError` carrying that spot (``suggested``), which a face can offer to
apply in one click (the studio's "move to the nearest free spot").
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass, field
from weakref import WeakKeyDictionary

import numpy as np
from scipy import ndimage

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.mission.model import Mission, Waypoint
from navseq.mission.robot import DEFAULT_PROFILE, RobotProfile
from navseq.sim.costmap import LETHAL, NO_INFORMATION, Costmap
from navseq.sim.footprint import Footprint, footprint_collides
from navseq.sim.occupancy import OCCUPIED, UNKNOWN, blocked_values

_EIGHT_CONNECTED = np.ones((3, 3), dtype=bool)


class MisplacedError(NavseqError):
    """A waypoint or start pose where the robot cannot stand and turn, with the nearest
    spot where it can (``suggested``: map x, y in metres), when there is one."""

    def __init__(
        self,
        message: str,
        *,
        suggested: tuple[float, float] | None,
        source: str | None = None,
        subject: str | None = None,
    ) -> None:
        super().__init__(message, source=source, subject=subject)
        self.suggested = suggested


@dataclass(frozen=True)
class _Placement:
    """Why the robot cannot be at a point, and the nearest spot where it can (or None)."""

    text: str
    spot: tuple[float, float] | None = None


def check_mission(
    mission: Mission,
    costmap: Costmap,
    start: Pose2D | None = None,
    *,
    numbers: Sequence[int] | None = None,
    robot: RobotProfile | None = None,
) -> list[NavseqError]:
    """Every problem that would stop the robot reaching the mission's waypoints.

    ``start`` defaults to ``mission.start``. An empty list means the mission is
    feasible on this map (as far as a static map can tell). ``numbers`` are the
    waypoints' indices in the file when ``mission`` is the readable part of a
    faulty one, so that messages number them as the file does. ``robot`` (default:
    the mission's, else the default profile) gives the outline tested at the start and
    the margin of suggested spots; ``costmap`` must have been built for that robot.
    """
    start = start if start is not None else mission.start
    if numbers is None:  # a part's mission knows its file numbers
        numbers = mission.numbers if mission.numbers is not None else range(len(mission))
    robot = robot or mission.robot or DEFAULT_PROFILE
    free = free_regions(costmap, robot)
    problems: list[NavseqError] = []

    start_region: int | None = None
    if start is not None:
        problem = _start_problem(free, start)
        if problem:
            position = _format_position(start.x, start.y)
            problems.append(
                MisplacedError(
                    f"{position} {problem.text}",
                    suggested=problem.spot,
                    source=mission.source,
                    subject="start",
                )
            )
        else:
            start_region = free.region_at(start.x, start.y)

    # Reachability is judged against one region of the map: the start pose's, or, when
    # the start is not known, the one most waypoints are in. A waypoint outside it is
    # reported once, and the leg after it is checked from the last waypoint the robot
    # can get to, so a waypoint after an isolated one is not blamed as well. Every
    # waypoint reached is in that one region, so the way back to the first waypoint
    # for the next loop needs no check of its own.
    regions = free.regions_of(mission.waypoints)
    reference = start_region if start_region is not None else _most_common(regions)
    # The last waypoint the robot can get to, named only when a message needs it.
    previous: tuple[int, Waypoint] | None = None
    for index, waypoint, region in zip(numbers, mission.waypoints, regions, strict=True):
        if region is not None and (reference is None or region == reference):
            previous = (index, waypoint)
            continue
        source = waypoint.where or mission.source
        subject = waypoint.label(index)
        position = _format_position(waypoint.x, waypoint.y)
        if region is None:
            placement = free.placement(waypoint.x, waypoint.y, reference)
            assert placement is not None  # region None: the robot cannot be there
            problems.append(
                MisplacedError(
                    f"{position} {placement.text}",
                    suggested=placement.spot,
                    source=source,
                    subject=subject,
                )
            )
            continue
        if previous is not None:
            before, reached = previous
            where_from = (
                f"cannot be reached from {reached.label(before)} "
                f"{_format_position(reached.x, reached.y)}"
            )
        elif start_region is not None:
            where_from = "cannot be reached from the start pose"
        else:
            where_from = "is cut off from the mission's other waypoints"
        problems.append(
            NavseqError(
                f"{position} {where_from}: no free path connects them on the map",
                source=source,
                subject=subject,
            )
        )
    return problems


def _most_common(regions: Sequence[int | None]) -> int | None:
    """The region most waypoints are in (the earliest one's on a tie), None if none."""
    counts: dict[int, int] = {}
    for region in regions:
        if region is not None:
            counts[region] = counts.get(region, 0) + 1
    return max(counts, key=lambda region: counts[region]) if counts else None


def _start_problem(free: _FreeRegions, start: Pose2D) -> _Placement | None:
    """Why the robot cannot start at ``start``, or None if it can."""
    problem = _placement_problem(free, start.x, start.y, "the robot cannot turn there", None)
    costmap = free.costmap
    if problem is None or costmap.cost_at(start.x, start.y) in (LETHAL, NO_INFORMATION):
        return problem  # off the map, in an obstacle or in unknown space: said so already
    if footprint_collides(costmap.grid, free.footprint, start):
        hint, spot = free.nearest_hint(start.x, start.y, None)
        return _Placement(
            "puts the robot's footprint over an obstacle, unknown space or the map edge: "
            "the robot cannot be there" + hint,
            spot,
        )
    return problem


def _placement_problem(
    free: _FreeRegions, x: float, y: float, consequence: str, from_region: int | None
) -> _Placement | None:
    """Why the robot centre cannot be at (x, y) and turn there, or None if it can.

    ``from_region``: where the robot comes from, so that a suggested spot is reachable.
    """
    costmap = free.costmap
    if not costmap.grid.contains(x, y):
        xmin, ymin, xmax, ymax = costmap.grid.bounds
        return _Placement(
            f"is outside the map (x {xmin:.2f} .. {xmax:.2f}, y {ymin:.2f} .. {ymax:.2f} m, "
            f"{costmap.grid.source})"
        )
    cost = costmap.cost_at(x, y)
    zones = costmap.grid.filters
    if zones is not None and zones.in_keepout(costmap.grid, x, y):
        what = f"is in a keepout zone ({zones.keepout_source()})"
    elif cost == LETHAL:
        what = "is inside an obstacle"
    elif cost == NO_INFORMATION:
        what = "is in unmapped space (unknown cells)"
    else:
        clearance = free.clearance_at(x, y)
        radius = costmap.params.circumscribed_radius
        if clearance >= radius and costmap.is_free(x, y):
            return None
        near = (
            "an obstacle, a keepout zone, unknown space or the map edge"
            if costmap.grid.keepout_mask() is not None
            else "an obstacle, unknown space or the map edge"
        )
        what = (
            f"is {clearance:.3f} m from {near}, within "
            f"the robot's circumscribed radius ({radius:.3f} m, {free.robot.name}): "
            f"{consequence}"
        )
    hint, spot = free.nearest_hint(x, y, from_region)
    return _Placement(what + hint, spot)


def _format_position(x: float, y: float) -> str:
    return f"at ({x:.2f}, {y:.2f})"


#: The free regions of the costmaps still in use, per robot: labelling a 2000 x 2000 map
#: takes 40 ms, and the studio checks the same map after every edit. A costmap is never
#: changed once built (frozen), so what is worked out from it stays true while it lives.
_KEPT: WeakKeyDictionary[Costmap, dict[RobotProfile, _FreeRegions]] = WeakKeyDictionary()
_KEPT_LOCK = threading.Lock()
#: Verdicts kept per costmap and robot (points looked at closely, placements): past
#: this many, they are forgotten and worked out again.
_VERDICTS_KEPT = 200_000


def free_regions(costmap: Costmap, robot: RobotProfile) -> _FreeRegions:
    """The free regions of ``costmap`` for ``robot``, made once per costmap and robot."""
    with _KEPT_LOCK:
        per_robot = _KEPT.setdefault(costmap, {})
        regions = per_robot.get(robot)
    if regions is None:
        regions = _FreeRegions(costmap, robot)
        with _KEPT_LOCK:
            regions = per_robot.setdefault(robot, regions)
    return regions


@dataclass
class _FreeRegions:
    """Connected components of the cells the planner may cross, and the robot's room.

    Verdicts about single points (a point near an obstacle looked at closely, the nearest
    free spot) are kept by their coordinates: after an edit in the studio, a check of
    5000 waypoints looks again only at the ones that moved.
    """

    costmap: Costmap
    robot: RobotProfile
    _regions: dict[tuple[float, float], int | None] = field(default_factory=dict, repr=False)
    _placements: dict[tuple[float, float, int | None], _Placement | None] = field(
        default_factory=dict, repr=False
    )

    def placement(self, x: float, y: float, from_region: int | None) -> _Placement | None:
        """:func:`_placement_problem` of a waypoint (the robot must turn there), kept."""
        key = (x, y, from_region)
        if key not in self._placements:
            if len(self._placements) > _VERDICTS_KEPT:
                self._placements.clear()
            self._placements[key] = _placement_problem(
                self, x, y, "the robot cannot turn there", from_region
            )
        return self._placements[key]

    def _region_looked_at(self, x: float, y: float) -> int | None:
        """The free region of a point near an obstacle, unknown space or the map edge
        (None: the robot cannot stand and turn there), kept."""
        key = (x, y)
        if key not in self._regions:
            if len(self._regions) > _VERDICTS_KEPT:
                self._regions.clear()
            self._regions[key] = (
                self.region_at(x, y) if _placement_problem(self, x, y, "", None) is None else None
            )
        return self._regions[key]

    def __post_init__(self) -> None:
        self.free = self.costmap.free_mask()
        self.labels, _ = ndimage.label(self.free, structure=_EIGHT_CONNECTED)
        self.footprint = Footprint(np.array(self.robot.footprint, dtype=float))
        # Where a suggested spot may be: room to turn, with the margin to spare.
        roomy = self.costmap.params.circumscribed_radius + self.robot.clearance_margin_m
        self._roomy_cells = np.argwhere(self.free & (self.costmap.clearance >= roomy))

    def regions_of(self, waypoints: Sequence[Waypoint]) -> list[int | None]:
        """Each waypoint's free region, or None where the robot cannot stand and turn.

        The same verdict as :func:`_placement_problem`, in one numpy pass for the
        waypoints whose cell clears the robot with room to spare (most of them); only
        those near an obstacle, unknown space or the map edge are looked at closely.
        """
        if not waypoints:
            return []
        costmap, grid = self.costmap, self.costmap.grid
        xs = np.fromiter((w.x for w in waypoints), dtype=float, count=len(waypoints))
        ys = np.fromiter((w.y for w in waypoints), dtype=float, count=len(waypoints))
        rows, cols = grid.world_to_cells(xs, ys)
        inside = (rows >= 0) & (rows < grid.height) & (cols >= 0) & (cols < grid.width)
        rows, cols = np.where(inside, rows, 0), np.where(inside, cols, 0)
        cost = costmap.cost[rows, cols]
        # Beyond this cell clearance, clearance_at needs no closer look (see there).
        roomy = costmap.params.circumscribed_radius + 2 * grid.resolution
        clear = (
            inside
            & (cost != LETHAL)
            & (cost != NO_INFORMATION)
            & self.free[rows, cols]
            & (costmap.clearance[rows, cols] > roomy)
        )
        labels = self.labels[rows, cols]
        return [
            int(label) if ok else self._region_looked_at(w.x, w.y)
            for w, ok, label in zip(waypoints, clear.tolist(), labels.tolist(), strict=True)
        ]

    def region_at(self, x: float, y: float) -> int:
        row, col = self.costmap.world_to_cell(x, y)
        return int(self.labels[row, col])

    def clearance_at(self, x: float, y: float) -> float:
        """Metres from (x, y) to the nearest blocked cell or the map edge: the smaller of
        the exact distance from the point and its cell's (the planner's) clearance."""
        costmap = self.costmap
        grid = costmap.grid
        resolution = grid.resolution
        reach = costmap.params.circumscribed_radius + resolution
        cell_clearance = costmap.clearance_at(x, y)
        if cell_clearance > reach + resolution:
            return cell_clearance  # the point is within half a diagonal of its cell centre
        gx, gy = grid.world_to_grid(x, y)  # grid units: cell (r, c) spans [c, c+1] x [r, r+1]
        span = int(np.ceil(reach / resolution)) + 1
        row, col = int(np.floor(gy)), int(np.floor(gx))
        top, left = max(row - span, 0), max(col - span, 0)
        values = grid.data[top : row + span + 1, left : col + span + 1]
        if costmap.params.unknown_is_lethal:
            window = blocked_values(values)
            edge = min(gx, gy, grid.width - gx, grid.height - gy)
        else:
            window = (values >= OCCUPIED) | (values < UNKNOWN)
            edge = np.inf
        rows, cols = np.nonzero(window)
        nearest = edge
        if rows.size:
            rows, cols = rows + top, cols + left
            d_col = np.maximum(np.maximum(cols - gx, gx - (cols + 1)), 0.0)
            d_row = np.maximum(np.maximum(rows - gy, gy - (rows + 1)), 0.0)
            nearest = min(nearest, float(np.hypot(d_col, d_row).min()))
        return min(cell_clearance, float(nearest) * resolution)

    def nearest_hint(
        self, x: float, y: float, from_region: int | None
    ) -> tuple[str, tuple[float, float] | None]:
        """``"; the nearest free spot is at (x, y)"`` and that spot, or an explanation
        why there is none and None.

        The spot leaves the robot room to turn with its clearance margin to spare and,
        when ``from_region`` is known, is reachable from where the robot comes from.
        """
        cells = self._roomy_cells
        if from_region is not None and len(cells):
            cells = cells[self.labels[cells[:, 0], cells[:, 1]] == from_region]
        if len(cells) == 0:
            if from_region is not None:
                return (
                    "; no spot reachable from the previous pose leaves the robot room to turn",
                    None,
                )
            return "; the map has no spot where the robot has room to turn", None
        row, col = self.costmap.world_to_cell(x, y)
        nearest = np.argmin(((cells - (row, col)) ** 2).sum(axis=1))
        free_x, free_y = self.costmap.cell_to_world(*cells[nearest])
        # The cell's centre, to the millimetre: still inside the cell (>= 1 cm wide).
        spot = (round(float(free_x), 3), round(float(free_y), 3))
        return f"; the nearest free spot is {_format_position(free_x, free_y)}", spot
