"""The side panel of the mission picture: legend and time colour bar, beside the map."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from navseq.geometry import Pose2D
from navseq.sinks.picture.marks import Markers
from navseq.sinks.picture.style import (
    AXES_WIDTH,
    GAP,
    LEFT,
    PLAN_COLOUR,
    SIDE,
    START_COLOUR,
    STATUS_COLOURS,
    STATUS_LABELS,
    Status,
    WaypointOutcomes,
)
from navseq.sinks.picture.view import Layout

if TYPE_CHECKING:
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from navseq.mission.robot import RobotProfile


def side_panel(
    fig: Figure,
    layout: Layout,
    outcomes: WaypointOutcomes,
    markers: Markers | None,
    *,
    labels: int,
    start: Pose2D | None,
    robot: RobotProfile | None,
    drew_plans: bool,
    drew_radius: bool,
    lines: LineCollection | None,
    zones: Sequence[Any] = (),
) -> None:
    """Legend (top) and time colour bar (bottom) beside the map, never over it."""
    from matplotlib.lines import Line2D

    left = LEFT + AXES_WIDTH + GAP
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
            label=STATUS_LABELS[s] + ("" if len(outcomes) <= 1 else f" ({outcomes.count(s):,})"),
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
    handles.extend(zones)  # the map's keepout and speed zones (navseq.sinks.picture.zones)
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
    side = fig.add_axes(layout.fraction((left, bottom, SIDE, height)))
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
