"""``navseq run MISSION``: drive a robot (simulated by default) through a mission.

The command is two phases. :func:`prepare` reads and checks everything the user
gave (mission, map, start pose, journal to resume) and runs the pre-flight check;
any problem is a :class:`~navseq.errors.NavseqError` (exit 2) raised before the
robot moves and before anything is written. :func:`execute` then runs the mission
with the journal, the progress display and the recorder listening, and writes the
report and the picture even when the run is interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from navseq.commands.common import (
    add_robot_option,
    format_pose,
    parse_loops,
    parse_pose,
    parse_realtime,
    parse_waypoint_number,
)
from navseq.navigators.registry import (
    NavigatorDraft,
    add_navigator_choice,
    add_navigator_options,
    journaled_options,
    navigator_kind,
)
from navseq.text import printable

if TYPE_CHECKING:
    from navseq.errors import NavseqError
    from navseq.executor.control import MissionControl
    from navseq.executor.machine import MissionListener
    from navseq.executor.result import MissionResult
    from navseq.executor.resume import ResumePoint
    from navseq.geometry import Pose2D
    from navseq.journal.writer import JournalState, JournalWriter
    from navseq.mission.model import Mission
    from navseq.mission.part import MissionPart
    from navseq.mission.robot import RobotProfile
    from navseq.navigators.base import Navigator
    from navseq.signals import SignalGuard
    from navseq.sim.occupancy import OccupancyGrid
    from navseq.sinks.json_events import JsonProgress
    from navseq.sinks.recorder import RunRecorder


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "mission",
        type=Path,
        nargs="?",
        metavar="MISSION",
        help="mission file (navseq YAML, launch, rosparam YAML, CSV); "
        "optional with --resume (taken from the journal)",
    )
    add_navigator_choice(parser, default=None)  # None: sim, or the journal's when resuming
    parser.add_argument(
        "--map", type=Path, metavar="MAP", help="map_server YAML (default: the mission's map:)"
    )
    parser.add_argument(
        "--start",
        type=parse_pose,
        metavar="X,Y,YAW",
        help="simulated robot's start pose, metres, metres, degrees "
        "(default: the mission's start:)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="output folder (default: navseq-out/<mission>-<YYYYmmdd-HHMMSS>)",
    )
    parser.add_argument(
        "--json", action="store_true", help="print one JSON object per event instead of progress"
    )
    parser.add_argument(
        "--resume",
        type=Path,
        metavar="JOURNAL",
        help="continue the run recorded in this journal.jsonl (reached waypoints are not re-run)",
    )
    parser.add_argument(
        "--no-preflight",
        action="store_true",
        help="skip checking the waypoints against the map before the robot moves",
    )
    parser.add_argument(
        "--loops",
        type=parse_loops,
        default=argparse.SUPPRESS,  # absent unless given: None already means "forever"
        metavar="N|forever",
        help="run the waypoint list N times, or until interrupted (default: the mission's loops:)",
    )
    parser.add_argument(
        "--from",
        dest="from_waypoint",
        type=parse_waypoint_number,
        metavar="N",
        help="start at waypoint N (1-based, as numbered in the summary table)",
    )
    parser.add_argument(
        "--to",
        dest="to_waypoint",
        type=parse_waypoint_number,
        metavar="N",
        help="end at waypoint N, inclusive (1-based, as numbered in the summary table)",
    )
    parser.add_argument(
        "--only",
        metavar="NAME_OR_NUMBER,...",
        help="run only these waypoints, in the mission's order (names or 1-based numbers)",
    )
    parser.add_argument(
        "--realtime",
        type=parse_realtime,
        nargs="?",
        const=1.0,
        metavar="FACTOR",
        help="pace the simulator at FACTOR times real time (1 when no FACTOR is given), to "
        "watch it or drive RViz; without it the simulator runs as fast as it can",
    )
    parser.add_argument(
        "--no-picture",
        action="store_true",
        default=None,  # None: not given (a resume takes the journal's)
        help="do not draw mission.png",
    )
    add_robot_option(parser)
    # Each navigator kind's options (navseq.navigators.registry), the test double's hidden.
    add_navigator_options(parser)


@dataclass
class RunSetup:
    """Everything checked and ready: what to run, on what, and where to write."""

    mission: Mission
    mission_path: Path
    digest: str
    make_navigator: Callable[[], Navigator]
    navigator_info: dict[str, Any]
    # What pre-flight, the planner, the simulator and the arrival check assume.
    robot: RobotProfile
    start: Pose2D | None = None
    start_source: str | None = None  # where ``start`` came from: "--start", "mission start:"
    grid: OccupancyGrid | None = None
    map_path: Path | None = None
    resume: ResumePoint | None = None
    journal: Path | None = None  # the journal to append to when resuming
    history: JournalState | None = None  # what that journal held before resuming
    notes: list[str] = field(default_factory=list)
    run_options: dict[str, Any] = field(default_factory=dict)  # journaled for a resume
    part: MissionPart | None = None  # the waypoints run, when not all of them
    # Extra mission listeners the navigator's setup made (ROS markers and status).
    listeners: list[MissionListener] = field(default_factory=list)
    # Operator requests (stop, pause, skip) from another thread: the studio's buttons.
    control: MissionControl | None = None


def _read_resume(journal: Path, mission_arg: Path | None) -> tuple[Path, ResumePoint, JournalState]:
    """The mission file, resume point and contents of a journal (mission unchanged)."""
    from navseq.commands.common import require_file
    from navseq.errors import NavseqError
    from navseq.journal.writer import mission_digest, read_journal, resume_point

    require_file(journal, "--resume")
    state = read_journal(journal)
    mission_path = mission_arg if mission_arg is not None else Path(state.mission_source)
    if not mission_path.exists():
        raise NavseqError(
            f"the journal's mission file {mission_path} does not exist any more; "
            "give the mission file as MISSION",
            source=str(journal),
        )
    # resume_point refuses a mission whose digest differs from the journal's.
    point = resume_point(state, mission_digest=mission_digest(mission_path))
    return mission_path, point, state


def _map_info(grid: OccupancyGrid, map_path: Path) -> dict[str, Any]:
    from navseq.sinks.report import map_summary

    return map_summary(grid, map_path)


def prepare(args: argparse.Namespace) -> RunSetup:
    """Load and check the user's input; raise NavseqError on any problem."""
    from navseq.commands.common import choose_robot, require_file
    from navseq.errors import NavseqError
    from navseq.journal.writer import mission_digest
    from navseq.mission import load_mission
    from navseq.mission.part import PartSpec

    resume = history = None
    notes: list[str] = []
    start_given = args.start is not None  # on this command line, not from a journal
    if args.resume is not None:
        mission_path, resume, history = _read_resume(args.resume, args.mission)
        notes = continue_as_journaled(args, history)
    elif args.mission is None:
        raise NavseqError(
            "no mission given: name the mission file to run (navseq run MISSION), "
            "or the journal of a run to continue (--resume JOURNAL)"
        )
    else:
        mission_path = args.mission
        require_file(mission_path, "MISSION")
    if args.map is not None:
        require_file(args.map, "--map")
    apply_run_defaults(args)
    _refuse_sim_options(args, start_given)
    mission = load_mission(mission_path)
    if "loops" in vars(args):  # given on the command line (None = forever)
        mission = dataclasses.replace(mission, loops=args.loops)
    spec = PartSpec(args.from_waypoint, args.to_waypoint, args.only)
    part = None if spec.whole else spec.select(mission)
    if part is not None:
        mission = part.apply(mission)
    if resume is not None:
        # Refuse a journal the mission cannot continue before anything is appended to it.
        from navseq.executor.machine import MissionExecutor

        MissionExecutor(mission, resume=resume)
    map_path = args.map if args.map is not None else mission.map
    start = args.start if args.start is not None else mission.start
    start_source = (
        "--start" if args.start is not None else "mission start:" if start is not None else None
    )
    kind = navigator_kind(args.navigator)
    draft = NavigatorDraft(
        mission=mission,
        map_path=map_path,
        start=start,
        start_source=start_source,
        robot=choose_robot(args.robot, mission),
        preflight=not args.no_preflight,
        numbers=part.numbers if part is not None else None,
    )
    made = kind.create(args, draft)
    setup = RunSetup(
        mission=mission,
        mission_path=mission_path,
        digest=mission_digest(mission_path),
        make_navigator=made.make_navigator,
        navigator_info=made.info,
        robot=draft.robot,
        start=draft.start,
        start_source=draft.start_source,
        grid=made.grid,
        map_path=map_path,
        resume=resume,
        journal=args.resume,
        history=history,
        notes=[*notes, *made.notes],
        listeners=made.listeners,
        part=part,
    )
    setup.run_options = run_options(args, setup)
    return setup


