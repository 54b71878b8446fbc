"""Past runs: the output folders ``navseq run`` (or the studio) left, replayed in time.

A run folder holds the mission as run, ``journal.jsonl`` and ``report.json``. The
journal is read by :func:`navseq.journal.writer.read_journal` (its chain checked, as
``navseq run --resume`` checks it) and its events are folded by the live view's own
rules (:class:`~navseq.studio.runs.LiveView`), so a replayed waypoint is in the state
the live page showed at that moment. What the page gets is a timeline it can scrub
with a slider: robot poses, only those the robot reported (the journal keeps the
driven path's corners, the pose at every arrival and one at least every 30 s, all
within 5 cm of the path driven; the page draws the robot in between), each
change of the waypoints' states (only the waypoints that changed, so that the timeline
grows with the run, not with the run times the mission's length), and each planned
path, all on one clock starting at 0.
"""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from navseq.errors import NavseqError
from navseq.text import printable

JOURNAL_NAME = "journal.jsonl"
RECORDING_NAME = "run.mcap"  # navseq run --record: replayed when the journal is gone
#: Runs listed at most (newest first): a folder of thousands stays quick to open.
MAX_RUNS_LISTED = 200


def run_folders(searched: list[Path]) -> list[Path]:
    """Folders holding a journal (or a recording, ``run.mcap``), under each of
    ``searched`` (one or two levels down)."""
    found: dict[Path, float] = {}
    for top in searched:
        if not top.is_dir():
            continue
        kept = [*top.glob(f"*/{JOURNAL_NAME}"), *top.glob(f"*/*/{JOURNAL_NAME}")]
        kept += [*top.glob(f"*/{RECORDING_NAME}"), *top.glob(f"*/*/{RECORDING_NAME}")]
        for journal in kept:
            try:
                found[journal.parent.resolve()] = journal.stat().st_mtime
            except OSError:
                continue
    return sorted(found, key=lambda folder: found[folder], reverse=True)[:MAX_RUNS_LISTED]


def run_summary(folder: Path, shown: str) -> dict[str, Any]:
    """One line of the runs list: folder, when, and the report's verdict if there is one."""
    from navseq.studio.runs import _latest_report

    report = _latest_report(folder)
    totals = report.get("totals", {}) if report else {}
    return {
        "folder": shown,
        "modified_s": _run_file(folder).stat().st_mtime,
        "reason": report.get("reason") if report else None,
        "reached": totals.get("reached"),
        "visits": totals.get("visits"),
    }


