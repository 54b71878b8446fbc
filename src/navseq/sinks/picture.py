"""The mission picture: map, waypoints, planned legs and driven trajectory in one PNG.

Drawn with matplotlib's object API on the Agg canvas (no pyplot, no display needed),
readable from 1 to 100 000 waypoints and drawn in bounded time (a run that got a
signal waits for it):

- the occupancy grid in metres with its true extent and orientation (free white,
  occupied black, unknown grey, as in map_server images and RViz), cropped to the
  view and reduced to about one cell per pixel (:mod:`navseq.sinks.picture_thin`);
- every waypoint coloured by its meaningful outcome (:func:`waypoint_outcomes`):
  reached green, skipped orange, failed red, interrupted pink, not run grey. While
  there is room, each waypoint is a numbered disc with an arrow along its yaw and its
  pass-through radius dashed; a crowded mission gets small dots instead;
- labels that never collide with one another, with the markers that matter or with
  the legend (which sits outside the axes): all of them when they fit, else the
  first, the last, the failures and a spread-out sample (:mod:`~navseq.sinks.picture_labels`);
- waypoints on top of one another drawn as one marker with a count ("×3") and the
  list of their numbers; waypoints outside the view drawn as triangles on its border,
  pointing towards them, with their coordinates;
- each leg's planned path (thin, dashed) and the driven trajectory coloured by time,
  both thinned to what the pixels can show;
- the start pose, a legend and a colour bar beside the map, and a title with the
  mission name and its result.
"""

from __future__ import annotations

import enum
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult
from navseq.files import write_atomically
from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.sinks.picture_labels import LabelPlacer, spread_order
from navseq.sinks.picture_thin import (
    Groups,
    coincident_groups,
    map_image,
    thin_segments,
)
from navseq.text import printable

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from navseq.mission.robot import RobotProfile
    from navseq.sim.occupancy import OccupancyGrid


class Status(str, enum.Enum):
    """What a waypoint's marker says about it (one per waypoint, over all its visits)."""

    REACHED = "reached"
    SKIPPED = "skipped"
    FAILED = "failed"
    INTERRUPTED = "interrupted"  # its only visits were cut short by a signal or crash
    NOT_RUN = "not_run"


STATUS_COLOURS = {
    Status.REACHED: "#2ca02c",
    Status.SKIPPED: "#ff8c00",
    Status.FAILED: "#d62728",
    Status.INTERRUPTED: "#e7298a",
    Status.NOT_RUN: "#8c8c8c",
}
STATUS_LABELS = {
    Status.REACHED: "reached",
    Status.SKIPPED: "skipped (gave up, went on)",
    Status.FAILED: "failed (mission stopped)",
    Status.INTERRUPTED: "interrupted (Ctrl-C, signal)",
    Status.NOT_RUN: "not run",
}
_STATUSES = tuple(Status)
# Markers drawn bottom to top: the ones a reader looks for on top.
_DRAW_ORDER = (Status.NOT_RUN, Status.REACHED, Status.SKIPPED, Status.INTERRUPTED, Status.FAILED)
PLAN_COLOUR = "#1f5fbf"
START_COLOUR = "#7b2cbf"
MAP_BORDER_COLOUR = "#6b7785"

# Layout, inches: the map axes, then the legend and colour bar in a side panel.
_AXES_WIDTH = 7.0
_AXES_HEIGHT_RANGE = (4.2, 9.0)
_LEFT, _GAP, _SIDE, _RIGHT = 0.75, 0.3, 2.1, 0.1
_BOTTOM, _TOP = 0.55, 0.75
# Waypoint markers, points.
_DISC = 15.0  # a numbered disc
_DISC_MIN = 11.0
_DOT_RANGE = (2.5, 8.0)
_NUMBERED_MAX = 300  # more discs than this are never numbered one by one
_DOT_LABELS = 50  # labels shown when the mission is too crowded to label everything
_LABEL_FONT = 7.0
_LABEL_PAD = 0.15  # fraction of the font size, around a label's text
_PLAN_SEGMENTS = 6_000
_DOTS_DRAWN = 10_000  # beyond this, dots covering one another are drawn once
_ALARMING = (Status.FAILED, Status.INTERRUPTED)
_COINCIDENT = 0.02  # m: closer than this, two waypoints are one spot
_TRAJECTORY_SEGMENTS = 12_000

Path2D = Sequence[tuple[float, float]]


@dataclass(frozen=True)
class Box:
    """An axis-aligned rectangle in metres."""

    xmin: float
    ymin: float
    xmax: float
    ymax: float

    @classmethod
    def around(cls, points: np.ndarray) -> Box:
        return cls(*points.min(axis=0), *points.max(axis=0))

    @property
    def width(self) -> float:
        return self.xmax - self.xmin

    @property
    def height(self) -> float:
        return self.ymax - self.ymin

    def grown(self, margin: float) -> Box:
        return Box(self.xmin - margin, self.ymin - margin, self.xmax + margin, self.ymax + margin)

    def union(self, other: Box) -> Box:
        return Box(
            min(self.xmin, other.xmin),
            min(self.ymin, other.ymin),
            max(self.xmax, other.xmax),
            max(self.ymax, other.ymax),
        )

    def clipped(self, other: Box) -> Box:
        return Box(
            max(self.xmin, other.xmin),
            max(self.ymin, other.ymin),
            min(self.xmax, other.xmax),
            min(self.ymax, other.ymax),
        )

    def contains(self, points: np.ndarray) -> np.ndarray:
        x, y = points[:, 0], points[:, 1]
        return (x >= self.xmin) & (x <= self.xmax) & (y >= self.ymin) & (y <= self.ymax)

    def with_aspect(self, ratio: float) -> Box:
        """This box grown about its centre so that height / width == ``ratio``."""
        width, height = self.width, self.height
        if height < ratio * width:
            height = ratio * width
        else:
            width = height / ratio
        cx, cy = (self.xmin + self.xmax) / 2.0, (self.ymin + self.ymax) / 2.0
        return Box(cx - width / 2.0, cy - height / 2.0, cx + width / 2.0, cy + height / 2.0)