#: Options a run records in its journal, with their defaults; a resume continues with
#: the recorded value of each one the command line does not give again.
#: The chosen navigator kind's options are journaled too (NavigatorKind.journaled).
RUN_OPTION_DEFAULTS: dict[str, Any] = {
    "navigator": "sim",
    "no_picture": False,
}
#: The options that choose the part of the mission run: a resume must run the same part
#: (the journal's waypoint positions are positions in it).
PART_OPTIONS = ("from_waypoint", "to_waypoint", "only")
#: How the journal's option names are typed on the command line, where they differ.
OPTION_FLAGS = {"from_waypoint": "--from", "to_waypoint": "--to", "no_picture": "--no-picture"}


def _refuse_sim_options(args: argparse.Namespace, start_given: bool) -> None:
    """Options that only the embedded simulator can honour, refused for a real robot."""
    from navseq.errors import NavseqError

    if not navigator_kind(args.navigator).places_robot and start_given:
        raise NavseqError(
            f"sets the simulated robot's start pose; with --navigator {args.navigator} the "
            "robot is where it is. Leave --start out (set a robot's pose with RViz's 2D Pose "
            "Estimate, which publishes /initialpose)",
            source="--start",
        )
    if args.navigator != "sim" and args.realtime is not None:
        raise NavseqError(
            f"paces the embedded simulator; --navigator {args.navigator} keeps its own "
            "time. Leave --realtime out",
            source="--realtime",
        )


