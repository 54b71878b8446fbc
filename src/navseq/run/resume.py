"""The resume rules: a journal's run continues as it was started, or is refused.

A resume reads the journal (:func:`read_resume`), refuses a mission file that changed
since and a part of the mission other than the one the run started with, and continues
with the run's recorded options (:func:`continue_as_journaled`): navigator kind and its
journaled settings, picture, loop count, map, start pose and costmap filters (and
refuses a mission whose GPS datum is not the journal's). An option the request
gives again with another value wins, and is said in a note, so that an operator never
changes a patrol by accident. :func:`run_options` is what a new run records for that.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.errors import NavseqError
from navseq.navigators.registry import kind_of, navigator_kind, settings_from
from navseq.navigators.settings import setting_fields
from navseq.run.request import Outputs, RunRequest, UseNavigator
from navseq.run.values import format_pose, loops_from_text, pose_degrees, pose_from_text

if TYPE_CHECKING:
    from navseq.executor.resume import ResumePoint
    from navseq.geometry import Pose2D
    from navseq.journal.writer import JournalState
    from navseq.mission.costmap_filters import CostmapFilter
    from navseq.mission.model import Mission
    from navseq.navigators.registry import NavigatorKind

#: The navigator kind of a run that names none (journals older than the option).
DEFAULT_KIND = "sim"
#: The journal's names of the options that choose the part of the mission run: a resume
#: must run the same part (the journal's waypoint positions are positions in it).
PART_OPTIONS = ("from_waypoint", "to_waypoint", "only")


def read_resume(journal: Path, mission_path: Path | None) -> tuple[Path, ResumePoint, JournalState]:
    """The mission file, resume point and contents of a journal (mission unchanged)."""
    from navseq.files import require_file
    from navseq.journal.writer import mission_digest, read_journal, resume_point

    require_file(journal, "--resume")
    state = read_journal(journal)
    path = mission_path if mission_path is not None else Path(state.mission_source)
    if not path.exists():
        raise NavseqError(
            f"the journal's mission file {path} does not exist any more; "
            "give the mission file as MISSION",
            source=str(journal),
        )
    # resume_point refuses a mission whose digest differs from the journal's.
    point = resume_point(state, mission_digest=mission_digest(path))
    return path, point, state


def known_kind(name: str) -> NavigatorKind:
    """The kind named ``name`` (by a request or a journal), or one clear NavseqError."""
    try:
        return navigator_kind(name)
    except KeyError:  # a journal naming a navigator this navseq does not have
        raise NavseqError(f"unknown navigator {name!r}", source="--navigator") from None


class _Notes:
    """The run's notes on options given again with another value than the journal's."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def settle(self, flag: str, given: Any, recorded: Any) -> Any:
        """``given``, or ``recorded`` when nothing was given; a note when they differ."""
        if given is None:
            return recorded
        if given != recorded:
            self.lines.append(
                f"resuming with {flag} {_option_text(given)} instead of the journal's "
                f"{_option_text(recorded)}"
            )
        return given


def continue_as_journaled(
    request: RunRequest, history: JournalState
) -> tuple[RunRequest, list[str]]:
    """``request`` with what it leaves out taken from the journaled run; notes on overrides."""
    recorded = dict(history.run_options)
    started = history.mission_started
    if "loops" not in recorded and started is not None:
        recorded["loops"] = started.loops  # journals written before run options existed
    where = f"{history.path}:1"
    _refuse_another_part(request, recorded, where)
    notes = _Notes()
    navigator = request.navigator
    if isinstance(navigator, UseNavigator):
        # The face's own navigator (a fleet's robot), made as the journaled run had it,
        # with the face's outputs: only the mission's part, loops, map and start follow.
        return _continued_options(request, recorded, where, notes, navigator, own=True), (
            notes.lines
        )
    journaled_kind = str(recorded.get("navigator") or DEFAULT_KIND)
    given_kind = kind_of(navigator).name if navigator is not None else None
    kind = known_kind(notes.settle("--navigator", given_kind, journaled_kind))
    given = (
        {name: getattr(navigator, name) for name in kind.journaled()}
        if navigator is not None and given_kind == kind.name
        else dict(request.navigator_options)
    )
    values = dict(
        dataclasses.asdict(navigator) if navigator is not None else request.navigator_options
    )
    for option in setting_fields(kind.settings):
        if option.info.journaled and option.name in recorded:
            values[option.name] = notes.settle(
                option.info.flag, given.get(option.name), recorded[option.name]
            )
    return _continued_options(request, recorded, where, notes, settings_from(kind, values)), (
        notes.lines
    )