# --------------------------------------------------------------------------- outcomes


@dataclass(frozen=True)
class WaypointOutcomes:
    """Per waypoint: its :class:`Status` code and visit counts (arrays of one length).

    ``status[i]`` indexes ``tuple(Status)``; ``reached`` and ``ended`` count the visits
    that reached it and that ran to an end (reached, skipped or failed);
    ``interrupted`` says a visit to it was cut short (the run ended while driving there).
    """

    status: np.ndarray
    reached: np.ndarray
    ended: np.ndarray
    interrupted: np.ndarray

    def __getitem__(self, index: int) -> Status:
        return _STATUSES[int(self.status[index])]

    def __len__(self) -> int:
        return len(self.status)

    def count(self, status: Status) -> int:
        return int(np.count_nonzero(self.status == _STATUSES.index(status)))


# How bad a visit's outcome is (enum members and their values: a result read back
# from JSON may hold either).
_SEVERITY: dict[Any, int] = {
    **{WaypointOutcome.REACHED: 1, WaypointOutcome.SKIPPED: 2, WaypointOutcome.FAILED: 3},
    **{"reached": 1, "skipped": 2, "failed": 3},
}


def _is_interruption(visit: Any) -> bool:
    """A visit ended by a signal or crash, not by the robot: the run's end, not its failure."""
    return str(getattr(visit, "reason", "")).startswith("interrupted")


def waypoint_outcomes(result: MissionResult, count: int) -> WaypointOutcomes:
    """What each waypoint's marker says: the one place the picture reads a result's visits.

    The meaningful outcome of a waypoint is its worst visit that ran to an end: failed,
    else skipped, else reached. A visit cut short by Ctrl-C or a signal is not a
    failure of the waypoint: a patrol point reached 1806 times and interrupted once is
    reached (drawn with an "interrupted here" ring), and a waypoint whose only visit
    was interrupted is *interrupted*, not failed. Never visited: not run.
    """
    worst = np.zeros(count, dtype=np.int8)
    reached = np.zeros(count, dtype=np.int64)
    ended = np.zeros(count, dtype=np.int64)
    interrupted = np.zeros(count, dtype=bool)
    for visit in result.visits:
        index = visit.index
        severity = _SEVERITY.get(visit.outcome, 0)  # 0: not run
        if severity == 0 or not 0 <= index < count:
            continue
        if severity == 3 and _is_interruption(visit):
            interrupted[index] = True
            continue
        ended[index] += 1
        if severity == 1:
            reached[index] += 1
        if severity > worst[index]:
            worst[index] = severity
    code = {status: _STATUSES.index(status) for status in Status}
    status = np.select(
        [worst == 3, worst == 2, worst == 1, interrupted],
        [code[Status.FAILED], code[Status.SKIPPED], code[Status.REACHED], code[Status.INTERRUPTED]],
        default=code[Status.NOT_RUN],
    ).astype(np.int8)
    return WaypointOutcomes(status, reached, ended, interrupted)


# --------------------------------------------------------------------------- the view


def occupancy_rgb(data: np.ndarray) -> np.ndarray:
    """RGB image (rows as in ``data``, 0..1) of occupancy values, as the picture shows them."""
    from navseq.sinks.picture_thin import occupancy_levels

    grey = occupancy_levels(data).astype(np.float32) / 255.0
    return np.repeat(grey[:, :, None], 3, axis=2)


def _known_box(grid: OccupancyGrid) -> Box | None:
    """The world box around every mapped (not unknown) cell, or None if all are unknown."""
    known = grid.data != -1
    rows = np.flatnonzero(known.any(axis=1))
    cols = np.flatnonzero(known.any(axis=0))
    if rows.size == 0:
        return None
    corners_rows = np.array([rows[0], rows[0], rows[-1] + 1, rows[-1] + 1]) - 0.5
    corners_cols = np.array([cols[0], cols[-1] + 1, cols[0], cols[-1] + 1]) - 0.5
    return Box.around(grid.cells_to_world(corners_rows, corners_cols))


def _map_box(grid: OccupancyGrid) -> Box:
    return Box(*grid.bounds)


def _reach(waypoints: np.ndarray, grid: OccupancyGrid | None) -> Box:
    """How far the view may extend: the map and a margin, or the bulk of the mission.

    Waypoints beyond it (a typo, a point 1 km off the map) are drawn on the view's
    border instead of shrinking everything else to a speck.
    """
    if grid is not None:
        box = _map_box(grid)
        return box.grown(max(2.0, 0.25 * max(box.width, box.height)))
    if len(waypoints) == 0:
        return Box(-math.inf, -math.inf, math.inf, math.inf)
    low = np.percentile(waypoints, 2, axis=0)
    high = np.percentile(waypoints, 98, axis=0)
    bulk = Box(*low, *high)
    return bulk.grown(max(5.0, 2.0 * max(bulk.width, bulk.height)))