def apply_run_defaults(args: argparse.Namespace) -> None:
    """Fill the options left out (None) with their defaults, the navigator's included."""
    from navseq.errors import NavseqError

    for name, default in RUN_OPTION_DEFAULTS.items():
        if getattr(args, name, None) is None:
            setattr(args, name, default)
    try:
        kind = navigator_kind(args.navigator)
    except KeyError:  # a journal naming a navigator this navseq does not have
        raise NavseqError(f"unknown navigator {args.navigator!r}", source="--navigator") from None
    for name, default in kind.option_defaults().items():
        if getattr(args, name, None) is None:
            setattr(args, name, default)


def continue_as_journaled(args: argparse.Namespace, history: JournalState) -> list[str]:
    """Take the journaled run's options the command line leaves out; notes on overrides.

    A resume continues the mission as it was started: its loop count, navigator and
    navigator settings, map and start pose. An option given again with another value
    wins, and is said, so an operator never changes a patrol by accident.
    """
    from navseq.commands.common import parse_loops, parse_pose
    from navseq.errors import NavseqError

    recorded = dict(history.run_options)
    started = history.mission_started
    if "loops" not in recorded and started is not None:
        recorded["loops"] = started.loops  # journals written before run options existed
    notes: list[str] = []

    def given(name: str) -> bool:
        if name == "loops":
            return "loops" in vars(args)
        return getattr(args, name, None) is not None

    _refuse_another_part(args, recorded, history)
    for name, value in recorded.items():
        if name not in (
            *RUN_OPTION_DEFAULTS,
            *journaled_options(),
            *PART_OPTIONS,
            "loops",
            "map",
            "start",
        ):
            continue
        try:
            if name in PART_OPTIONS:
                setattr(args, name, value)  # checked by _refuse_another_part
                continue
            if name == "no_picture":
                value = bool(value)
            if name == "loops":
                value = None if value in (None, "forever") else parse_loops(str(value))
            elif name == "map":
                value = None if value is None else Path(str(value))
            elif name == "start":
                value = None if value is None else parse_pose(",".join(map(str, value)))
        except (argparse.ArgumentTypeError, TypeError) as error:
            raise NavseqError(
                f"the journal's run option {name} is not valid: {error}",
                source=f"{history.path}:1",
            ) from None
        if not given(name):
            setattr(args, name, value)
        elif getattr(args, name) != value:
            flag = OPTION_FLAGS.get(name, f"--{name}")
            notes.append(
                f"resuming with {flag} {_option_text(getattr(args, name))} instead of the "
                f"journal's {_option_text(value)}"
            )
    return notes


