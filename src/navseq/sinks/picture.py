"""The mission picture: map, waypoints, planned legs and driven trajectory in one PNG.

Drawn with matplotlib's object API on the Agg canvas (no pyplot, no display needed):

- the occupancy grid in metres with its true extent and orientation (free white,
  occupied black, unknown grey, as in map_server images and RViz);
- every waypoint numbered, with an arrow along its yaw, coloured by outcome (reached
  green, skipped orange, failed red, not run grey) and its pass-through radius dashed;
- each leg's planned path (thin, dashed) and the driven trajectory coloured by time;
- the start pose, a legend, and a title with the mission name and its result;
- the view cropped to the area of interest (the mission plus the mapped surroundings).
"""

from __future__ import annotations

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
from navseq.text import printable

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from navseq.mission.robot import RobotProfile
    from navseq.sim.occupancy import OccupancyGrid

OUTCOME_COLOURS = {
    WaypointOutcome.REACHED: "#2ca02c",
    WaypointOutcome.SKIPPED: "#ff8c00",
    WaypointOutcome.FAILED: "#d62728",
    WaypointOutcome.NOT_RUN: "#8c8c8c",
}
OUTCOME_LABELS = {
    WaypointOutcome.REACHED: "reached",
    WaypointOutcome.SKIPPED: "skipped",
    WaypointOutcome.FAILED: "failed",
    WaypointOutcome.NOT_RUN: "not run",
}
# How bad an outcome is, to colour a patrol waypoint by its worst visit.
_SEVERITY = {
    WaypointOutcome.NOT_RUN: 0,
    WaypointOutcome.REACHED: 1,
    WaypointOutcome.SKIPPED: 2,
    WaypointOutcome.FAILED: 3,
}
PLAN_COLOUR = "#1f5fbf"
START_COLOUR = "#7b2cbf"
UNKNOWN_GREY = 205 / 255  # map_server writes unknown cells as 205
OCCUPIED_GREY = 0.12

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


def waypoint_outcomes(result: MissionResult, count: int) -> list[WaypointOutcome]:
    """One outcome per waypoint: its worst visit that ran (not run if none ran)."""
    outcomes = [WaypointOutcome.NOT_RUN] * count
    for visit in result.visits:
        if 0 <= visit.index < count:
            outcome = WaypointOutcome(visit.outcome)
            if _SEVERITY[outcome] > _SEVERITY[outcomes[visit.index]]:
                outcomes[visit.index] = outcome
    return outcomes


def occupancy_rgb(data: np.ndarray) -> np.ndarray:
    """RGB image (rows as in ``data``) of occupancy values: 0 white .. 100 black, -1 grey."""
    values = np.clip(data.astype(np.float32), 0.0, 100.0)
    grey = 1.0 - (1.0 - OCCUPIED_GREY) * values / 100.0
    # Only -1 is unknown; other negative values (raw mode) are obstacles to costmap_2d.
    grey = np.where(data == -1, UNKNOWN_GREY, np.where(data < -1, OCCUPIED_GREY, grey))
    return np.repeat(grey[:, :, None], 3, axis=2)


def _known_box(grid: OccupancyGrid) -> Box | None:
    """The world box around every mapped (not unknown) cell, or None if all are unknown."""
    rows, cols = np.nonzero(grid.data != -1)
    if rows.size == 0:
        return None
    corners_rows = np.array([rows.min(), rows.min(), rows.max() + 1, rows.max() + 1]) - 0.5
    corners_cols = np.array([cols.min(), cols.max() + 1, cols.min(), cols.max() + 1]) - 0.5
    return Box.around(grid.cells_to_world(corners_rows, corners_cols))


def _map_box(grid: OccupancyGrid) -> Box:
    rows = np.array([0, 0, grid.height, grid.height]) - 0.5
    cols = np.array([0, grid.width, 0, grid.width]) - 0.5
    return Box.around(grid.cells_to_world(rows, cols))


