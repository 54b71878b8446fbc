"""The mission picture: map, waypoints, planned legs and driven trajectory in one PNG.

Drawn with matplotlib's object API on the Agg canvas (no pyplot, no display needed),
readable from 1 to 100 000 waypoints and drawn in bounded time (a run that got a
signal waits for it):

- the occupancy grid in metres with its true extent and orientation (free white,
  occupied black, unknown grey, as in map_server images and RViz), cropped to the
  view and reduced to about one cell per pixel (:mod:`navseq.sinks.picture.thin`);
- every waypoint coloured by its meaningful outcome (:func:`waypoint_outcomes`):
  reached green, skipped orange, failed red, interrupted pink, not run grey. While
  there is room, each waypoint is a numbered disc with an arrow along its yaw and its
  pass-through radius dashed; a crowded mission gets small dots instead;
- labels that never collide with one another, with the markers that matter or with
  the legend (which sits outside the axes): all of them when they fit, else the
  first, the last, the failures and a spread-out sample (:mod:`~navseq.sinks.picture.labels`);
- waypoints on top of one another drawn as one marker with a count ("×3") and the
  list of their numbers; waypoints outside the view drawn as triangles on its border,
  pointing towards them, with their coordinates;
- each leg's planned path (thin, dashed) and the driven trajectory coloured by time,
  both thinned to what the pixels can show;
- the start pose, a legend and a colour bar beside the map, and a title with the
  mission name and its result.

This module reads the run (:func:`waypoint_outcomes` is the only place that reads a
result's visits) and puts the picture together; the helpers draw: ``view``
(view, layout, map, paths), ``marks`` (markers and labels), ``legend``
(side panel), with ``style`` (colours, sizes, budgets), ``thin`` and
``labels`` (the numpy and placement work).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from navseq.executor.events import WaypointOutcome
from navseq.executor.result import MissionResult
from navseq.files import write_atomically
from navseq.geometry import Pose2D
from navseq.mission.model import Mission
from navseq.sinks.picture.legend import side_panel
from navseq.sinks.picture.marks import (
    draw_markers,
    draw_numbered_details,
    group_markers,
    place_labels,
    square,
)
from navseq.sinks.picture.style import (
    DISC,
    STATUS_COLOURS,
    STATUS_LABELS,
    STATUSES,
    Status,
    WaypointOutcomes,
)
from navseq.sinks.picture.view import (
    Box,
    area_of_interest,
    draw_map,
    draw_plans,
    draw_start,
    draw_trajectory,
    make_layout,
    occupancy_rgb,
)
from navseq.sinks.picture.zones import draw_zones
from navseq.text import printable

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from navseq.mission.robot import RobotProfile
    from navseq.sim.occupancy import OccupancyGrid

__all__ = [
    "STATUS_COLOURS",
    "STATUS_LABELS",
    "Box",
    "Status",
    "WaypointOutcomes",
    "area_of_interest",
    "draw_mission_picture",
    "mission_figure",
    "mission_picture_png",
    "occupancy_rgb",
    "waypoint_outcomes",
]

Path2D = Sequence[tuple[float, float]]


# How bad a visit's outcome is. WaypointOutcome is a str enum, so these keys also
# match the plain strings ("reached") of a result read back from JSON.
_SEVERITY: dict[Any, int] = {
    WaypointOutcome.REACHED: 1,
    WaypointOutcome.SKIPPED: 2,
    WaypointOutcome.FAILED: 3,
}


def _is_interruption(visit: Any) -> bool:
    """A visit ended by a signal, a crash or the operator's cancel, not by the robot: the
    run's end, not its failure."""
    from navseq.executor.control import ended_from_outside

    return ended_from_outside(str(getattr(visit, "reason", "")))