def _refuse_another_part(
    args: argparse.Namespace, recorded: dict[str, Any], history: JournalState
) -> None:
    """A resume runs the part of the mission the journal's run ran, or nothing."""
    from navseq.errors import NavseqError
    from navseq.mission.part import part_from_options

    journaled = part_from_options(recorded, f"{history.path}:1")
    asked = {name: getattr(args, name, None) for name in PART_OPTIONS}
    if all(value is None for value in asked.values()):
        return
    if asked != {
        "from_waypoint": journaled.first,
        "to_waypoint": journaled.last,
        "only": journaled.only,
    }:
        ran = journaled.describe() or "the whole mission"
        raise NavseqError(
            f"a resume continues the part of the mission its run started with ({ran}); "
            "leave out --from, --to and --only, or start a new run without --resume",
            source="--resume",
        )


def _option_text(value: Any) -> str:
    if value is None:
        return "none (forever for loops)"
    if hasattr(value, "yaw"):
        return format_pose(value)
    return str(value)


def run_options(args: argparse.Namespace, setup: RunSetup) -> dict[str, Any]:
    """What the journal's header records so that a resume continues the same run."""
    import math

    start = setup.start
    return {
        "navigator": args.navigator,
        **{name: getattr(args, name) for name in navigator_kind(args.navigator).journaled()},
        "no_picture": bool(args.no_picture),
        "from_waypoint": args.from_waypoint,
        "to_waypoint": args.to_waypoint,
        "only": args.only,
        "loops": setup.mission.loops,
        "map": str(Path(setup.map_path).resolve()) if setup.map_path is not None else None,
        "start": None
        if start is None
        else [round(start.x, 6), round(start.y, 6), round(math.degrees(start.yaw), 6)],
    }


@dataclass
class RunOutcome:
    """How a run ended, with the sinks that watched it."""

    result: MissionResult
    exit_code: int
    interrupted: str | None  # signal name
    navigator: Navigator
    recorder: RunRecorder
    json_lines: JsonProgress | None
    error: NavseqError | None = None  # what stopped the run, if an output failed
    # The navigator's clock and the wall clock over the run, for the real-time factor.
    navigator_seconds: float = 0.0
    wall_seconds: float = 0.0

    @property
    def clock(self) -> dict[str, float | None]:
        """The report's and ``RunFinished``'s ``clock``: how fast the navigator's clock ran."""
        from navseq.sinks.json_events import clock_record

        return clock_record(self.navigator_seconds, self.wall_seconds)


def _output_folder(setup: RunSetup, args: argparse.Namespace) -> tuple[Path, bool]:
    """The folder to write into, and whether this run created it."""
    from navseq.commands.output import create_run_folder, default_run_folder

    if args.out is not None:
        existed = args.out.exists()
        return create_run_folder(args.out, fresh=False), not existed
    if setup.journal is not None:  # a resumed run writes beside its journal
        return create_run_folder(setup.journal.parent, fresh=False), False
    return create_run_folder(default_run_folder(setup.mission_path.stem), fresh=True), True


