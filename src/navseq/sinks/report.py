"""The run report: one JSON document saying what happened to every waypoint visit.

Schema (``schema_version`` 9; the unit is in every field's name where there is one:
``_s`` seconds, ``_m`` metres, ``_deg`` degrees; ``x``, ``y`` are metres in the
mission's frame). The JSON Schema is ``docs/schemas/report.schema.json``; the
``--json`` events (:mod:`navseq.sinks.json_events`) use the same field names::

    {
      "schema_version": 9,
      "navseq_version": "0.1.0",
      "created": "2026-11-22T04:30:00+00:00",        # wall clock, UTC
      "mission": {"source", "name", "digest", "frame", "waypoints", "loops"},
      "navigator": {"kind": "sim" | "ros1" | ..., ...options},
      "map": {"source", "resolution_m", "width_cells", "height_cells",
              "origin": {"x", "y", "yaw_deg"}} | null,
      "start": {"x", "y", "yaw_deg"} | null,      # where the robot was when the run began
      "start_source": "robot" | "mission start:" | "--start" | ... | null,
      "planned_start": {"x", "y", "yaw_deg"} | null,  # --start or the mission's start:
      "success": bool,            # every visit reached
      "reason": "completed" | "stopped: ..." | "interrupted: SIGINT" | ...,
      "interrupted": "SIGINT" | "SIGTERM" | null,
      "exit_code": 0 | 1 | 130 | 143,
      "totals": {"visits", "reached", "skipped", "failed", "not_run",
                 "duration_s", "distance_m", "loops_completed"},   # over ALL visits
      "waypoints": [{"index", "number", "name", "visits", "reached", "skipped",
                     "failed", "not_run", "attempts", "duration_s", "distance_m"}],
      "visits_listed": {"listed", "omitted", "kept"},
      "visits": [{"index", "number", "loop", "name", "x", "y", "yaw_deg", "outcome",
                  "attempts": [{"number", "reached", "status", "reason", "text",
                                "duration_s", "distance_m", "recoveries", "held_s"}],
                  "duration_s", "distance_m", "held_s", "reason", "passed_through",
                  "tasks": [{"number", "kind", "attempt", "outcome", "duration_s",
                             "detail", "files", "output"}],
                  "recoveries_run": [{"number", "kind", "amount", "attempt", "outcome",
                                      "duration_s", "detail"}]}],
      "files": {"journal", "picture", ...},
      "filters": [{"mask", "type", "base", "multiplier"}],  # Nav2 costmap filters
      "datum": {"latitude", "longitude", "altitude", "yaw_deg"} | null,  # GPS datum
      "part": {"from", "to", "only", "numbers", "of"} | null,  # navseq run adds these
      "clock": {"navigator_s", "wall_s", "real_time_factor"}   # (not navseq report)
    }

``index`` is 0-based (as in events and the journal), ``number`` 1-based (as in
messages: "waypoint 3"); ``loop`` is 0-based; ``outcome`` is one of reached,
skipped, failed, not_run. ``start`` is the robot's first pose the navigator gave
(``start_source`` ``"robot"``); when the navigator gave none, the planned start
(``--start`` or the mission's ``start:``, as ``start_source`` says).

Each attempt is one goal sent: ``status`` is the navigation stack's terminal status
(SUCCEEDED, ABORTED, ...; null when navseq ended the attempt: timeout, stalled,
interrupt), ``reason`` navseq's verdict (empty for the attempt that reached the
waypoint; ``succeeded far from goal (2.38 m)`` when the stack said SUCCEEDED but the
robot was not there), ``text`` the stack's own result text, ``recoveries`` the
recovery behaviours the stack ran for the goal (Nav2's count; null from stacks that
do not count them; version 4 added it). Version 1 had
``attempts`` as a count: it is the length of the list now. Version 2 had the map's
``resolution``, ``width``, ``height`` and an ``origin`` list with its yaw in radians.

A patrol that loops for days, or a mission of 100 000 waypoints, makes more visits
than a report can list: ``visits`` lists a small finite mission's every visit, else
the last 1000 visits and up to 1000 earlier visits that were not reached (see
:class:`~navseq.executor.result.VisitLog`); ``visits_listed`` says how many are
listed, how many omitted and what was kept. ``totals`` and ``waypoints`` (one entry
per mission waypoint, its visits over every loop: counts, summed time and distance)
count every visit. Versions 2 and 3 had neither ``waypoints`` nor
``visits_listed`` and listed every visit; readers of reports (``navseq report``) accept both.
Version 4 had no ``clock`` (how fast the navigator's clock ran, see
:func:`navseq.sinks.json_events.clock_record`). Version 8 added ``filters`` (the Nav2
costmap filters the run drove with: each ``{"mask", "type", "base", "multiplier"}``,
``--keepout`` / ``--speed-mask`` or the mission's) and ``datum`` (``{"latitude",
"longitude", "altitude", "yaw_deg"}`` its GPS waypoints were converted with, or null).
Version 9 added ``held_s`` to attempts and visits: the seconds of ``duration_s`` a fleet
held the robot back (waiting, or giving way to another robot), which its goal's timeout
and stall clocks did not count.
"""