def replay_of(
    folder: Path,
    shown: str,
    base_dir: Path,
    may_read: Callable[[Path], bool] = lambda path: False,
) -> dict[str, Any]:
    """The run in ``folder`` as a timeline (docs/studio.md, ``GET /api/replay``).

    ``base_dir``: the folder the mission document's ``map:`` is made relative to (the
    studio's mission folder, so the page loads the map as it loads its own).
    ``may_read(path)``: whether the mission file the journal names may be read where it
    is (a ``navseq run`` folder holds no copy of it); it is used only if its bytes are
    still those that were run.
    Raises NavseqError when the folder has no readable journal.
    """
    from navseq.executor import events as ev
    from navseq.journal.reader import journal_events
    from navseq.journal.writer import read_journal
    from navseq.mission import load_mission
    from navseq.mission.robot import DEFAULT_PROFILE
    from navseq.studio.documents import document_of
    from navseq.studio.runs import LiveView, _latest_report

    journal_path = folder / JOURNAL_NAME
    events: Callable[[], Iterable[ev.MissionEvent]] = functools.partial(
        journal_events, journal_path
    )
    if journal_path.is_file():
        state = read_journal(journal_path)
    else:  # a recorded run whose journal is gone: its recordings hold the same events
        from navseq.sinks.recording.reading import (
            read_recordings,
            recorded_events,
            recordings_in,
        )

        recordings = recordings_in(folder) if folder.is_dir() else []
        if not recordings:
            raise NavseqError(
                f"{printable(shown)} has no {JOURNAL_NAME} and no {RECORDING_NAME}: "
                "not a run folder"
            )
        state = read_recordings(recordings)
        events = functools.partial(recorded_events, recordings)
    mission_path = _mission_file(folder, state.mission_source) or _source_as_run(
        folder, state.mission_source, state.mission_digest, may_read
    )
    mission = load_mission(mission_path) if mission_path is not None else None
    # Events are streamed from the file, never held: a patrol's journal may hold weeks.
    if mission is not None:
        count = len(mission.waypoints)
    else:
        indices = (getattr(event, "index", -1) for event in events())
        count = 1 + max(indices, default=-1)
    fold = LiveView(count, footprint=[])
    poses: list[list[float]] = []
    states: list[dict[str, Any]] = []
    plans: list[dict[str, Any]] = []
    start_t: float | None = None
    last_t = 0.0
    # A resumed run's clock may start again (the simulator's does, at 0): its part is laid
    # after the part before, so that the timeline goes forward through every resume.
    offset = 0.0
    for event in events():
        if isinstance(event, ev.MissionStarted) and event.resumed_from is not None:
            offset = max(offset, last_t - event.t)
        at = event.t + offset
        if start_t is None:
            start_t = at
        last_t = at
        before = (fold.current, fold.loop, fold.status)
        fold(event)
        t = round(at - start_t, 3)
        # Only poses the robot reported: a goal (WaypointStarted) is where it was sent,
        # not where it was, and drawn as a pose it cut the trail through walls.
        if isinstance(event, ev.WaypointProgress):
            poses.append(
                [t, round(event.x, 3), round(event.y, 3), round(math.degrees(event.yaw), 2)]
            )
        elif isinstance(event, ev.WaypointPlan):
            plans.append({"t": t, "index": event.index, "points": _thinned(event.path)})
        reset, changes = fold.take_changes()
        if reset or changes or (fold.current, fold.loop, fold.status) != before:
            # Only what changed: a full list per change would grow with the square of
            # the mission's length (5000 waypoints: hundreds of megabytes).
            states.append(
                {
                    "t": t,
                    "reset": reset,
                    "changes": [list(change) for change in changes],
                    "current": fold.current,
                    "loop": fold.loop,
                    "status": fold.status,
                }
            )
    robot = mission.robot if mission is not None and mission.robot else DEFAULT_PROFILE
    return {
        "folder": shown,
        "mission": document_of(mission, base_dir) if mission is not None else None,
        "report": _latest_report(folder),
        "duration_s": round(last_t - start_t, 3) if start_t is not None else 0.0,
        # The run's clock at its first event: a fleet's robots share one clock, and their
        # timelines are laid on it by this (navseq.studio.fleet_replay).
        "clock_start_s": round(start_t, 3) if start_t is not None else 0.0,
        "finish_reason": state.finish_reason,
        "damaged_lines": state.damaged_lines,
        "footprint_m": [[float(x), float(y)] for x, y in robot.footprint],
        "poses": poses,
        "states": states,
        "plans": plans,
    }


def _run_file(folder: Path) -> Path:
    """The file that says a folder holds a run: its journal, else its recording."""
    journal = folder / JOURNAL_NAME
    return journal if journal.exists() else folder / RECORDING_NAME


def _mission_file(folder: Path, source: str) -> Path | None:
    """The mission as run: the journal's source when it is in the folder, else the one
    YAML beside the journal (a folder moved elsewhere keeps its mission)."""
    named = Path(source)
    candidates = [folder / named.name] if named.name else []
    candidates += sorted(path for path in folder.glob("*.yaml") if path.is_file())
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    return None


def _source_as_run(
    folder: Path, source: str, digest: str, may_read: Callable[[Path], bool]
) -> Path | None:
    """The journal's mission file where it was run from, if allowed and unchanged since."""
    from navseq.journal.writer import mission_digest

    # A relative source was relative to where navseq ran: usually the run folder's parent's.
    for candidate in [Path(source)] if Path(source).is_absolute() else [folder.parent / source]:
        try:
            if may_read(candidate) and mission_digest(candidate) == digest:
                return candidate
        except (NavseqError, OSError):
            continue
    return None


def _thinned(path: Any) -> list[list[float]]:
    from navseq.route.legs import corners

    return [[x, y] for x, y in corners(path)] if len(path) else []


def shown_folder(folder: Path, base: Path) -> str:
    return printable(os.path.relpath(folder, base))