def _discard_unused(journal: Path) -> None:
    """Remove a journal that holds only its header."""
    try:
        if journal.exists() and len(journal.read_bytes().splitlines()) <= 1:
            journal.unlink()
    except OSError:
        pass  # tidying up only; the original error matters more


def _remove_if_unused(folder: Path) -> None:
    """Remove a folder this run created if nothing but its released lock is in it."""
    from navseq.runlock import LOCK_NAME

    try:
        if {entry.name for entry in folder.iterdir()} <= {LOCK_NAME}:
            (folder / LOCK_NAME).unlink(missing_ok=True)
            folder.rmdir()
    except OSError:
        pass  # tidying up only


def new_recorder(setup: RunSetup) -> RunRecorder:
    """The run's recorder; a resumed run's starts with what its journal recorded.

    So the picture of a resumed run shows the whole mission: the path driven and the
    legs planned before the resume too, in one mission-time colouring.
    """
    from navseq.sinks.recorder import RunRecorder

    if setup.history is None:
        return RunRecorder()
    return setup.history.recorder  # what reading the journal replayed into it


def _new_journal(setup: RunSetup, journal_path: Path) -> JournalWriter:
    """A new run's journal, its header written."""
    from navseq.journal.writer import JournalWriter

    # The absolute path, so that --resume works from any directory.
    source = str(setup.mission_path.resolve())
    return JournalWriter(journal_path, source, setup.digest, run_options=setup.run_options)


def _run_with_sinks(
    setup: RunSetup,
    args: argparse.Namespace,
    journal_path: Path,
    signals: SignalGuard,
    fresh: JournalWriter | None,
) -> RunOutcome:
    """Run the mission; from the moment it ends, shutdown signals are only counted.

    ``fresh`` is a new run's journal (None when resuming: the journal at
    ``journal_path`` is continued once the navigator is there).
    """
    import time

    from navseq.commands.run_outputs import StdoutGuard
    from navseq.executor.runner import MissionAborted, MissionInterrupted, run_mission
    from navseq.journal.writer import JournalWriter
    from navseq.sinks.json_events import JsonProgress
    from navseq.sinks.progress import make_progress

    navigator = setup.make_navigator()
    error: NavseqError | None = None
    navigator_start, wall_start = navigator.now(), time.monotonic()
    try:
        if fresh is not None:
            journal = fresh
        else:
            assert setup.resume is not None
            journal = JournalWriter.resume(journal_path, setup.resume, history=setup.history)
        recorder = new_recorder(setup)
        progress = make_progress(
            setup.mission,
            json_lines=args.json,
            robot=setup.robot,
            numbers=setup.part.numbers if setup.part is not None else None,
        )
        with progress, journal:
            try:
                result = run_mission(
                    setup.mission,
                    navigator,
                    [journal, recorder, StdoutGuard(progress), *setup.listeners],
                    resume=setup.resume,
                    signals=signals,
                    robot=setup.robot,
                    control=setup.control,
                )
                exit_code, interrupted = result.exit_code, None
            except MissionInterrupted as stop:
                result, exit_code, interrupted = stop.result, stop.exit_code, stop.signal_name
            except MissionAborted as aborted:
                # Stopped by an output that failed: report what happened, then exit 2.
                result, exit_code, interrupted = aborted.result, 2, None
                error = aborted
    finally:
        signals.defer()  # the goal is reached or cancelled: the report comes first now
        navigator.close()
    json_lines = progress if isinstance(progress, JsonProgress) else None
    return RunOutcome(
        result,
        exit_code,
        interrupted,
        navigator,
        recorder,
        json_lines,
        error,
        navigator_seconds=navigator.now() - navigator_start,
        wall_seconds=time.monotonic() - wall_start,
    )