from __future__ import annotations

import datetime
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq import __version__
from navseq.executor.events import WaypointOutcome
from navseq.executor.result import (
    KEEP_LAST_VISITS,
    KEEP_NOT_REACHED_VISITS,
    AttemptResult,
    MissionResult,
    RecoveryResult,
    TaskResult,
    WaypointResult,
    WaypointTotals,
)
from navseq.files import write_atomically
from navseq.geometry import Pose2D
from navseq.mission.geo_records import datum_record, filters_record
from navseq.mission.model import Mission

if TYPE_CHECKING:
    from navseq.sim.occupancy import OccupancyGrid

try:  # a dependency, but a ROS install of the package may not have it (see report_json)
    import orjson
except ImportError:  # pragma: no cover - the tests run with it installed
    orjson = None  # type: ignore[assignment]

SCHEMA_VERSION = 9
#: What ``visits_listed.kept`` says when a run made more visits than the report lists.
KEPT_VISITS = (
    f"the last {KEEP_LAST_VISITS} visits and up to {KEEP_NOT_REACHED_VISITS} earlier "
    "visits not reached; totals and waypoints count every visit"
)
#: ``start_source`` when the report's start is the robot's own first pose.
START_FROM_ROBOT = "robot"


def _rounded(value: float, digits: int = 3) -> float | None:
    return round(value, digits) if math.isfinite(value) else None


def _pose_dict(pose: Pose2D) -> dict[str, float | None]:
    return {
        "x": _rounded(pose.x),
        "y": _rounded(pose.y),
        "yaw_deg": _rounded(math.degrees(pose.yaw), 1),
    }


def map_summary(grid: OccupancyGrid, source: Path | str) -> dict[str, Any]:
    """The report's ``map``: where the map came from, its cell size, extent and origin."""
    return {
        "source": str(source),
        "resolution_m": grid.resolution,  # metres per cell (map_server's resolution)
        "width_cells": grid.width,
        "height_cells": grid.height,
        "origin": _pose_dict(grid.origin),
    }


def _attempt_dict(attempt: AttemptResult) -> dict[str, Any]:
    return {
        "number": attempt.number,
        "reached": attempt.reached,
        "status": attempt.status,
        "reason": attempt.reason,
        "text": attempt.text,
        "duration_s": _rounded(attempt.duration, 2),
        "distance_m": _rounded(attempt.distance_driven),
        "recoveries": attempt.recoveries,
        "held_s": _rounded(attempt.held, 2),
    }


def _visit_dict(visit: WaypointResult) -> dict[str, Any]:
    return {
        "index": visit.index,
        "number": visit.index + 1,
        "loop": visit.loop,
        "name": visit.name,
        "x": _rounded(visit.x),
        "y": _rounded(visit.y),
        "yaw_deg": _rounded(math.degrees(visit.yaw_rad), 1),
        "outcome": WaypointOutcome(visit.outcome).value,
        "attempts": [_attempt_dict(attempt) for attempt in visit.attempt_results],
        "duration_s": _rounded(visit.duration, 2),
        "distance_m": _rounded(visit.distance_driven),
        "held_s": _rounded(visit.held_s, 2),
        "reason": visit.reason,
        "passed_through": visit.passed_through,
        "tasks": [_task_dict(task) for task in visit.tasks],
        "recoveries_run": [_recovery_dict(run) for run in visit.recoveries],
    }


def _recovery_dict(run: RecoveryResult) -> dict[str, Any]:
    """One recovery run before a retry: ``amount`` in the kind's unit (spin degrees,
    backup metres, wait seconds; null for clear_costmaps)."""
    return {
        "number": run.number,
        "kind": run.kind,
        "amount": run.amount,
        "attempt": run.attempt,
        "outcome": run.outcome,
        "duration_s": _rounded(run.duration, 2),
        "detail": run.detail,
    }