def area_of_interest(mission_points: np.ndarray, grid: OccupancyGrid | None) -> Box:
    """What to show: the mission with a margin, plus the mapped area if it is not huge.

    A small arena is shown whole (its walls give the mission context); on a large
    map only the neighbourhood of the mission is shown.
    """
    box = Box.around(mission_points)
    margin = max(0.5, 0.12 * max(box.width, box.height))
    box = box.grown(margin)
    if grid is not None:
        known = _known_box(grid)
        if known is not None and known.width * known.height <= 4.0 * box.width * box.height:
            box = box.union(known.grown(2 * grid.resolution))
        box = box.clipped(_map_box(grid)) if grid is not None else box
    # Never a degenerate box (a single waypoint on a map that does not contain it).
    if box.width <= 0 or box.height <= 0:
        box = Box.around(mission_points).grown(1.0)
    return box


def _draw_map(ax: Axes, grid: OccupancyGrid) -> None:
    from matplotlib.transforms import Affine2D

    extent = (
        grid.origin.x,
        grid.origin.x + grid.width * grid.resolution,
        grid.origin.y,
        grid.origin.y + grid.height * grid.resolution,
    )
    image = ax.imshow(
        occupancy_rgb(grid.data),
        origin="lower",  # row 0 of the grid is the bottom of the map
        extent=extent,
        interpolation="nearest",
        zorder=0,
    )
    if grid.origin.yaw:
        rotation = Affine2D().rotate_around(grid.origin.x, grid.origin.y, grid.origin.yaw)
        image.set_transform(rotation + ax.transData)


def _draw_pose_arrow(
    ax: Axes, pose: Pose2D, length: float, colour: str, *, zorder: float, width: float
) -> None:
    from matplotlib.patches import FancyArrow

    ax.add_patch(
        FancyArrow(
            pose.x,
            pose.y,
            length * math.cos(pose.yaw),
            length * math.sin(pose.yaw),
            width=width,
            head_width=3.2 * width,
            head_length=3.0 * width,
            length_includes_head=True,
            facecolor=colour,
            edgecolor="black",
            linewidth=0.6,
            zorder=zorder,
        )
    )


def _draw_trajectory(ax: Axes, trajectory: np.ndarray) -> LineCollection | None:
    """Driven path coloured by mission time; returns the collection for a colour bar."""
    from matplotlib.collections import LineCollection

    if len(trajectory) < 2:
        return None
    points = trajectory[:, 1:3]
    segments = np.stack([points[:-1], points[1:]], axis=1)
    times = trajectory[:-1, 0]
    # A NaN row is a break (between the segments of a resumed run): no line across it.
    drawn = np.isfinite(segments).all(axis=(1, 2)) & np.isfinite(times)
    if not drawn.any():
        return None
    lines = LineCollection(
        segments[drawn], cmap="viridis", linewidths=2.4, capstyle="round", zorder=3
    )
    lines.set_array(times[drawn])
    ax.add_collection(lines)
    return lines