def real_time_text(clock: Mapping[str, float | None]) -> str:
    """``simulated 62.4 s in 0.9 s: 69x real time``: how fast the simulator ran.

    ``clock`` is :func:`~navseq.sinks.json_events.clock_record`'s, as the report says it.
    """
    simulated, wall, factor = clock["navigator_s"], clock["wall_s"], clock["real_time_factor"]
    assert simulated is not None and wall is not None
    if factor is None:
        return f"simulated {simulated:.1f} s"
    shown = f"{factor:.0f}" if factor >= 10 else f"{factor:.2g}"
    # A short mission simulates in hundredths of a second: "in 0.0 s" would say nothing.
    wall_shown = f"{wall:.1f}" if wall >= 1 else f"{wall:.3f}"
    return f"simulated {simulated:.1f} s in {wall_shown} s: {shown}x real time"


def execute(setup: RunSetup, args: argparse.Namespace) -> int:
    """Run the mission with every sink attached; write report and picture; exit status."""
    from navseq.commands.run_outputs import remove_stale_temporaries
    from navseq.runlock import RunLock
    from navseq.signals import SignalGuard

    folder, created = _output_folder(setup, args)
    # One live run per folder: a second --resume of the same journal is refused here,
    # before it writes anything or moves the robot.
    lock = RunLock(folder).acquire()
    remove_stale_temporaries(folder)  # of a run killed while it wrote its outputs
    signals = SignalGuard()
    try:
        return _execute_locked(setup, args, folder, lock, signals)
    finally:
        lock.release()
        if created:
            _remove_if_unused(folder)
        if not getattr(args, "exits_after_command", False):
            # In the navseq process itself the guard goes on counting signals until
            # the exit: the status the report states is the one the process returns.
            signals.restore()
        if len(signals.received) > 1:  # the first one is the interruption itself
            print(
                f"navseq run: {', '.join(signals.received)} received; the robot was stopped "
                "and the outputs were finished first",
                file=sys.stderr,
            )


def _execute_locked(
    setup: RunSetup,
    args: argparse.Namespace,
    folder: Path,
    lock: Any,
    signals: SignalGuard,
) -> int:
    from navseq.commands.output import reserve_file
    from navseq.commands.run_outputs import (
        RunFiles,
        outputs_error,
        print_summary,
        report_failures,
        silence_stdout,
        write_outputs,
    )

    if lock.took_over is not None:
        setup.notes.append(
            f"took over the lock of process {lock.took_over}, which is no longer running"
        )
    # Resuming appends to the run's own journal; a new run starts a new one.
    journal_path = setup.journal or reserve_file(folder, "journal.jsonl")
    fresh: JournalWriter | None = None
    try:
        # A new journal gets its header at once, before the slow steps (the picture's
        # imports, the navigator's connection): a run killed during them used to
        # leave an empty journal, which neither --resume nor navseq report can read.
        if setup.journal is None:
            fresh = _new_journal(setup, journal_path)
        for note in setup.notes:
            print(f"navseq run: {printable(note)}", file=sys.stderr)
        if not args.no_picture:
            _import_picture_modules()
        outcome = _run_with_sinks(setup, args, journal_path, signals, fresh)
    except BaseException:
        # No result to report (e.g. no navigation server, or a signal before the run
        # began): leave no journal of nothing behind.
        if fresh is not None:
            fresh.close()
        if setup.journal is None:
            _discard_unused(journal_path)
        raise
    files = RunFiles(paths={"journal": str(journal_path)})
    exit_code = write_outputs(
        folder,
        files,
        lambda paths, code: _report(setup, outcome, paths, code),
        None if args.no_picture else lambda: _picture_png(setup, outcome),
        signals,
        outcome.exit_code,
    )
    notes = []
    if setup.navigator_info.get("kind") == "sim":
        notes.append(real_time_text(outcome.clock))
    if outcome.json_lines is not None:
        try:
            outcome.json_lines.run_finished(
                success=outcome.result.success,
                reason=outcome.result.reason,
                exit_code=exit_code,
                interrupted=outcome.interrupted,
                files=files.paths,
                clock=outcome.clock,
            )
        except BrokenPipeError:
            silence_stdout()
        for note in notes:  # stdout is for programs here
            print(f"navseq run: {printable(note)}", file=sys.stderr)
    else:
        print_summary(
            setup.mission,
            outcome.result,
            files,
            numbers=setup.part.numbers if setup.part is not None else None,
            part=setup.part.describe() if setup.part is not None else None,
            notes=notes,
        )
    failure = outputs_error(files, folder, journal_path, exit_code)
    if failure is None or outcome.error is not None:
        report_failures(files)  # else the closing message says it all, once
    if outcome.error is not None:
        raise outcome.error
    if failure is not None:
        from navseq.errors import NavseqError

        raise NavseqError(failure)
    return exit_code