def area_of_interest(
    mission_points: np.ndarray, grid: OccupancyGrid | None, waypoints: np.ndarray | None = None
) -> Box:
    """What to show: the mission with a margin, plus the mapped area if it is not huge.

    A small arena is shown whole (its walls give the mission context); on a large
    map only the neighbourhood of the mission is shown. Points beyond the map's
    surroundings (or, without a map, far from the bulk of the mission) do not widen
    the view: they are drawn on its border.
    """
    reach = _reach(mission_points if waypoints is None else waypoints, grid)
    near = mission_points[reach.contains(mission_points)] if len(mission_points) else mission_points
    if len(near) == 0:
        near = np.array([[(reach.xmin + reach.xmax) / 2, (reach.ymin + reach.ymax) / 2]])
        if not np.isfinite(near).all():
            near = np.zeros((1, 2))
    box = Box.around(near)
    margin = max(0.5, 0.12 * max(box.width, box.height))
    box = box.grown(margin)
    if grid is not None:
        known = _known_box(grid)
        if known is not None and known.width * known.height <= 4.0 * box.width * box.height:
            box = box.union(known.grown(2 * grid.resolution))
        # Not beyond the map, unless the mission itself is.
        limit = _map_box(grid)
        off_map = near[~limit.contains(near)]
        if len(off_map):
            limit = limit.union(Box.around(off_map).grown(margin))
        box = box.clipped(limit)
    # Never a degenerate box (a single waypoint on a map that does not contain it).
    if not (box.width > 0 and box.height > 0):
        box = Box.around(near).grown(1.0)
    return box


@dataclass(frozen=True)
class _Layout:
    """Where everything goes, fixed before drawing (so labels can be placed in pixels)."""

    view: Box
    size: tuple[float, float]  # figure, inches
    axes: tuple[float, float, float, float]  # map axes: left, bottom, width, height (inches)
    dpi: float

    @property
    def scale(self) -> float:
        """Display pixels per metre."""
        return self.axes[2] * self.dpi / self.view.width

    def to_pixels(self, points: np.ndarray) -> np.ndarray:
        origin = np.array([self.axes[0], self.axes[1]]) * self.dpi
        return (points - np.array([self.view.xmin, self.view.ymin])) * self.scale + origin

    def to_world(self, x: float, y: float) -> tuple[float, float]:
        return (
            self.view.xmin + (x - self.axes[0] * self.dpi) / self.scale,
            self.view.ymin + (y - self.axes[1] * self.dpi) / self.scale,
        )

    @property
    def axes_pixels(self) -> tuple[float, float, float, float]:
        left, bottom, width, height = (v * self.dpi for v in self.axes)
        return left, bottom, left + width, bottom + height

    def fraction(self, rect: tuple[float, float, float, float]) -> tuple[float, ...]:
        w, h = self.size
        return (rect[0] / w, rect[1] / h, rect[2] / w, rect[3] / h)


def _layout(box: Box, dpi: float) -> _Layout:
    low, high = _AXES_HEIGHT_RANGE
    height = min(max(_AXES_WIDTH * box.height / box.width, low), high)
    view = box.with_aspect(height / _AXES_WIDTH)
    size = (_LEFT + _AXES_WIDTH + _GAP + _SIDE + _RIGHT, _BOTTOM + height + _TOP)
    return _Layout(view, size, (_LEFT, _BOTTOM, _AXES_WIDTH, height), dpi)


# --------------------------------------------------------------------------- drawing


def _draw_map(ax: Axes, grid: OccupancyGrid, layout: _Layout) -> None:
    """The map, cropped to the view (unless rotated) and reduced to about a cell a pixel."""
    from matplotlib.patches import Polygon
    from matplotlib.transforms import Affine2D

    rows, cols = slice(0, grid.height), slice(0, grid.width)
    if not grid.origin.yaw:
        view = layout.view
        c0 = max(0, math.floor((view.xmin - grid.origin.x) / grid.resolution) - 1)
        c1 = min(grid.width, math.ceil((view.xmax - grid.origin.x) / grid.resolution) + 1)
        r0 = max(0, math.floor((view.ymin - grid.origin.y) / grid.resolution) - 1)
        r1 = min(grid.height, math.ceil((view.ymax - grid.origin.y) / grid.resolution) + 1)
        rows, cols = slice(r0, max(r0, r1)), slice(c0, max(c0, c1))
    cells_per_pixel = 1.0 / (grid.resolution * layout.scale)
    image, factor = map_image(grid.data, rows, cols, cells_per_pixel)
    if image.size:
        step = grid.resolution * factor
        x0 = grid.origin.x + (cols.start or 0) * grid.resolution
        y0 = grid.origin.y + (rows.start or 0) * grid.resolution
        extent = (x0, x0 + image.shape[1] * step, y0, y0 + image.shape[0] * step)
        artist = ax.imshow(
            image,
            cmap="gray",
            vmin=0,
            vmax=255,
            origin="lower",  # row 0 of the grid is the bottom of the map
            extent=extent,
            interpolation="nearest",
            zorder=0,
        )
        if grid.origin.yaw:
            rotation = Affine2D().rotate_around(grid.origin.x, grid.origin.y, grid.origin.yaw)
            artist.set_transform(rotation + ax.transData)
    # The map's edge, so that a waypoint beyond it is seen to be off the map.
    corners = grid.cells_to_world(np.array([0, 0, grid.height, grid.height]) - 0.5, np.array([0, grid.width, grid.width, 0]) - 0.5)
    ax.add_patch(
        Polygon(
            corners,
            closed=True,
            fill=False,
            edgecolor=MAP_BORDER_COLOUR,
            linewidth=0.8,
            linestyle=(0, (6, 3)),
            zorder=1.5,
        )
    )