def _title(mission: Mission, result: MissionResult, interrupted: str | None) -> str:
    name = printable(Path(mission.source).stem) if mission.source else "mission"
    reached = sum(
        1 for visit in result.visits if WaypointOutcome(visit.outcome) == WaypointOutcome.REACHED
    )
    verdict = (
        "success"
        if result.success
        else (f"interrupted ({interrupted})" if interrupted else result.reason)
    )
    return (
        f"{name} — {verdict}\n"
        f"{reached}/{len(result.visits)} visits reached · {result.duration:.1f} s · "
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
    # "tight" keeps the legend and axis labels that sit outside the axes.
    fig.savefig(png, format="png", bbox_inches="tight", pad_inches=0.15)
    return png.getvalue()


def _placed_outline(robot: RobotProfile, pose: Pose2D) -> list[tuple[float, float]]:
    """The robot's footprint polygon at ``pose``, world coordinates."""
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    return [(pose.x + c * x - s * y, pose.y + s * x + c * y) for x, y in robot.footprint]


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
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle

    waypoints = mission.waypoints
    traj = np.asarray(trajectory, dtype=float).reshape(-1, 3)
    plan_arrays = [np.asarray(p, dtype=float).reshape(-1, 2) for p in plans if len(p) > 1]
    driven = traj[np.isfinite(traj).all(axis=1), 1:3]
    point_sets = [np.array([[w.x, w.y] for w in waypoints]).reshape(-1, 2), driven]
    point_sets += plan_arrays
    if start is not None:
        point_sets.append(np.array([[start.x, start.y]]))
    all_points = np.concatenate([p for p in point_sets if len(p)] or [np.zeros((1, 2))])
    box = area_of_interest(all_points, grid)

    # Size the figure to the box so the map fills it; the colour bar takes a strip.
    aspect = box.height / box.width
    fig_width = 9.0
    fig = Figure(figsize=(fig_width, min(max(fig_width * aspect * 0.92, 4.0), 12.0)), dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.set_facecolor("white")
    if grid is not None:
        _draw_map(ax, grid)

    scale = max(box.width, box.height)
    arrow_length = 0.055 * scale
    arrow_width = 0.0045 * scale

    for plan in plan_arrays:
        ax.plot(
            plan[:, 0],
            plan[:, 1],
            linestyle=(0, (4, 3)),
            linewidth=1.0,
            color=PLAN_COLOUR,
            alpha=0.85,
            zorder=2,
        )
    lines = _draw_trajectory(ax, traj)

    outcomes = waypoint_outcomes(result, len(waypoints))
    last = len(waypoints) - 1
    drew_radius = False
    for index, (waypoint, outcome) in enumerate(zip(waypoints, outcomes, strict=True)):
        colour = OUTCOME_COLOURS[outcome]
        radius = mission.policy_for(index).pass_through_m
        if radius and index != last and mission.policy_for(index).dwell_s == 0:
            ax.add_patch(
                Circle(
                    (waypoint.x, waypoint.y),
                    radius,
                    fill=False,
                    edgecolor=colour,
                    linestyle=(0, (2, 2)),
                    linewidth=1.0,
                    zorder=4,
                )
            )
            drew_radius = True
        _draw_pose_arrow(ax, waypoint.pose, arrow_length, colour, zorder=5, width=arrow_width)
        ax.plot(
            waypoint.x,
            waypoint.y,
            marker="o",
            markersize=15,
            color=colour,
            markeredgecolor="black",
            markeredgewidth=0.8,
            zorder=6,
        )
        ax.text(
            waypoint.x,
            waypoint.y,
            str(index + 1),
            ha="center",
            va="center",
            fontsize=7.5,
            fontweight="bold",
            color="white",
            zorder=7,
        )
        if waypoint.name:
            ax.annotate(
                printable(waypoint.name),
                (waypoint.x, waypoint.y),
                xytext=(9, -12),
                textcoords="offset points",
                fontsize=7,
                color="#222222",
                zorder=7,
                bbox={
                    "boxstyle": "round,pad=0.15",
                    "facecolor": "white",
                    "edgecolor": "none",
                    "alpha": 0.75,
                },
            )

    if start is not None and robot is not None:
        from matplotlib.patches import Polygon

        outline = _placed_outline(robot, start)
        ax.add_patch(
            Polygon(outline, closed=True, fill=False, edgecolor="black", linewidth=0.9, zorder=6.5)
        )
    if start is not None:
        # Under the waypoint markers and a little larger, so that a waypoint at the
        # start pose (a tour that returns home) stays visible with the square around it.
        _draw_pose_arrow(ax, start, arrow_length, START_COLOUR, zorder=4.5, width=arrow_width)
        ax.plot(
            start.x,
            start.y,
            marker="s",
            markersize=17,
            color=START_COLOUR,
            markeredgecolor="black",
            markeredgewidth=0.8,
            zorder=5.5,
        )

    handles = [
        Line2D(
            [],
            [],
            marker="o",
            linestyle="none",
            markersize=9,
            color=OUTCOME_COLOURS[o],
            markeredgecolor="black",
            label=OUTCOME_LABELS[o],
        )
        for o in WaypointOutcome
        if o in outcomes or o == WaypointOutcome.REACHED
    ]
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
    if plan_arrays:
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
    ax.legend(
        handles=handles,
        loc="upper left",
        bbox_to_anchor=(1.02, 1.0),
        borderaxespad=0.0,
        fontsize=8,
        frameon=False,
    )
    if lines is not None:
        bar = fig.colorbar(
            lines, ax=ax, location="right", fraction=0.035, pad=0.02, anchor=(0.0, 0.0), shrink=0.55
        )
        bar.set_label("mission time [s]", fontsize=8)
        bar.ax.tick_params(labelsize=7)

    ax.set_xlim(box.xmin, box.xmax)
    ax.set_ylim(box.ymin, box.ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#9aa5b1", linewidth=0.4, alpha=0.5, zorder=1)
    ax.set_axisbelow(False)
    ax.set_title(_title(mission, result, interrupted), fontsize=10, loc="left")
    return fig