def waypoint_outcomes(result: MissionResult, count: int) -> WaypointOutcomes:
    """What each waypoint's marker says: the one place the picture reads a result's visits.

    The meaningful outcome of a waypoint is its worst visit that ran to an end: failed,
    else skipped, else reached. A visit cut short by Ctrl-C, a signal or a cancel is not a
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
    if result.omitted_visits and result.waypoints:
        # A long patrol lists only some visits in full; the per-waypoint totals count
        # them all (an interruption is counted as failed there: at most one per run).
        for totals in result.waypoints:
            index = totals.index
            if not 0 <= index < count:
                continue
            failures = totals.failed - int(interrupted[index])
            reached[index] = totals.reached
            ended[index] = totals.reached + totals.skipped + failures
            severity = 3 if failures > 0 else 2 if totals.skipped else 1 if totals.reached else 0
            worst[index] = max(int(worst[index]), severity)
    code = {status: STATUSES.index(status) for status in Status}
    status = np.select(
        [worst == 3, worst == 2, worst == 1, interrupted],
        [code[Status.FAILED], code[Status.SKIPPED], code[Status.REACHED], code[Status.INTERRUPTED]],
        default=code[Status.NOT_RUN],
    ).astype(np.int8)
    return WaypointOutcomes(status, reached, ended, interrupted)


def _title(
    mission: Mission, result: MissionResult, outcomes: WaypointOutcomes, interrupted: str | None
) -> str:
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


#: What drawing a picture imports (the modules above import them only when they draw).
DRAWING_MODULES = (
    "matplotlib.backends.backend_agg",
    "matplotlib.collections",
    "matplotlib.figure",
    "matplotlib.font_manager",
    "matplotlib.lines",
    "matplotlib.patches",
    "matplotlib.transforms",
    "scipy.spatial",
)


def import_drawing_modules() -> None:
    """Import :data:`DRAWING_MODULES` (about half a second), for a caller that can do it
    ahead of time, while nothing waits for it."""
    import importlib

    for name in DRAWING_MODULES:
        importlib.import_module(name)


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
    yaws = np.array([w.yaw_rad for w in mission.waypoints], dtype=float)
    traj = np.asarray(trajectory, dtype=float).reshape(-1, 3)
    plan_arrays = [np.asarray(p, dtype=float).reshape(-1, 2) for p in plans if len(p) > 1]
    driven = traj[np.isfinite(traj).all(axis=1), 1:3]
    point_sets = [positions, driven, *plan_arrays]
    if start is not None:
        point_sets.append(np.array([[start.x, start.y]]))
    all_points = np.concatenate([p for p in point_sets if len(p)] or [np.zeros((1, 2))])
    layout = make_layout(area_of_interest(all_points, grid, positions if count else None), dpi)
    view = layout.view

    fig = Figure(figsize=layout.size, dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_axes(layout.fraction(layout.axes))
    ax.set_facecolor("white")
    ax.set_xlim(view.xmin, view.xmax)
    ax.set_ylim(view.ymin, view.ymax)
    ax.set_aspect("equal")
    zone_handles: list[Any] = []
    if grid is not None:
        draw_map(ax, grid, layout)
        zone_handles = draw_zones(ax, grid, layout)
    outcomes = waypoint_outcomes(result, count)
    markers = group_markers(positions, outcomes, layout, dpi) if count else None
    crowded = markers is not None and not markers.numbered
    drew_plans = draw_plans(ax, plan_arrays, layout)
    # Thinner among a crowd of dots, so that the dots stay visible.
    lines = draw_trajectory(ax, traj, layout, width=1.2 if crowded else 2.4)
    drew_radius = False
    labels = 0
    if markers is not None:
        draw_markers(ax, markers, outcomes, positions, layout)
        if markers.numbered:
            drew_radius = draw_numbered_details(ax, mission, markers, positions, yaws, layout)
    arrow_length = 1.8 * DISC / 72.0 * dpi / layout.scale
    obstacles = np.zeros((0, 4))
    if start is not None:
        draw_start(ax, start, robot, arrow_length)
        start_px = layout.to_pixels(np.array([[start.x, start.y]]))
        obstacles = square(start_px, 0.5 * (DISC + 2) / 72.0 * dpi)
    if markers is not None:
        labels = place_labels(
            ax, fig, mission, markers, outcomes, positions, layout, obstacles, yaws
        )

    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#9aa5b1", linewidth=0.4, alpha=0.5, zorder=1)
    ax.set_axisbelow(False)
    ax.set_title(_title(mission, result, outcomes, interrupted), fontsize=10, loc="left")
    side_panel(
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
        zones=zone_handles,
    )
    return fig
