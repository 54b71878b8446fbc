"""A fleet run's report (JSON) and picture (PNG: each robot's trail in its own colour)."""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from navseq.fleet.run import FleetRun, Member
    from navseq.sinks.picture.view import Box

#: The fleet report's version (docs/fleet.md shows one).
SCHEMA_VERSION = 1
_EXIT_OK, _EXIT_NOT_ALL = 0, 1


def member_summary(member: Member) -> dict[str, Any]:
    """One robot's line of the fleet report."""
    robot = member.robot
    row: dict[str, Any] = {
        "name": robot.name,
        "namespace": robot.namespace,
        "robot": robot.profile.name,
        "waypoints": member.waypoints,
        "reached": member.counts["reached"],
        "skipped": member.counts["skipped"],
        "failed": member.counts["failed"],
        "mission_time_s": None,
        "distance_m": None,
        "held_s": None,
        "exit_status": None,
        "folder": None,
    }
    outcome = member.outcome
    finished = member.finished
    if finished is not None:  # complete before a resume: as its journal says
        row["mission_time_s"] = round(finished.time_s, 1)
        row["distance_m"] = round(finished.distance_m, 2)
        row["exit_status"] = _EXIT_OK if finished.all_reached else _EXIT_NOT_ALL
        row["folder"] = str(finished.folder)
    if outcome is not None:
        result = outcome.result
        # The whole share: a resumed run's result holds the visits before the resume.
        counts = result.outcome_counts()
        for key in ("reached", "skipped", "failed"):
            row[key] = next((n for o, n in counts.items() if o.value == key), 0)
        row["mission_time_s"] = round(result.duration_s, 1)
        row["distance_m"] = round(result.distance_m, 2)
        # Waiting or giving way for the others: not counted against its goals' timeouts.
        row["held_s"] = round(sum(visit.held_s for visit in result.visits), 1)
        row["exit_status"] = outcome.exit_status
        row["folder"] = str(outcome.folder) if outcome.folder is not None else None
        # A resumed run's report is beside the first one (report-2.json ...).
        report = outcome.report_path
        row["report"] = None if report is None else str(report)
        if outcome.interrupted:
            row["interrupted"] = outcome.interrupted
    if member.error is not None:
        row["error"] = str(member.error)
    if member.session is None and finished is None:
        row["exit_status"] = _EXIT_OK  # nothing to do is done
    return row


def fleet_report(run: FleetRun) -> dict[str, Any]:
    """The fleet's report: per robot reached / skipped / failed, and the makespan."""
    plan = run.plan
    mission = plan.fleet.mission
    robots = [member_summary(member) for member in run.members]
    statuses = [row["exit_status"] for row in robots]
    if run.stopped_by is not None:
        from navseq.executor.runner import SIGNAL_EXIT_CODES

        exit_status = SIGNAL_EXIT_CODES.get(run.stopped_by, _EXIT_NOT_ALL)
    elif all(status == _EXIT_OK for status in statuses) and not plan.split.dropped:
        exit_status = _EXIT_OK
    else:
        exit_status = _EXIT_NOT_ALL
    times = [row["mission_time_s"] for row in robots if row["mission_time_s"] is not None]
    return {
        "schema_version": SCHEMA_VERSION,
        "fleet": plan.fleet.source,
        "mission": str(mission.source),
        "map": str(plan.fleet.map) if plan.fleet.map is not None else None,
        "robots": robots,
        "reached": sum(row["reached"] for row in robots),
        "skipped": sum(row["skipped"] for row in robots),
        "failed": sum(row["failed"] for row in robots),
        "left_out": [mission.number(i) for i in plan.split.dropped],
        "makespan_s": max(times, default=0.0),
        "planned_makespan_s": round(plan.split.makespan_s, 1),
        "robot_overlaps": run.world.collisions,
        "interrupted": run.stopped_by,
        "exit_status": exit_status,
    }


def _view(run: FleetRun) -> Box:
    """The mapped part of the map and every robot's start and waypoints, with a margin."""
    import numpy as np

    from navseq.sinks.picture.view import Box

    grid = run.plan.grid
    assert grid is not None
    rows, cols = np.nonzero(grid.data != -1)
    points = [(r.start.x, r.start.y) for r in run.plan.fleet.robots]
    points += [(w.x, w.y) for w in run.plan.fleet.mission.waypoints]
    if rows.size:
        points += [tuple(p) for p in grid.cells_to_world(rows[[0, -1]], cols[[0, -1]])]
        points += [
            tuple(p)
            for p in grid.cells_to_world(
                np.array([rows.min(), rows.max()]), np.array([cols.min(), cols.max()])
            )
        ]
    return Box.around(np.array(points, dtype=float)).grown(0.3)


def fleet_picture_png(run: FleetRun) -> bytes:
    """The map, and per robot in its colour: its trail, its start and its waypoints
    (filled where reached, a cross where failed or skipped)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from navseq.executor.events import WaypointOutcome
    from navseq.sinks.picture.view import draw_map, make_layout

    grid = run.plan.grid
    assert grid is not None
    layout = make_layout(_view(run), 100)
    figure = Figure(figsize=layout.size, dpi=layout.dpi)
    FigureCanvasAgg(figure)
    left, bottom, width, height = layout.axes
    figure_width, figure_height = layout.size
    ax = figure.add_axes(
        (left / figure_width, bottom / figure_height, width / figure_width, height / figure_height)
    )
    view = layout.view
    ax.set_xlim(view.xmin, view.xmax)
    ax.set_ylim(view.ymin, view.ymax)
    ax.set_aspect("equal")
    draw_map(ax, grid, layout)
    palette = [f"C{k % 10}" for k in range(len(run.members))]
    for member, colour in zip(run.members, palette, strict=True):
        robot = member.robot
        label = f"{robot.name} ({member.counts['reached']}/{member.waypoints} reached)"
        navigator = member.navigator
        # A resumed run: the path before the resume (from the journal), then this run's.
        for rows in (member.earlier_trail, list(navigator.trajectory) if navigator else []):
            if rows:
                ax.plot([r[1] for r in rows], [r[2] for r in rows], color=colour, lw=1.4)
        ax.plot([robot.start.x], [robot.start.y], marker="s", color=colour, ms=7, label=label)
        outcome = member.outcome
        if outcome is not None:
            visits = list(outcome.result.visits)
        elif member.finished is not None:
            visits = list(member.finished.visits)
        else:
            continue
        for visit in visits:
            reached = visit.outcome is WaypointOutcome.REACHED
            ax.plot(
                [visit.x],
                [visit.y],
                marker="o" if reached else "x",
                color=colour,
                ms=6,
                markerfacecolor=colour if reached else "none",
            )
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    report = fleet_report(run)
    ax.set_title(
        f"{len(run.members)} robots: {report['reached']} reached, {report['skipped']} "
        f"skipped, {report['failed']} failed; makespan {report['makespan_s']:.0f} s",
        fontsize=9,
    )
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=layout.dpi)
    return buffer.getvalue()


__all__ = ["SCHEMA_VERSION", "fleet_picture_png", "fleet_report", "member_summary"]
