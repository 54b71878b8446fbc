"""``navseq report RUN``: rebuild a run's report and picture from its journal.

(Or from its recordings, ``run.mcap`` ..., when the journal is gone: they keep every
event and what the journal's header says, :mod:`navseq.sinks.recording.reading`.)

A run killed with ``kill -9`` (or on a full disk) after its last journal line but
before its report leaves no report; the journal still holds everything the report
says. This command reads the journal (refusing one that was altered, see
:mod:`navseq.journal.writer`), checks the mission file is the one the run used, and
writes whatever of ``report.json`` / ``mission.png`` is missing, empty or unreadable.
A complete report is left as it is. ``navseq run --resume`` of a journal with nothing
left to run does the same.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.text import printable

if TYPE_CHECKING:
    from navseq.executor.result import MissionResult
    from navseq.journal.writer import JournalState
    from navseq.mission.model import Mission
    from navseq.mission.part import MissionPart

JOURNAL_NAME = "journal.jsonl"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: Exit statuses of runs that ended by a signal, by the reason the journal gives.
SIGNAL_EXITS = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}
UNFINISHED_REASON = "ended without finishing: the process stopped before the mission did"


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "run",
        type=Path,
        metavar="RUN",
        help="a run's output folder (navseq-out/...) or its journal.jsonl",
    )


def run(args: argparse.Namespace) -> int:
    from navseq.commands.common import require_file
    from navseq.run.runlock import RunLock

    journal = args.run / JOURNAL_NAME if args.run.is_dir() else args.run
    recordings: list[Path] = []
    if args.run.is_dir() and not journal.exists():
        from navseq.errors import NavseqError
        from navseq.sinks.recording.reading import recordings_in

        recordings = recordings_in(args.run)  # a recorded run: rebuilt from run.mcap
        if not recordings:
            raise NavseqError(
                f"{printable(str(args.run))} is not a run's output folder (it has no "
                f"{JOURNAL_NAME}) and holds no recording (run.mcap); give the folder "
                f"navseq run wrote (navseq-out/...) or its {JOURNAL_NAME}",
                source="RUN",
            )
    else:
        require_file(journal, "RUN")
    with RunLock(journal.parent):  # not while a live run writes them
        rebuilt = rebuild_outputs(journal, recordings=recordings)
    if not rebuilt.written:
        print(
            f"navseq report: the report in {printable(str(journal.parent))} is complete; "
            "nothing to rebuild"
        )
        return 0
    for role, path in rebuilt.written.items():
        print(f"{role:>8}: {printable(path)}")
    return 0


@dataclass(frozen=True)
class Rebuilt:
    """What :func:`rebuild_outputs` wrote (role -> path) and the run's own exit status
    (None when the journal ends before the mission did)."""

    written: dict[str, str]
    exit_code: int | None


def rebuild_outputs(
    journal: Path, state: JournalState | None = None, *, recordings: list[Path] | None = None
) -> Rebuilt:
    """Write the missing or broken report / picture of the run in ``journal``.

    ``state`` is the journal already read (by a resume that found nothing to run), so
    that a long journal is not read twice. ``recordings``: the journal is gone, the run
    is read from these (``run.mcap``, ``run-2.mcap`` ..., in order) instead. The caller
    holds the folder's run lock; temporaries a killed run left there are removed.
    """
    from navseq.files import write_atomically
    from navseq.journal.writer import read_journal
    from navseq.mission.part import number_visits
    from navseq.run.files import output_error, remove_stale_temporaries
    from navseq.sinks.report import report_json

    if recordings:
        from navseq.extras import require_extra
        from navseq.sinks.recording.reading import read_recordings

        require_extra("record", f"rebuilding the run from {recordings[0].name}")
        state = read_recordings(recordings)
    elif state is None or state.path != journal or not state.is_current():
        state = read_journal(journal)
    remove_stale_temporaries(journal.parent)
    whole = journaled_mission(state)
    part = journaled_part(state, whole)
    mission = part.apply(whole) if part is not None else whole
    result = result_from_journal(state, mission)
    folder = journal.parent
    report_path, picture_path = folder / "report.json", folder / "mission.png"
    written: dict[str, str] = {}
    if not _complete_report(report_path):
        report = _report(state, mission, result, report_path, picture_path, journal)
        if recordings:  # what the report was rebuilt from, and the recordings it names
            del report["rebuilt_from_journal"], report["files"]["journal"]
            report["rebuilt_from_recording"] = True
            report["files"]["recording"] = str(recordings[-1])
        number_visits(report, part)
        text = report_json(report)
        try:
            write_atomically(report_path, text)
        except OSError as error:
            raise output_error(report_path, error) from None
        written["report"] = str(report_path)
    if not state.run_options.get("no_picture") and not _complete_picture(picture_path):
        png = _picture(state, mission, result)
        try:
            write_atomically(picture_path, png)
        except OSError as error:
            raise output_error(picture_path, error) from None
        written["picture"] = str(picture_path)
    return Rebuilt(written, exit_code_of(result, state.finish_reason is not None))


def result_from_journal(state: JournalState, mission: Mission) -> MissionResult:
    """The run's result as its journal tells it (visits not finished are not run).

    Built through the same :class:`~navseq.executor.result.VisitLog` as a live run's
    (the one reading the journal folded its visits into), so a rebuilt report lists
    and counts visits as the run's own would have.
    """
    from navseq.errors import NavseqError

    started = state.mission_started
    loops = started.loops if started is not None else mission.loops
    history = state.visits
    try:
        log = history.log_for(mission.waypoints, loops, unfinished=True)
    except ValueError:
        raise NavseqError(
            f"the journal records a mission of {history.waypoint_count} waypoint(s), but "
            f"the mission has {len(mission.waypoints)}; the report would describe other "
            "waypoints",
            source=str(state.path),
        ) from None
    success = log.finished > 0 and log.all_reached()
    return log.result(
        success=success and state.finish_reason is not None,
        reason=state.finish_reason or UNFINISHED_REASON,
        duration=state.previous_duration,
        loops_completed=history.loops_completed(loops),
    )


def exit_code_of(result: MissionResult, finished: bool) -> int | None:
    """The exit status the run had, from its journal; None if it never finished."""
    if not finished:
        return None
    for name, code in SIGNAL_EXITS.items():
        if result.reason.startswith(f"interrupted: {name}"):
            return code
    return result.exit_code


def journaled_mission(state: JournalState) -> Mission:
    import dataclasses

    from navseq.commands.common import require_file
    from navseq.errors import NavseqError
    from navseq.journal.writer import mission_digest
    from navseq.mission import load_mission
    from navseq.mission.geo_records import filters_from_record

    source = Path(state.mission_source)
    require_file(source, f"the journal's mission file ({state.path})")
    if mission_digest(source) != state.mission_digest:
        raise NavseqError(
            "the mission file changed since the run; the report would describe other "
            "waypoints. Restore the original mission file",
            source=str(source),
        )
    mission = load_mission(source)
    started = state.mission_started
    if started is not None:
        mission = dataclasses.replace(mission, loops=started.loops)
    # The zones the run drove with (--keepout / --speed-mask), not only the file's.
    filters = filters_from_record(state.run_options.get("filters"), f"{state.path}:1")
    if filters is not None:
        mission = dataclasses.replace(mission, filters=filters)
    return mission


def journaled_part(state: JournalState, mission: Mission) -> MissionPart | None:
    """The part of the (whole) mission the journal's run ran; None for all of it."""
    from navseq.mission.part import part_from_options

    spec = part_from_options(state.run_options, f"{state.path}:1")
    return None if spec.whole else spec.select(mission)