def _report(
    setup: RunSetup, outcome: RunOutcome, files: dict[str, str], exit_code: int
) -> dict[str, Any]:
    from navseq.mission.part import number_visits
    from navseq.sinks.report import build_report

    report = build_report(
        setup.mission,
        outcome.result,
        exit_code=exit_code,
        navigator=setup.navigator_info,
        interrupted=outcome.interrupted,
        mission_digest=setup.digest,
        map_info=_map_info(setup.grid, setup.map_path)
        if setup.grid is not None and setup.map_path is not None
        else None,
        start=setup.start,
        start_source=setup.start_source,
        files=files,
    )
    number_visits(report, setup.part)
    # Not in a report rebuilt from the journal (navseq report): it keeps no wall time.
    report["clock"] = outcome.clock
    return report


def _import_picture_modules() -> None:
    """Import what the picture draws with now, before the robot moves, not after.

    matplotlib takes about half a second to import; a run stopped by a signal has
    about two seconds to write its outputs and exit, and should not spend a quarter of
    them there. (Not in a thread alongside the run: a daemon thread still importing
    when a refused run exits can crash the interpreter's shutdown.) A failed import is
    left for the picture itself to report.
    """
    from navseq.sinks.picture.draw import import_drawing_modules

    with contextlib.suppress(ImportError):
        import_drawing_modules()


def _picture_png(setup: RunSetup, outcome: RunOutcome) -> bytes:
    from navseq.sinks.picture.draw import mission_picture_png

    return mission_picture_png(
        setup.mission,
        outcome.result,
        grid=setup.grid,
        # Where the robot really set out from (the planned start if it never said; a
        # resumed run's picture shows the whole mission, so its planned start too).
        start=setup.start
        if setup.resume is not None and setup.start is not None
        else outcome.result.start_pose or setup.start,
        plans=outcome.recorder.leg_plans(),
        trajectory=picture_trajectory(outcome),
        interrupted=outcome.interrupted,
        robot=setup.robot,
    )


def picture_trajectory(outcome: RunOutcome) -> list[tuple[float, float, float]]:
    """The driven path to draw, (mission time, x, y), NaN rows between run segments.

    The simulator records every step of this run; other navigators give only what
    their feedback showed (the recorder's progress events). Either way the segments
    before a resume come from the journal, through the recorder.
    """
    recorder = outcome.recorder
    stepped = getattr(outcome.navigator, "trajectory", None)
    if not stepped:
        return recorder.trajectory()
    now = [(recorder.mission_time(t), x, y) for t, x, y in stepped]
    return [*recorder.earlier_trajectory(), *now]


def run(args: argparse.Namespace) -> int:
    from navseq.journal.writer import NothingToResume

    try:
        setup = prepare(args)
    except NothingToResume as finished:
        # A finished run: all a resume can still do is finish its outputs.
        code = _rebuild_finished(args.resume, finished.state)
        if code is None:
            raise
        return code
    return execute(setup, args)


def _rebuild_finished(journal: Path, state: JournalState | None) -> int | None:
    """Rebuild a finished run's missing report/picture; its exit status, or None if complete."""
    from navseq.commands.report import rebuild_outputs
    from navseq.runlock import RunLock

    with RunLock(journal.parent):
        rebuilt = rebuild_outputs(journal, state)
    if not rebuilt.written:
        return None
    for role, path in rebuilt.written.items():
        print(
            f"navseq run: nothing left to run; rebuilt the {role}: {printable(path)}",
            file=sys.stderr,
        )
    return 1 if rebuilt.exit_code is None else rebuilt.exit_code