def _task_dict(task: TaskResult) -> dict[str, Any]:
    """One run of a waypoint's task: ``outcome`` succeeded, failed, timed_out or
    cancelled; ``files`` what it wrote; ``output`` a program's last lines."""
    return {
        "number": task.number,
        "kind": task.kind,
        "attempt": task.attempt,
        "outcome": task.outcome,
        "duration_s": _rounded(task.duration, 2),
        "detail": task.detail,
        "files": list(task.files),
        "output": list(task.output),
    }


def _totals_dict(totals: WaypointTotals) -> dict[str, Any]:
    return {
        "index": totals.index,
        "number": totals.index + 1,
        "name": totals.name,
        "visits": totals.visits,
        "reached": totals.reached,
        "skipped": totals.skipped,
        "failed": totals.failed,
        "not_run": totals.not_run,
        "attempts": totals.attempts,
        "duration_s": _rounded(totals.duration, 2),
        "distance_m": _rounded(totals.distance_driven),
    }


def _waypoint_totals(mission: Mission, result: MissionResult) -> list[WaypointTotals]:
    """The result's per-waypoint totals; counted from ``visits`` for a result without."""
    if result.waypoints:
        return result.waypoints
    totals = [
        WaypointTotals(i, w.name, w.x, w.y, w.yaw_rad) for i, w in enumerate(mission.waypoints)
    ]
    for visit in result.visits:
        if 0 <= visit.index < len(totals):
            totals[visit.index].add(visit)
    return totals


def build_report(
    mission: Mission,
    result: MissionResult,
    *,
    exit_code: int,
    navigator: Mapping[str, Any],
    interrupted: str | None = None,
    mission_digest: str | None = None,
    map_info: Mapping[str, Any] | None = None,
    start: Pose2D | None = None,
    start_source: str | None = None,
    files: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """The report of one run as a JSON-ready dict (see the module docstring).

    ``start`` is the planned start pose (``--start``, the mission's ``start:``, the
    simulator's default) and ``start_source`` says which; the report's ``start`` is
    the robot's own first pose (``result.start_pose``) whenever the run saw one.
    """
    actual: Pose2D | None
    actual_source: str | None
    if result.start_pose is not None:
        actual, actual_source = result.start_pose, START_FROM_ROBOT
    else:
        actual, actual_source = start, start_source if start is not None else None
    counts = result.outcome_counts()
    omitted = result.omitted_visits
    return {
        "schema_version": SCHEMA_VERSION,
        "navseq_version": __version__,
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "mission": {
            "source": mission.source,
            "name": Path(mission.source).stem,
            "digest": mission_digest,
            "frame": mission.frame,
            "waypoints": len(mission.waypoints),
            "loops": "forever" if mission.loops is None else mission.loops,
        },
        "navigator": dict(navigator),
        "map": dict(map_info) if map_info is not None else None,
        "start": _pose_dict(actual) if actual is not None else None,
        "start_source": actual_source,
        "planned_start": _pose_dict(start) if start is not None else None,
        "success": result.success,
        "reason": result.reason,
        "interrupted": interrupted,
        "exit_code": exit_code,
        "totals": {
            "visits": result.total_visits,
            **{outcome.value: counts.get(outcome, 0) for outcome in WaypointOutcome},
            "duration_s": _rounded(result.duration, 2),
            "distance_m": _rounded(result.distance_driven),
            "loops_completed": result.loops_completed,
        },
        "waypoints": [_totals_dict(t) for t in _waypoint_totals(mission, result)],
        "visits_listed": {
            "listed": len(result.visits),
            "omitted": omitted,
            "kept": KEPT_VISITS if omitted else "every visit",
        },
        "visits": [_visit_dict(visit) for visit in result.visits],
        "files": dict(files or {}),
        "filters": filters_record(mission.filters),
        "datum": datum_record(mission.datum),
    }


def report_json(report: Mapping[str, Any]) -> str:
    """The report as JSON text, indented by two spaces.

    With orjson where it is installed: Python's own encoder indents in pure Python, a
    second for the 25 MB report of a 100 000-waypoint mission (of the two a stopped
    run has to exit); orjson writes the same text in 0.04 s. Python's encoder writes
    what orjson refuses, such as a file name whose bytes are not UTF-8 (held as lone
    surrogates, which the file's writer escapes).
    """
    if orjson is not None:
        try:
            return orjson.dumps(report, option=orjson.OPT_INDENT_2).decode() + "\n"
        except (TypeError, orjson.JSONEncodeError):
            pass
    return json.dumps(report, indent=2, ensure_ascii=False) + "\n"


def write_report(report: Mapping[str, Any], path: Path) -> None:
    """Write ``report`` as indented JSON, atomically (a temp file renamed into place)."""
    text = report_json(report)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, text)
