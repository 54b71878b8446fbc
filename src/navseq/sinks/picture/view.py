"""What the mission picture shows and where: the view, the layout, the map and paths.

- :func:`area_of_interest` chooses the part of the world to show (the mission, the
  mapped arena when small, never a far-off typo) and :func:`make_layout` fixes the
  figure's geometry before anything is drawn, so that labels can be placed in pixels;
- :func:`draw_map` draws the occupancy grid cropped to the view and reduced to about a
  cell per pixel, with its edge; :func:`draw_plans` and :func:`draw_trajectory` draw
  the legs' plans and the driven path thinned to the pixels
  (:mod:`navseq.sinks.picture.thin`); :func:`draw_start` the start pose and robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from navseq.geometry import Pose2D
from navseq.sinks.picture.style import (
    AXES_HEIGHT_RANGE,
    AXES_WIDTH,
    BOTTOM,
    DISC,
    GAP,
    LEFT,
    MAP_BORDER_COLOUR,
    PLAN_COLOUR,
    PLAN_SEGMENTS,
    RIGHT,
    SIDE,
    START_COLOUR,
    TOP,
    TRAJECTORY_SEGMENTS,
)
from navseq.sinks.picture.thin import map_image, occupancy_levels, thin_segments

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.collections import LineCollection

    from navseq.mission.robot import RobotProfile
    from navseq.sim.occupancy import OccupancyGrid


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


def occupancy_rgb(data: np.ndarray) -> np.ndarray:
    """RGB image (rows as in ``data``, 0..1) of occupancy values, as the picture shows them."""

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
    # The middle half of the waypoints, widened three times its size (at least 2 m):
    # a spread-out mission is all inside, a lone point 1 km away is not.
    low = np.percentile(waypoints, 25, axis=0)
    high = np.percentile(waypoints, 75, axis=0)
    middle = Box(*low, *high)
    return middle.grown(3.0 * max(middle.width, middle.height, 2.0))


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
class Layout:
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

    def fraction(
        self, rect: tuple[float, float, float, float]
    ) -> tuple[float, float, float, float]:
        """A rectangle in inches as fractions of the figure (what ``add_axes`` takes)."""
        w, h = self.size
        return (rect[0] / w, rect[1] / h, rect[2] / w, rect[3] / h)


def make_layout(box: Box, dpi: float) -> Layout:
    low, high = AXES_HEIGHT_RANGE
    height = min(max(AXES_WIDTH * box.height / box.width, low), high)
    view = box.with_aspect(height / AXES_WIDTH)
    size = (LEFT + AXES_WIDTH + GAP + SIDE + RIGHT, BOTTOM + height + TOP)
    return Layout(view, size, (LEFT, BOTTOM, AXES_WIDTH, height), dpi)


def draw_map(ax: Axes, grid: OccupancyGrid, layout: Layout) -> None:
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
    corners = grid.cells_to_world(
        np.array([0, 0, grid.height, grid.height]) - 0.5,
        np.array([0, grid.width, grid.width, 0]) - 0.5,
    )
    ax.add_patch(
        Polygon(
            corners,
            closed=True,
            fill=False,
            edgecolor=MAP_BORDER_COLOUR,
            linewidth=0.8,
            linestyle=(0, (6, 3)),
            zorder=1.5,
            gid="map-border",
        )
    )


def draw_plans(ax: Axes, plans: list[np.ndarray], layout: Layout) -> bool:
    from matplotlib.collections import LineCollection

    if not plans:
        return False
    gap = np.full((1, 2), np.nan)
    joined = np.concatenate([part for plan in plans for part in (plan, gap)])
    order = np.concatenate([np.full(len(p) + 1, float(i)) for i, p in enumerate(plans)])
    segments, _ = thin_segments(joined, order, layout.scale, PLAN_SEGMENTS)
    if not len(segments):
        return False
    crowded = len(plans) > 50
    ax.add_collection(
        LineCollection(
            cast("Any", segments),  # an (N, 2, 2) array, which matplotlib takes as is
            linestyles=[(0, (4, 3))],
            linewidths=0.7 if crowded else 1.0,
            colors=PLAN_COLOUR,
            alpha=0.45 if crowded else 0.85,
            zorder=2,
        )
    )
    return True


def draw_trajectory(
    ax: Axes, trajectory: np.ndarray, layout: Layout, width: float
) -> LineCollection | None:
    """Driven path coloured by mission time; returns the collection for a colour bar.

    A NaN row is a break (between the segments of a resumed run): no line across it.
    """
    from matplotlib.collections import LineCollection

    if len(trajectory) < 2:
        return None
    segments, times = thin_segments(
        trajectory[:, 1:3], trajectory[:, 0], layout.scale, TRAJECTORY_SEGMENTS
    )
    if not len(segments):
        return None
    lines = LineCollection(
        cast("Any", segments), cmap="viridis", linewidths=width, capstyle="round", zorder=3
    )
    lines.set_array(times)
    ax.add_collection(lines)
    return lines


def pose_arrows(
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


def draw_start(ax: Axes, start: Pose2D, robot: RobotProfile | None, length: float) -> None:
    from matplotlib.patches import Polygon

    if robot is not None:
        outline = _placed_outline(robot, start)
        ax.add_patch(
            Polygon(
                outline,
                closed=True,
                fill=False,
                edgecolor="black",
                linewidth=0.9,
                zorder=6.5,
                gid="robot-outline",
            )
        )
    # Under the waypoint markers and a little larger, so that a waypoint at the
    # start pose (a tour that returns home) stays visible with the square around it.
    pose_arrows(
        ax, np.array([[start.x, start.y]]), np.array([start.yaw]), [START_COLOUR], length, 4.5
    )
    ax.plot(
        start.x,
        start.y,
        marker="s",
        markersize=DISC + 2,
        color=START_COLOUR,
        markeredgecolor="black",
        markeredgewidth=0.8,
        zorder=5.5,
    )


def _placed_outline(robot: RobotProfile, pose: Pose2D) -> list[tuple[float, float]]:
    """The robot's footprint polygon at ``pose``, world coordinates."""
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    return [(pose.x + c * x - s * y, pose.y + s * x + c * y) for x, y in robot.footprint]