def _draw_plans(ax: Axes, plans: list[np.ndarray], layout: _Layout) -> bool:
    from matplotlib.collections import LineCollection

    if not plans:
        return False
    gap = np.full((1, 2), np.nan)
    joined = np.concatenate([part for plan in plans for part in (plan, gap)])
    order = np.concatenate([np.full(len(p) + 1, float(i)) for i, p in enumerate(plans)])
    segments, _ = thin_segments(joined, order, layout.scale, _PLAN_SEGMENTS)
    if not len(segments):
        return False
    crowded = len(plans) > 50
    ax.add_collection(
        LineCollection(
            segments,
            linestyles=[(0, (4, 3))],
            linewidths=0.7 if crowded else 1.0,
            colors=PLAN_COLOUR,
            alpha=0.45 if crowded else 0.85,
            zorder=2,
        )
    )
    return True


def _draw_trajectory(ax: Axes, trajectory: np.ndarray, layout: _Layout) -> LineCollection | None:
    """Driven path coloured by mission time; returns the collection for a colour bar.

    A NaN row is a break (between the segments of a resumed run): no line across it.
    """
    from matplotlib.collections import LineCollection

    if len(trajectory) < 2:
        return None
    segments, times = thin_segments(
        trajectory[:, 1:3], trajectory[:, 0], layout.scale, _TRAJECTORY_SEGMENTS
    )
    if not len(segments):
        return None
    lines = LineCollection(segments, cmap="viridis", linewidths=2.4, capstyle="round", zorder=3)
    lines.set_array(times)
    ax.add_collection(lines)
    return lines


def _pose_arrows(
    ax: Axes, points: np.ndarray, yaws: np.ndarray, colours: list[str], length: float, zorder: float
) -> None:
    """Arrows along each waypoint's yaw, ``length`` metres, in one collection."""
    if not len(points):
        return
    width = 0.08 * length
    ax.quiver(
        points[:, 0],
        points[:, 1],
        length * np.cos(yaws),
        length * np.sin(yaws),
        color=colours,
        angles="xy",
        scale_units="xy",
        scale=1.0,
        units="xy",
        width=width,
        headwidth=3.2,
        headlength=3.0,
        headaxislength=2.7,
        edgecolor="black",
        linewidth=0.6,
        zorder=zorder,
    )


def _draw_start(ax: Axes, start: Pose2D, robot: RobotProfile | None, length: float) -> None:
    from matplotlib.patches import Polygon

    if robot is not None:
        outline = _placed_outline(robot, start)
        ax.add_patch(
            Polygon(outline, closed=True, fill=False, edgecolor="black", linewidth=0.9, zorder=6.5)
        )
    # Under the waypoint markers and a little larger, so that a waypoint at the
    # start pose (a tour that returns home) stays visible with the square around it.
    _pose_arrows(
        ax, np.array([[start.x, start.y]]), np.array([start.yaw]), [START_COLOUR], length, 4.5
    )
    ax.plot(
        start.x,
        start.y,
        marker="s",
        markersize=_DISC + 2,
        color=START_COLOUR,
        markeredgecolor="black",
        markeredgewidth=0.8,
        zorder=5.5,
    )


def _placed_outline(robot: RobotProfile, pose: Pose2D) -> list[tuple[float, float]]:
    """The robot's footprint polygon at ``pose``, world coordinates."""
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    return [(pose.x + c * x - s * y, pose.y + s * x + c * y) for x, y in robot.footprint]


def _numbers(members: np.ndarray, most: int = 5) -> str:
    shown = ", ".join(str(int(i) + 1) for i in members[:most])
    return shown + (", …" if len(members) > most else "")


@dataclass
class _Markers:
    """The waypoint markers as drawn: one per group, in the view or on its border."""

    groups: Groups
    points: np.ndarray  # (G, 2) world position of each marker
    pixels: np.ndarray  # (G, 2) display pixels
    status: np.ndarray  # (G,) worst status code of the members
    inside: np.ndarray  # (G,) True: in the view; False: on the border
    numbered: bool
    size: float  # marker diameter, points
    spacing: float  # median distance between neighbouring markers, points


def _group_status(outcomes: WaypointOutcomes, groups: Groups) -> np.ndarray:
    """A group's status: its most alarming member's (the draw order's last)."""
    rank = np.array([_DRAW_ORDER.index(s) for s in _STATUSES])[outcomes.status]
    worst = np.zeros(len(groups), dtype=np.int64)
    np.maximum.at(worst, groups.of, rank)
    return np.array([_STATUSES.index(_DRAW_ORDER[r]) for r in range(len(_DRAW_ORDER))])[worst]