def _continued_options(
    request: RunRequest,
    recorded: dict[str, Any],
    where: str,
    notes: _Notes,
    navigator: Any,
    *,
    own: bool = False,
) -> RunRequest:
    """``request`` with ``navigator`` and the journal's outputs (unless ``own``: the
    face's), loops, map, start and part."""
    outputs = request.outputs or Outputs()
    if own:
        recorded = {**recorded, "no_picture": outputs.picture is False, "record": False}
    no_picture = None if outputs.picture is None else not outputs.picture
    picture = not notes.settle("--no-picture", no_picture, bool(recorded.get("no_picture", False)))
    # A recorded run goes on recording, into a new file beside the first (run-2.mcap);
    # a face with its own navigator (a fleet, which records its robots in one file of
    # its own) says itself whether the robot's run records.
    record = (
        outputs.record if own else outputs.record or bool(recorded.get("record", False)) or None
    )
    record_format = notes.settle(
        "--record-format", outputs.record_format, recorded.get("record_format")
    )
    try:
        loops = notes.settle("--loops", request.loops, _journal_loops(recorded))
        map_path = notes.settle("--map", request.map, _journal_map(recorded))
        # The face's own navigator's robot is where the face put it (a fleet: where its
        # journal last saw it), not a choice to note.
        start = (
            request.start
            if own and request.start is not None
            else notes.settle("--start", request.start, _journal_start(recorded))
        )
    except (TypeError, ValueError) as error:
        raise NavseqError(f"the journal's run option {error}", source=where) from None
    filters = _continued_filters(request, recorded, where, notes)
    return dataclasses.replace(
        request,
        filters=filters,
        navigator=navigator,
        navigator_options={},
        outputs=dataclasses.replace(
            outputs, picture=picture, record=record, record_format=record_format
        ),
        loops=loops,
        map=map_path,
        start=start,
        first=recorded.get("from_waypoint"),
        last=recorded.get("to_waypoint"),
        only=recorded.get("only"),
    )


def _continued_filters(
    request: RunRequest, recorded: dict[str, Any], where: str, notes: _Notes
) -> tuple[CostmapFilter, ...] | None:
    """The costmap filters the journaled run drove with (its --keepout / --speed-mask or
    the mission's), unless the request gives others: then those, and a note."""
    from navseq.mission.geo_records import describe_filters, filters_from_record

    journaled = filters_from_record(recorded.get("filters"), where)
    if request.filters is None or journaled is None:
        return request.filters if request.filters is not None else journaled
    if request.filters != journaled:
        notes.lines.append(
            f"resuming with --keepout/--speed-mask {describe_filters(request.filters)} "
            f"instead of the journal's {describe_filters(journaled)}"
        )
    return request.filters


def refuse_another_datum(mission: Mission, history: JournalState) -> None:
    """A resume converts GPS waypoints with the datum the journaled run used, or stops:
    the journal's positions are positions through it."""
    from navseq.mission.geo_records import datum_record, same_datum

    recorded = history.run_options.get("datum", _UNRECORDED)
    if recorded is _UNRECORDED or same_datum(mission.datum, recorded):
        return  # a journal written before navseq recorded the datum: nothing to hold to
    raise NavseqError(
        f"the mission's datum {datum_record(mission.datum)} is not the journal's "
        f"{recorded}: its GPS waypoints would land elsewhere; resume with the mission "
        "the run started with, or start a new run without --resume",
        source="--resume",
    )


_UNRECORDED = object()


def _journal_loops(recorded: dict[str, Any]) -> int | str | None:
    if "loops" not in recorded:
        return None
    value = recorded["loops"]
    if value in (None, "forever"):
        return "forever"
    try:
        loops = loops_from_text(str(value))
    except ValueError as error:
        raise ValueError(f"loops is not valid: {error}") from None
    return "forever" if loops is None else loops


def _journal_map(recorded: dict[str, Any]) -> Path | None:
    value = recorded.get("map")
    return None if value is None else Path(str(value))


def _journal_start(recorded: dict[str, Any]) -> Pose2D | None:
    value = recorded.get("start")
    if value is None:
        return None
    try:
        return pose_from_text(",".join(map(str, value)))
    except (TypeError, ValueError) as error:
        raise ValueError(f"start is not valid: {error}") from None


def _refuse_another_part(request: RunRequest, recorded: dict[str, Any], where: str) -> None:
    """A resume runs the part of the mission the journal's run ran, or nothing."""
    from navseq.mission.part import part_from_options

    journaled = part_from_options(recorded, where)
    asked = (request.first, request.last, request.only)
    if all(value is None for value in asked):
        return
    if asked != (journaled.first, journaled.last, journaled.only):
        ran = journaled.describe() or "the whole mission"
        raise NavseqError(
            f"a resume continues the part of the mission its run started with ({ran}); "
            "leave out --from, --to and --only, or start a new run without --resume",
            source="--resume",
        )


def _option_text(value: Any) -> str:
    if value is None:
        return "none"
    if hasattr(value, "yaw"):
        return format_pose(value)
    return str(value)


def run_options(
    request: RunRequest,
    kind: NavigatorKind,
    mission: Mission,
    map_path: Path | None,
    start: Pose2D | None,
) -> dict[str, Any]:
    """What a new run's journal header records so that a resume continues the same run.

    ``request`` is the run's, its navigator settings resolved; ``mission`` the one run
    (its loop count as given); ``start`` the start pose the run settled on.
    """
    from navseq.mission.geo_records import datum_record, filters_record

    settings = request.navigator
    outputs = request.outputs or Outputs()
    return {
        "navigator": kind.name,
        **{name: getattr(settings, name, None) for name in kind.journaled()},
        "no_picture": outputs.picture is False,
        "record": bool(outputs.record or mission.record),
        "record_format": outputs.record_format or "ros2",
        "from_waypoint": request.first,
        "to_waypoint": request.last,
        "only": request.only,
        "loops": mission.loops,
        "map": str(Path(map_path).resolve()) if map_path is not None else None,
        "start": None if start is None else pose_degrees(start),
        # What the waypoints and zones were: the filters driven with, the GPS datum.
        "filters": filters_record(mission.filters),
        "datum": datum_record(mission.datum),
    }


__all__ = [
    "PART_OPTIONS",
    "continue_as_journaled",
    "known_kind",
    "read_resume",
    "refuse_another_datum",
    "run_options",
]