def _report(
    state: JournalState,
    mission: Mission,
    result: MissionResult,
    report_path: Path,
    picture_path: Path,
    journal: Path,
) -> dict[str, Any]:
    from navseq.sinks.report import build_report

    options = state.run_options
    interrupted = next(
        (name for name in SIGNAL_EXITS if result.reason.startswith(f"interrupted: {name}")), None
    )
    report = build_report(
        mission,
        result,
        exit_code=exit_code_of(result, state.finish_reason is not None),  # type: ignore[arg-type]
        navigator={"kind": options.get("navigator", "unknown")},
        interrupted=interrupted,
        mission_digest=state.mission_digest,
        start=_start_of(options),
        files={
            "journal": str(journal),
            "report": str(report_path),
            **({} if options.get("no_picture") else {"picture": str(picture_path)}),
        },
    )
    report["rebuilt_from_journal"] = True
    return report


def _start_of(options: dict[str, Any]) -> Any:
    import math

    from navseq.geometry import Pose2D

    start = options.get("start")
    if (
        isinstance(start, list)
        and len(start) == 3
        and all(isinstance(v, int | float) and math.isfinite(v) for v in start)
    ):
        return Pose2D(float(start[0]), float(start[1]), math.radians(start[2]))
    return None


def _picture(state: JournalState, mission: Mission, result: MissionResult) -> bytes:
    from navseq.errors import NavseqError
    from navseq.sim.occupancy import load_map
    from navseq.sinks.picture.draw import mission_picture_png

    grid = None
    map_path = state.run_options.get("map") or mission.map
    if map_path:
        try:
            grid = load_map(map_path)
        except NavseqError as error:
            print(
                f"navseq report: drawing without the map ({printable(str(error))})",
                file=sys.stderr,
            )
    if grid is not None and mission.filters:
        from navseq.sim.filters import with_filters

        try:
            grid = with_filters(grid, mission.filters)
        except NavseqError as error:
            print(
                f"navseq report: drawing without the zones ({printable(str(error))})",
                file=sys.stderr,
            )
    recorder = state.recorder
    return mission_picture_png(
        mission,
        result,
        grid=grid,
        start=_start_of(state.run_options),
        plans=recorder.leg_plans(),
        trajectory=recorder.trajectory(),
        interrupted=None if state.finish_reason else "unfinished",
    )


def _complete_report(path: Path) -> bool:
    try:
        report = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(report, dict) and "visits" in report and "exit_code" in report


def _complete_picture(path: Path) -> bool:
    try:
        with path.open("rb") as handle:
            return handle.read(len(PNG_SIGNATURE)) == PNG_SIGNATURE
    except OSError:
        return False