def _markers(
    positions: np.ndarray, outcomes: WaypointOutcomes, layout: _Layout, dpi: float
) -> _Markers:
    """Group the waypoints into markers and choose numbered discs or dots.

    Numbered discs while there are at most a few hundred and most are a disc apart;
    discs that would overlap by more than half are one marker with a count. Else dots,
    sized to the typical spacing, grouped only when they fall on the same pixels.
    """
    from scipy.spatial import cKDTree

    view = layout.view
    inset = 0.5 * _DISC / 72.0 * dpi / layout.scale  # metres: a marker's radius
    inside_each = view.contains(positions)
    # A waypoint beyond the view is drawn on its border, just inside.
    border = np.column_stack(
        (
            np.clip(positions[:, 0], view.xmin + inset, view.xmax - inset),
            np.clip(positions[:, 1], view.ymin + inset, view.ymax - inset),
        )
    )
    clipped = np.where(inside_each[:, None], positions, border)
    pixel = 72.0 / dpi  # points per pixel
    metres_per_point = 1.0 / (layout.scale * pixel)
    fine = coincident_groups(clipped, 2.0 / layout.scale)
    spacing = np.inf
    if len(fine) > 1:
        reps = layout.to_pixels(clipped[fine.first])
        # The median over a sample is as good as over all, and bounded in time.
        sample = reps[:: max(1, len(reps) // 5000)]
        distances, _ = cKDTree(reps).query(sample, k=2)
        spacing = float(np.median(distances[:, 1])) * pixel  # points
    numbered = len(fine) <= _NUMBERED_MAX and spacing >= _DISC_MIN * 1.3
    if numbered:
        size = _DISC if spacing >= _DISC * 1.3 else _DISC_MIN
        groups = coincident_groups(clipped, 0.5 * size * metres_per_point)
    else:
        size = float(np.clip(0.5 * spacing, *_DOT_RANGE))
        # Only waypoints really at one spot (a route through one point twice) count as
        # coincident here; dots a few centimetres apart simply overlap.
        groups = coincident_groups(clipped, min(2.0 / layout.scale, _COINCIDENT))
    points = clipped[groups.first]
    inside = np.zeros(len(groups), dtype=bool)
    np.logical_or.at(inside, groups.of, inside_each)
    return _Markers(
        groups=groups,
        points=points,
        pixels=layout.to_pixels(points),
        status=_group_status(outcomes, groups),
        inside=inside,
        numbered=numbered,
        size=size,
        spacing=spacing,
    )


def _draw_markers(
    ax: Axes,
    markers: _Markers,
    outcomes: WaypointOutcomes,
    positions: np.ndarray,
    layout: _Layout,
) -> None:
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Polygon

    inside = markers.inside
    drawn = _thinned_dots(markers, layout) if not markers.numbered else inside
    # Dots packed tighter than their size lose their edges, or the crowd turns black.
    dense = not markers.numbered and markers.spacing < 2.0 * markers.size
    edge = 0.8 if markers.numbered else (0.0 if dense else 0.3)
    for status in _DRAW_ORDER:
        chosen = drawn & (markers.status == _STATUSES.index(status))
        if not chosen.any():
            continue
        # Dots that need attention are drawn larger than the crowd of reached ones.
        size, line = markers.size, edge
        if not markers.numbered and status in _ALARMING:
            size, line = max(2.0 * markers.size, 6.0), 0.8
        elif not markers.numbered and status is Status.SKIPPED and not dense:
            size = 1.3 * markers.size
        ax.scatter(
            markers.points[chosen, 0],
            markers.points[chosen, 1],
            s=size**2,
            c=STATUS_COLOURS[status],
            edgecolors="black",
            linewidths=line,
            zorder=6 + 0.01 * _DRAW_ORDER.index(status),
        )
    # Groups get a thick black ring: several waypoints under one marker.
    several = inside & (markers.groups.sizes > 1)
    if several.any() and not markers.numbered:
        ax.scatter(
            markers.points[several, 0],
            markers.points[several, 1],
            s=(markers.size + 3) ** 2,
            facecolors="none",
            edgecolors="black",
            linewidths=1.2,
            zorder=6.1,
        )
    # "Interrupted here": the waypoint being driven to when the run was cut short.
    ring = np.zeros(len(markers.groups), dtype=bool)
    np.logical_or.at(ring, markers.groups.of, outcomes.interrupted)
    if ring.any():
        ax.scatter(
            markers.points[ring, 0],
            markers.points[ring, 1],
            s=(markers.size + 7) ** 2,
            facecolors="none",
            edgecolors=STATUS_COLOURS[Status.INTERRUPTED],
            linewidths=2.2,
            zorder=5.9,
        )
    # Off the view: a triangle on the border, pointing at the waypoint.
    outside = np.flatnonzero(~inside)
    if len(outside):
        metres = _DISC / 72.0 * layout.dpi / layout.scale * 0.6
        triangles = []
        colours = []
        for group in outside:
            member = markers.groups.first[group]
            tip = markers.points[group]
            dx, dy = positions[member] - tip
            angle = math.atan2(dy, dx)
            c, s = math.cos(angle), math.sin(angle)
            shape = np.array([(1.0, 0.0), (-0.6, 0.7), (-0.6, -0.7)]) * metres
            triangles.append(
                Polygon(tip + shape @ np.array([[c, s], [-s, c]]), closed=True)
            )
            colours.append(STATUS_COLOURS[_STATUSES[int(markers.status[group])]])
        ax.add_collection(
            PatchCollection(
                triangles, facecolors=colours, edgecolors="black", linewidths=0.8, zorder=6.5
            )
        )


def _thinned_dots(markers: _Markers, layout: _Layout) -> np.ndarray:
    """Which dots to draw: one per status in each dot-sized cell, when there are very many.

    Dots that would cover one another to the pixel add nothing to the picture but
    drawing time; the most alarming status of a cell is drawn last, on top.
    """
    inside = markers.inside
    if np.count_nonzero(inside) <= _DOTS_DRAWN:
        return inside
    cell = markers.size / 72.0 * layout.dpi
    cells = np.floor(markers.pixels / cell).astype(np.int64)
    cells -= cells.min(axis=0)
    span = int(cells.max()) + 1
    keys = (cells[:, 0] * span + cells[:, 1]) * len(_STATUSES) + markers.status
    keys = np.where(inside, keys, -1)
    _, first = np.unique(keys, return_index=True)
    drawn = np.zeros(len(inside), dtype=bool)
    drawn[first] = True
    return drawn & inside


def _draw_numbered_details(
    ax: Axes,
    mission: Mission,
    markers: _Markers,
    waypoints: np.ndarray,
    yaws: np.ndarray,
    layout: _Layout,
) -> bool:
    """Numbers in the discs, yaw arrows and pass-through radii; True if a radius was drawn."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle

    groups = markers.groups
    shown = np.flatnonzero(markers.inside)
    colours = [STATUS_COLOURS[_STATUSES[int(markers.status[g])]] for g in shown]
    length = 1.8 * markers.size / 72.0 * layout.dpi / layout.scale
    members = groups.first[shown]
    _pose_arrows(ax, waypoints[members], yaws[members], colours, length, 5.0)
    circles, circle_colours = [], []
    last = len(mission.waypoints) - 1
    for group, colour in zip(shown, colours, strict=True):
        first = int(groups.first[group])
        size = int(groups.sizes[group])
        text = str(first + 1) if size == 1 else f"×{size}"
        digits = len(text)
        ax.text(
            *markers.points[group],
            text,
            ha="center",
            va="center",
            fontsize=(7.5 if digits <= 2 else 6.0) * markers.size / _DISC,
            fontweight="bold",
            color="white",
            zorder=7,
        )
        policy = mission.policy_for(first)
        if policy.pass_through and first != last and policy.dwell == 0:
            circles.append(Circle(tuple(waypoints[first]), policy.pass_through))
            circle_colours.append(colour)
    if circles:
        ax.add_collection(
            PatchCollection(
                circles,
                facecolors="none",
                edgecolors=circle_colours,
                linestyles=[(0, (2, 2))],
                linewidths=1.0,
                zorder=4,
            )
        )
    return bool(circles)


def _label_text(
    mission: Mission, markers: _Markers, group: int, positions: np.ndarray
) -> str | None:
    """What a marker's label says, or None when a numbered disc says it all already."""
    groups = markers.groups
    first = int(groups.first[group])
    name = mission.waypoints[first].name
    name_text = printable(name)[:28] if name else ""
    if groups.sizes[group] > 1:
        numbers = _numbers(groups.members(group))
        text = f"{numbers}" if markers.numbered else f"×{groups.sizes[group]}: {numbers}"
    elif markers.numbered:
        text = name_text
    else:
        text = f"{first + 1} {name_text}".strip()
    if not markers.inside[group]:
        x, y = positions[first]
        text = f"{text or first + 1} at ({x:.1f}, {y:.1f})".strip()
    return text or None


def _place_labels(
    ax: Axes,
    fig: Figure,
    mission: Mission,
    markers: _Markers,
    outcomes: WaypointOutcomes,
    positions: np.ndarray,
    layout: _Layout,
    obstacles: np.ndarray,
) -> int:
    """Place and draw the labels (see the module doc); returns how many were drawn."""
    from matplotlib.font_manager import FontProperties

    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    font = FontProperties(size=_LABEL_FONT)
    pad = 2 * _LABEL_PAD * _LABEL_FONT / 72.0 * layout.dpi

    def measure(text: str) -> tuple[float, float]:
        width, height, _ = renderer.get_text_width_height_descent(text, font, ismath=False)
        return width + pad, height + pad

    count = len(markers.groups)
    placer = LabelPlacer(
        area=layout.axes_pixels, measure=measure, limit=count if markers.numbered else _DOT_LABELS
    )
    radius_px = 0.5 * markers.size / 72.0 * layout.dpi + 1.5
    if markers.numbered:
        placer.block(_square(markers.pixels, radius_px))
    placer.block(obstacles)
    group_status = markers.status
    code = {status: _STATUSES.index(status) for status in Status}
    ring = np.zeros(count, dtype=bool)
    np.logical_or.at(ring, markers.groups.of, outcomes.interrupted)
    everyone = np.arange(count)
    tiers = [
        everyone[:1],
        everyone[markers.groups.of[-1:]] if len(positions) else everyone[:0],
        everyone[group_status == code[Status.FAILED]],
        everyone[(group_status == code[Status.INTERRUPTED]) | ring],
        everyone[~markers.inside],
        everyone[group_status == code[Status.SKIPPED]],
        everyone[markers.groups.sizes > 1],
        everyone[[bool(mission.waypoints[int(f)].name) for f in markers.groups.first]]
        if markers.numbered or count <= 5000
        else everyone[:0],
        everyone,
    ]
    done = np.zeros(count, dtype=bool)
    for tier in tiers:
        todo = tier[~done[tier]]
        if not len(todo):
            continue
        room = placer.limit - len(placer.placed)
        if room <= 0:
            break
        taken = np.array([(p.x, p.y) for p in placer.placed]).reshape(-1, 2)
        order = (
            todo.tolist()
            if markers.numbered
            else spread_order(markers.pixels, todo.tolist(), taken, 4 * room)
        )
        for group in order:
            done[group] = True
            text = _label_text(mission, markers, group, positions)
            if text is None:
                continue
            x, y = markers.pixels[group]
            if placer.place(group, text, x, y, radius_px) and not markers.numbered:
                placer.block(_square(markers.pixels[group : group + 1], radius_px))
    for label in placer.placed:
        ax.text(
            *layout.to_world(label.x, label.y),
            label.text,
            ha="center",
            va="center",
            fontsize=_LABEL_FONT,
            color="#222222",
            zorder=8,
            bbox={
                "boxstyle": f"round,pad={_LABEL_PAD}",
                "facecolor": "white",
                "edgecolor": "none",
                "alpha": 0.8,
            },
            gid="waypoint-label",
        )
    return len(placer.placed)


def _square(pixels: np.ndarray, radius: float) -> np.ndarray:
    return np.column_stack(
        (pixels[:, 0] - radius, pixels[:, 1] - radius, pixels[:, 0] + radius, pixels[:, 1] + radius)
    )


def _title(mission: Mission, result: MissionResult, outcomes: WaypointOutcomes, interrupted: str | None) -> str:
    name = printable(Path(mission.source).stem) if mission.source else "mission"
    visits = int(outcomes.ended.sum() + outcomes.interrupted.sum())
    verdict = (
        "success"
        if result.success
        else (f"interrupted ({interrupted})" if interrupted else result.reason)
    )
    count = len(outcomes)
    return (
        f"{name} — {printable(verdict)}\n"
        f"{count:,} waypoint{'s' if count != 1 else ''} · "
        f"{int(outcomes.reached.sum()):,}/{visits:,} visits reached · {result.duration:.1f} s · "
        f"{result.distance_driven:.1f} m driven"
    )


def draw_mission_picture(
    path: Path, mission: Mission, result: MissionResult, **drawing: Any
) -> None:
    """Draw the run into a PNG at ``path`` (written atomically: temp file, then rename).

    ``drawing`` takes the keyword arguments of :func:`mission_picture_png`.
    """
    png = mission_picture_png(mission, result, **drawing)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, png)


def mission_picture_png(
    mission: Mission,
    result: MissionResult,
    *,
    grid: OccupancyGrid | None = None,
    start: Pose2D | None = None,
    plans: Sequence[Path2D] = (),
    trajectory: Sequence[tuple[float, float, float]] = (),
    interrupted: str | None = None,
    dpi: int = 150,
    robot: RobotProfile | None = None,
) -> bytes:
    """The picture of the run as PNG bytes.

    ``plans`` are the legs' planned paths (x, y) and ``trajectory`` the driven
    positions as (t, x, y) with t in mission-clock seconds; a row of NaNs breaks the
    line (a resumed run's segments: the robot may not have been where it stopped).
    """
    fig = mission_figure(
        mission,
        result,
        grid=grid,
        start=start,
        plans=plans,
        trajectory=trajectory,
        interrupted=interrupted,
        dpi=dpi,
        robot=robot,
    )
    png = io.BytesIO()
    # The layout is fixed (legend and colour bar in their own panel): no "tight"
    # bounding box, which would draw the whole figure twice.
    fig.savefig(png, format="png")
    return png.getvalue()


def mission_figure(
    mission: Mission,
    result: MissionResult,
    *,
    grid: OccupancyGrid | None = None,
    start: Pose2D | None = None,
    plans: Sequence[Path2D] = (),
    trajectory: Sequence[tuple[float, float, float]] = (),
    interrupted: str | None = None,
    dpi: int = 150,
    robot: RobotProfile | None = None,
) -> Figure:
    """The picture as a matplotlib Figure on an Agg canvas (its first axes is the map).

    With ``robot``, its outline is drawn to scale at the start pose, so a reader sees
    how much room the robot needs in the map's corridors.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    count = len(mission.waypoints)
    positions = np.array([(w.x, w.y) for w in mission.waypoints], dtype=float).reshape(-1, 2)
    yaws = np.array([w.yaw for w in mission.waypoints], dtype=float)
    traj = np.asarray(trajectory, dtype=float).reshape(-1, 3)
    plan_arrays = [np.asarray(p, dtype=float).reshape(-1, 2) for p in plans if len(p) > 1]
    driven = traj[np.isfinite(traj).all(axis=1), 1:3]
    point_sets = [positions, driven, *plan_arrays]
    if start is not None:
        point_sets.append(np.array([[start.x, start.y]]))
    all_points = np.concatenate([p for p in point_sets if len(p)] or [np.zeros((1, 2))])
    layout = _layout(area_of_interest(all_points, grid, positions if count else None), dpi)
    view = layout.view

    fig = Figure(figsize=layout.size, dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_axes(layout.fraction(layout.axes))
    ax.set_facecolor("white")
    ax.set_xlim(view.xmin, view.xmax)
    ax.set_ylim(view.ymin, view.ymax)
    ax.set_aspect("equal")
    if grid is not None:
        _draw_map(ax, grid, layout)
    drew_plans = _draw_plans(ax, plan_arrays, layout)
    lines = _draw_trajectory(ax, traj, layout)

    outcomes = waypoint_outcomes(result, count)
    drew_radius = False
    labels = 0
    markers = None
    if count:
        markers = _markers(positions, outcomes, layout, dpi)
        _draw_markers(ax, markers, outcomes, positions, layout)
        if markers.numbered:
            drew_radius = _draw_numbered_details(ax, mission, markers, positions, yaws, layout)
    arrow_length = 1.8 * _DISC / 72.0 * dpi / layout.scale
    obstacles = np.zeros((0, 4))
    if start is not None:
        _draw_start(ax, start, robot, arrow_length)
        start_px = layout.to_pixels(np.array([[start.x, start.y]]))
        obstacles = _square(start_px, 0.5 * (_DISC + 2) / 72.0 * dpi)
    if markers is not None:
        labels = _place_labels(ax, fig, mission, markers, outcomes, positions, layout, obstacles)

    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#9aa5b1", linewidth=0.4, alpha=0.5, zorder=1)
    ax.set_axisbelow(False)
    ax.set_title(_title(mission, result, outcomes, interrupted), fontsize=10, loc="left")
    _side_panel(
        fig,
        layout,
        outcomes,
        markers,
        labels=labels,
        start=start,
        robot=robot,
        drew_plans=drew_plans,
        drew_radius=drew_radius,
        lines=lines,
    )
    return fig


def _side_panel(
    fig: Figure,
    layout: _Layout,
    outcomes: WaypointOutcomes,
    markers: _Markers | None,
    *,
    labels: int,
    start: Pose2D | None,
    robot: RobotProfile | None,
    drew_plans: bool,
    drew_radius: bool,
    lines: LineCollection | None,
) -> None:
    """Legend (top) and time colour bar (bottom) beside the map, never over it."""
    from matplotlib.lines import Line2D

    left = _LEFT + _AXES_WIDTH + _GAP
    bottom, height = layout.axes[1], layout.axes[3]
    dot = 9 if markers is None or markers.numbered else 7
    handles: list[Any] = [
        Line2D(
            [],
            [],
            marker="o",
            linestyle="none",
            markersize=dot,
            color=STATUS_COLOURS[s],
            markeredgecolor="black",
            label=STATUS_LABELS[s]
            + ("" if len(outcomes) <= 1 else f" ({outcomes.count(s):,})"),
        )
        for s in Status
        if outcomes.count(s) or s is Status.REACHED
    ]
    if outcomes.interrupted.any() and outcomes.count(Status.INTERRUPTED) < int(
        outcomes.interrupted.sum()
    ):
        handles.append(
            Line2D(
                [],
                [],
                marker="o",
                linestyle="none",
                markersize=dot + 3,
                fillstyle="none",
                markeredgewidth=2.0,
                markeredgecolor=STATUS_COLOURS[Status.INTERRUPTED],
                label="interrupted here",
            )
        )
    if markers is not None and (markers.groups.sizes[markers.inside] > 1).any():
        handles.append(
            Line2D(
                [],
                [],
                marker="o",
                linestyle="none",
                markersize=dot,
                color="white",
                markeredgecolor="black",
                markeredgewidth=1.5,
                label="×n: waypoints at one spot",
            )
        )
    if markers is not None and not markers.inside.all():
        handles.append(
            Line2D(
                [],
                [],
                marker=">",
                linestyle="none",
                markersize=dot,
                color="white",
                markeredgecolor="black",
                label="beyond the view (points to it)",
            )
        )
    if start is not None:
        handles.append(
            Line2D(
                [],
                [],
                marker="s",
                linestyle="none",
                markersize=8,
                color=START_COLOUR,
                markeredgecolor="black",
                label="start",
            )
        )
    if start is not None and robot is not None:
        handles.append(Line2D([], [], color="black", linewidth=0.9, label=f"{robot.name} outline"))
    if drew_plans:
        handles.append(
            Line2D([], [], linestyle=(0, (4, 3)), color=PLAN_COLOUR, label="planned path")
        )
    if drew_radius:
        handles.append(
            Line2D(
                [],
                [],
                marker="o",
                markersize=11,
                fillstyle="none",
                linestyle="none",
                markeredgecolor="#555555",
                label="pass-through radius",
            )
        )
    if lines is not None:
        handles.append(Line2D([], [], linewidth=2.4, color="#21918c", label="driven path"))
    side = fig.add_axes(layout.fraction((left, bottom, _SIDE, height)))
    side.set_axis_off()
    title = None
    if markers is not None and not markers.numbered:
        title = f"{labels} of {len(outcomes):,} waypoints labelled"
    side.legend(
        handles=handles,
        loc="upper left",
        borderaxespad=0.0,
        fontsize=7.5,
        frameon=False,
        title=title,
        title_fontsize=7.5,
        alignment="left",
    )
    if lines is not None:
        bar_height = min(0.4 * height, 2.6)
        cax = fig.add_axes(layout.fraction((left + 0.05, bottom, 0.15, bar_height)))
        bar = fig.colorbar(lines, cax=cax)
        bar.set_label("mission time [s]", fontsize=8)
        bar.ax.tick_params(labelsize=7)
